#!/usr/bin/env bash
# Finds flaky tests before CI does (docs/development.md "Flaky tests"): runs the ctest suite of
# build/debug (or the tests a pattern names) N times at CI's parallelism, with CPU load beside it,
# keeps every failed test's output, and prints how often each test failed.
#
#   scripts/flaky.sh [-n RUNS] [-j JOBS] [-R REGEX] [-E REGEX] [--timing] [--load N] [--load-nice NICE]
#
#   -n RUNS        runs of the suite (default 5)
#   -j JOBS        tests at once (default: scripts/test.sh's, 4 per CPU)
#   -R / -E REGEX  only the tests whose names match / do not match (ctest's -R / -E)
#   --timing       the tests labelled `timing` (scripts/test.sh's calm phase, 2 at a time, no load by
#                  default); without it, the others, as scripts/test.sh's main ctest phase runs them
#   --load N       N stress-ng CPU workers beside the tests (default: one per CPU; 0 = none). CI's own
#                  load is its tests plus the background builds at nice 19; the default is harsher
#   --load-nice K  the workers' nice value (default 0)
#
# Needs build/debug built (cmake --build --preset debug) and stress-ng (scripts/setup.sh installs it).
# Output: build/flaky/<time>/run-<i>/ (ctest.xml, ctest.log, failed/<test>.log, tmp -> the tests'
# TMPDIR, a short folder under /tmp, kept) and a summary at the end; exits 1 when any test failed in
# any run. A failure is fixed, never retried (docs/development.md).
set -euo pipefail
cd "$(dirname "$0")/.."

runs=5 jobs=$((4 * $(nproc))) regex= exclude= timing= load=$(nproc) load_nice=0 jobs_given=
while (($#)); do
  case $1 in
    -n) runs=$2; shift 2 ;;
    -j) jobs=$2; jobs_given=1; shift 2 ;;
    -R) regex=$2; shift 2 ;;
    -E) exclude=$2; shift 2 ;;
    --timing) timing=1; shift ;;
    --load) load=$2; shift 2 ;;
    --load-nice) load_nice=$2; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) echo "flaky: unknown argument $1 (--help)" >&2; exit 2 ;;
  esac
done
[[ $runs =~ ^[1-9][0-9]*$ ]] || { echo "flaky: -n takes a positive number" >&2; exit 2; }
[[ $jobs =~ ^[1-9][0-9]*$ ]] || { echo "flaky: -j takes a positive number" >&2; exit 2; }
[[ $load =~ ^[0-9]+$ ]] || { echo "flaky: --load takes a number" >&2; exit 2; }
[ -f build/debug/CTestTestfile.cmake ] || { echo "flaky: build/debug is not built (cmake --preset debug && cmake --build --preset debug)" >&2; exit 2; }
if ((load > 0)) && ! command -v stress-ng >/dev/null; then
  echo "flaky: stress-ng is missing (./scripts/setup.sh installs it; or --load 0)" >&2; exit 2
fi
if [ -n "$timing" ] && [ -z "$jobs_given" ]; then jobs=2; fi

# The same selection as scripts/test.sh's ctest phases.
excluded='^(docker: the image|install: the package on a fresh Debian 12 root)'
[ -n "$exclude" ] && excluded="$excluded|$exclude"
select=(-E "$excluded")
if [ -n "$timing" ]; then select+=(-L timing); else select+=(-LE timing); fi
[ -n "$regex" ] && select+=(-R "$regex")

out=build/flaky/$(date +%Y%m%d-%H%M%S)
mkdir -p "$out"
load_pid=
stop_load() { if [ -n "$load_pid" ]; then kill -- -"$load_pid" 2>/dev/null || true; wait "$load_pid" 2>/dev/null || true; load_pid=; fi; }
trap stop_load EXIT
if ((load > 0)); then
  setsid nice -n "$load_nice" stress-ng --cpu "$load" --timeout 0 --quiet >"$out/stress-ng.log" 2>&1 &
  load_pid=$!
fi

echo "flaky: $runs run(s), $jobs at once, load: $load CPU worker(s) at nice $load_nice; output in $out"
for ((i = 1; i <= runs; i++)); do
  dir=$out/run-$i
  mkdir -p "$dir"
  # TMPDIR: the tests' temporary folders land in a folder of the run's and stay (a test that keeps its
  # logs on failure leaves them there). Short, under /tmp: Unix socket paths (rr+local) hold 107 bytes.
  tmp=$(mktemp -d /tmp/f$i.XXXX)
  chmod 1777 "$tmp"  # as /tmp: tests run programs as other users (setpriv) in their folders
  ln -s "$tmp" "$dir/tmp"
  t0=$SECONDS
  TMPDIR=$tmp ctest --test-dir build/debug -j "$jobs" "${select[@]}" --output-on-failure \
    --test-output-size-passed 65536 --test-output-size-failed 4194304 \
    --output-junit "$PWD/$dir/ctest.xml" >"$dir/ctest.log" 2>&1 || true
  if grep -q 'No tests were found' "$dir/ctest.log"; then
    echo "flaky: no test matches$([ -n "$regex" ] && echo " -R '$regex'") in the $([ -n "$timing" ] && echo timing || echo main) phase (the browser tests and other \`timing\` ones need --timing)" >&2
    exit 2
  fi
  summary=$(grep -E 'tests passed|tests failed' "$dir/ctest.log" | tail -n 1 || true)
  echo "flaky: run $i/$runs: ${summary:-no ctest summary (see $dir/ctest.log)} ($((SECONDS - t0)) s, load average $(cut -d' ' -f1-3 /proc/loadavg))"
  python3 test/schedule/ctest_report.py failed "$dir/ctest.xml" --out "$dir/failed"
done
stop_load
echo "flaky: skipped tests (the last run):"
python3 test/schedule/ctest_report.py skipped "$out/run-$runs/ctest.xml"
python3 test/schedule/ctest_report.py summary "$out"
