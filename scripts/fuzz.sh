#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, ASan + UBSan) and runs each for N seconds (default 60).
# Seeds come from the shared test vectors and standard robdefs when they are present.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
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
  seeds=test/fuzz/seeds/$name
  echo "fuzz: $name for ${seconds}s"
  "$t" -max_total_time="$seconds" -print_final_stats=0 -artifact_prefix=build/fuzz/ "$corpus" \
       $( [ -d "$seeds" ] && echo "$seeds" ) >build/fuzz/$name.log 2>&1 || { tail -40 build/fuzz/$name.log; echo "fuzz: $name FAILED"; exit 1; }
  grep -E '^#[0-9]+.*(DONE|pulse)' build/fuzz/$name.log | tail -1 || true
done
echo "fuzz: ok"
