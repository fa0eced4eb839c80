#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, ASan + UBSan) and runs each for N seconds (default 60).
# Inputs: test/fuzz/seeds/<target> and test/fuzz/regressions/<target> (past crashes, kept as tests).
# RR_FUZZ_SEED fixes libFuzzer's random seed (default 1) so that a run from an empty corpus is
# reproducible: a slower machine explores a prefix of what a faster one does. RR_FUZZ_SEED=0 picks a
# new seed each run, which is what a longer fuzzing campaign wants.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
seed=${RR_FUZZ_SEED:-1}
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "${RR_JOBS:-$(nproc)}"
shopt -s nullglob
targets=(build/fuzz/test/fuzz/fuzz_*)
if ((${#targets[@]} == 0)); then echo "fuzz: no targets"; exit 0; fi
for t in "${targets[@]}"; do
  [ -x "$t" ] || continue
  name=$(basename "$t")
  corpus=build/fuzz/corpus/$name
  mkdir -p "$corpus"
  inputs=()
  for d in test/fuzz/seeds/$name test/fuzz/regressions/$name; do [ -d "$d" ] && inputs+=("$d"); done
  echo "fuzz: $name for ${seconds}s (seed $seed)"
  "$t" -seed="$seed" -max_total_time="$seconds" -print_final_stats=0 -artifact_prefix=build/fuzz/ "$corpus" \
       "${inputs[@]}" >build/fuzz/$name.log 2>&1 || { tail -40 build/fuzz/$name.log; echo "fuzz: $name FAILED"; exit 1; }
  grep -E '^#[0-9]+.*(DONE|pulse)' build/fuzz/$name.log | tail -1 || true
done
echo "fuzz: ok"
