#!/usr/bin/env bash
# Builds the libFuzzer targets (preset fuzz: clang-14, ASan + UBSan, the server included) and runs each
# one (docs/fuzzing.md).
#
#   scripts/fuzz.sh            CI: every target briefly (the times below: about 3 minutes in all),
#                              from the seeds and regressions (a fresh corpus in build/fuzz/ci-corpus)
#   scripts/fuzz.sh N          every target for N seconds
#   scripts/fuzz.sh --long     every target to 10^7 executions or RR_FUZZ_LONG_SECONDS (default 1800)
#                              seconds, whichever comes first; one worker, nice -n 10; the corpus grows
#                              in build/fuzz/corpus/<target>
#   scripts/fuzz.sh ... TARGET...   only these targets
#
# Inputs: test/fuzz/seeds/<target> and test/fuzz/regressions/<target> (past crashes, kept as tests and
# replayed by ctest in the debug build). RR_FUZZ_SEED fixes libFuzzer's random seed (default 1) so that
# a CI run from an empty corpus is reproducible: a slower machine explores a prefix of what a faster
# one does. RR_FUZZ_SEED=0 picks a new seed each run, which is what a longer campaign wants.
# A crash leaves its input in build/fuzz/<target>-crash-*; the log is build/fuzz/<target>.log.
set -euo pipefail
cd "$(dirname "$0")/.."

# Seconds per target in CI: the pure parsers saturate quickly; the gateway targets need a few seconds
# to start the gateway and run slower (every input goes through the gateway's threads and sockets).
declare -A CI_SECONDS=(
  [fuzz_robdef_parser]=15 [fuzz_message_reader]=15 [fuzz_message_structured]=20 [fuzz_connection_url]=10
  [fuzz_service_path]=10 [fuzz_gateway_config]=15 [fuzz_discovery_packet]=10 [fuzz_usb_descriptors]=10
  [fuzz_usb_packets]=10 [fuzz_json_socket]=20 [fuzz_json_rest]=20 [fuzz_gateway_port]=25
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

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target rr_fuzz_targets -j "${RR_JOBS:-$(nproc)}"

shopt -s nullglob
targets=()
if ((${#only[@]})); then
  for t in "${only[@]}"; do targets+=("build/fuzz/test/fuzz/$t"); done
else
  targets=(build/fuzz/test/fuzz/fuzz_*)
fi
if ((${#targets[@]} == 0)); then echo "fuzz: no targets"; exit 0; fi
for t in "${targets[@]}"; do
  [ -x "$t" ] || { echo "fuzz: no target $t"; exit 1; }
  name=$(basename "$t")
  # libFuzzer runs its whole starting corpus before it looks at the clock: a CI run starts from the
  # seeds and regressions only (a fresh folder), so its time stays bounded; --long keeps a corpus.
  if [ "$mode" = long ]; then corpus=build/fuzz/corpus/$name; else corpus=build/fuzz/ci-corpus/$name; rm -rf "$corpus"; fi
  mkdir -p "$corpus"
  inputs=()
  for d in test/fuzz/seeds/$name test/fuzz/regressions/$name; do [ -d "$d" ] && inputs+=("$d"); done
  dict=()
  [ -f "test/fuzz/$name.dict" ] && dict=(-dict="test/fuzz/$name.dict")
  if [ "$mode" = long ]; then
    limits=(-runs=10000000 -max_total_time="$long_seconds")
    runner=(nice -n 10)
    echo "fuzz: $name to 10^7 runs or ${long_seconds}s (seed $seed)"
  else
    s=${seconds:-${CI_SECONDS[$name]:-30}}
    limits=(-max_total_time="$s")
    runner=()
    echo "fuzz: $name for ${s}s (seed $seed)"
  fi
  start=$(date +%s)
  "${runner[@]}" "$t" -seed="$seed" "${limits[@]}" "${dict[@]}" -timeout=30 -rss_limit_mb=3072 -print_final_stats=1 \
       -artifact_prefix="build/fuzz/$name-" "$corpus" "${inputs[@]}" >"build/fuzz/$name.log" 2>&1 \
    || { tail -60 "build/fuzz/$name.log"; echo "fuzz: $name FAILED (input in build/fuzz/$name-*)"; exit 1; }
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "build/fuzz/$name.log" | tail -1)
  last=$(grep -E '^#[0-9]+' "build/fuzz/$name.log" | tail -1 | sed -E 's/^#[0-9]+[[:space:]]+[A-Z]+[[:space:]]+//')
  echo "  $((($(date +%s) - start)))s, ${runs:-?} runs; $last"
done
echo "fuzz: ok"
