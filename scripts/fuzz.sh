#!/usr/bin/env bash
# Runs the libFuzzer targets (docs/fuzzing.md).
#
#   scripts/fuzz.sh            CI: every target briefly (the times below, two targets at a time: about
#                              3 minutes in all), from the seeds and regressions (a fresh corpus in
#                              BUILD/ci-corpus). The targets that need no server library (core, robdef,
#                              json: rr_fuzz_core_targets) from preset fuzz (-O1; about 2 minutes to
#                              build cold, which scripts/test.sh does in the background), the server
#                              ones (gateway config, JSON socket and REST, the gateway's port) from the
#                              debug build (clang-14 -O0, ASan + UBSan, linked from the objects the tests
#                              use: the server is not compiled a second time). -O0 runs the core targets
#                              4 to 14 times slower than -O1 (docs/fuzzing.md, measured side by side).
#   scripts/fuzz.sh N          every target for N seconds
#   scripts/fuzz.sh --long     every target to 10^7 executions or RR_FUZZ_LONG_SECONDS (default 1800)
#                              seconds, whichever comes first; one worker, nice -n 10; the corpus grows
#                              in build/fuzz/corpus/<target>. Builds preset fuzz (-O1) for every target
#   scripts/fuzz.sh ... TARGET...   only these targets
#
# RR_FUZZ_PRESET=fuzz|debug|mixed picks the builds (CI: mixed, as above); RR_FUZZ_JOBS=N runs N targets at a time (CI: 2).
# Inputs: test/fuzz/seeds/<target> and test/fuzz/regressions/<target> (past crashes, kept as tests and
# replayed by ctest in the debug build). RR_FUZZ_SEED fixes libFuzzer's random seed (default 1) so that
# a CI run from an empty corpus is reproducible: a slower machine explores a prefix of what a faster
# one does. RR_FUZZ_SEED=0 picks a new seed each run, which is what a longer campaign wants.
# A crash leaves its input in BUILD/<target>-crash-*; the log is BUILD/<target>.log (BUILD: build/fuzz
# or build/debug/test/fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."

# Seconds per target in CI: the pure parsers saturate quickly; the gateway targets need a few seconds
# to start the gateway and run slower (every input goes through the gateway's threads and sockets).
# (Twice what the all -O1 layout of earlier sessions had; with two targets at a time the phase takes as
# long as it did.)
declare -A CI_SECONDS=(
  [fuzz_robdef_parser]=30 [fuzz_message_reader]=30 [fuzz_message_structured]=40 [fuzz_connection_url]=20
  [fuzz_service_path]=20 [fuzz_gateway_config]=30 [fuzz_discovery_packet]=20 [fuzz_usb_descriptors]=20
  [fuzz_usb_packets]=20 [fuzz_json_socket]=40 [fuzz_json_rest]=40 [fuzz_gateway_port]=50
  [fuzz_mcap_reader]=20
)

mode=ci
seconds=
only=()
for a in "$@"; do
  case "$a" in
    --long) mode=long ;;
    ''|*[!0-9]*) only+=("$a") ;;
    *) seconds=$a ;;
  esac
done
seed=${RR_FUZZ_SEED:-1}
long_seconds=${RR_FUZZ_LONG_SECONDS:-1800}

preset=${RR_FUZZ_PRESET:-}
[ -n "$preset" ] || { if [ "$mode" = long ]; then preset=fuzz; else preset=mixed; fi; }
case "$preset" in
  fuzz) bin=build/fuzz/test/fuzz ;;
  debug|mixed) bin=build/debug/test/fuzz ;;
  *) echo "fuzz: RR_FUZZ_PRESET is fuzz, debug or mixed, not $preset"; exit 2 ;;
esac
if [ "$preset" = mixed ]; then
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz --target rr_fuzz_core_targets -j "${RR_JOBS:-$(nproc)}"
  cmake --preset debug >/dev/null
  cmake --build --preset debug --target rr_fuzz_targets -j "${RR_JOBS:-$(nproc)}"
else
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" --target rr_fuzz_targets -j "${RR_JOBS:-$(nproc)}"
fi
# The binary of target NAME: in mixed mode the -O1 one for the core targets.
binary_of() {
  if [ "$preset" = mixed ] && grep -qx "$1" build/fuzz/test/fuzz/core_targets.txt; then echo "build/fuzz/test/fuzz/$1"
  else echo "$bin/$1"; fi
}
parallel=${RR_FUZZ_JOBS:-}
[ -n "$parallel" ] || { if [ "$mode" = long ]; then parallel=1; else parallel=2; fi; }

shopt -s nullglob
targets=()
if ((${#only[@]})); then
  for t in "${only[@]}"; do targets+=("$(binary_of "$t")"); done
else
  for t in "$bin"/fuzz_*; do  # the programs, not the logs and crash inputs beside them
    [[ -f $t && -x $t && $(basename "$t") != *[.-]* ]] && targets+=("$(binary_of "$(basename "$t")")")
  done
fi
if ((${#targets[@]} == 0)); then echo "fuzz: no targets"; exit 0; fi

# One target: its log in $out/<name>.log, a summary line on stdout when it ends.
run_target() {
  local t=$1 name corpus inputs dict limits runner s start runs last d out
  name=$(basename "$t")
  # logs, corpora and crash inputs beside the build the binary comes from
  case "$t" in build/fuzz/*) out=build/fuzz ;; *) out=build/debug/test/fuzz ;; esac
  # libFuzzer runs its whole starting corpus before it looks at the clock: a CI run starts from the
  # seeds and regressions only (a fresh folder), so its time stays bounded; --long keeps a corpus.
  if [ "$mode" = long ]; then corpus=$out/corpus/$name; else corpus=$out/ci-corpus/$name; rm -rf "$corpus"; fi
  mkdir -p "$corpus"
  inputs=()
  for d in test/fuzz/seeds/$name test/fuzz/regressions/$name; do [ -d "$d" ] && inputs+=("$d"); done
  dict=()
  [ -f "test/fuzz/$name.dict" ] && dict=(-dict="test/fuzz/$name.dict")
  if [ "$mode" = long ]; then
    limits=(-runs=10000000 -max_total_time="$long_seconds")
    runner=(nice -n 10)
  else
    s=${seconds:-${CI_SECONDS[$name]:-30}}
    limits=(-max_total_time="$s")
    runner=()
  fi
  start=$(date +%s)
  if ! "${runner[@]}" "$t" -seed="$seed" "${limits[@]}" "${dict[@]}" -timeout=30 -rss_limit_mb=3072 -print_final_stats=1 \
       -artifact_prefix="$out/$name-" "$corpus" "${inputs[@]}" >"$out/$name.log" 2>&1; then
    tail -60 "$out/$name.log"
    echo "fuzz: $name FAILED (input in $out/$name-*)"
    return 1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/$name.log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$out/$name.log" | tail -1 | sed -E 's/^#[0-9]+[[:space:]]+[A-Z]+[[:space:]]+//')
  echo "fuzz: $name $((($(date +%s) - start)))s, ${runs:-?} runs; $last"
}

for t in "${targets[@]}"; do [ -x "$t" ] || { echo "fuzz: no target $t"; exit 1; }; done
if [ "$mode" = long ]; then
  echo "fuzz: ${#targets[@]} targets ($preset build), each to 10^7 runs or ${long_seconds}s, $parallel at a time (seed $seed)"
else
  echo "fuzz: ${#targets[@]} targets ($preset build$([ "$preset" = mixed ] && echo ': core targets -O1, server ones -O0')), $parallel at a time (seed $seed)"
fi
# At most $parallel targets at once; the first failure stops the others.
pids=()
failed=0
for t in "${targets[@]}"; do
  while (($(jobs -rp | wc -l) >= parallel)); do wait -n || failed=1; ((failed)) && break; done
  ((failed)) && break
  run_target "$t" &
  pids+=($!)
done
while (($(jobs -rp | wc -l) > 0)); do wait -n || failed=1; done
if ((failed)); then
  kill "${pids[@]}" 2>/dev/null || true
  echo "fuzz: FAILED"
  exit 1
fi
echo "fuzz: ok"
