#!/usr/bin/env bash
# scripts/run_report.sh, the end of every scripts/test.sh run: it exits with the run's own status
# whatever it reports. A CI run whose every test passed ended 141 when the over-budget report's
# `sort | head` took a SIGPIPE under pipefail; here a run over budget with 5,000 tests in its JUnit file.
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

python3 - "$work/ctest-main.xml" <<'PY'
import sys
with open(sys.argv[1], "w") as f:
    f.write('<?xml version="1.0" encoding="UTF-8"?>\n<testsuite name="t" tests="5001">\n')
    for i in range(5000):
        f.write(f'<testcase name="suite: case {i} with a long name to fill the pipe buffer quickly" time="{i / 10:.1f}" status="run"><system-out>ok</system-out></testcase>\n')
    f.write('<testcase name="suite: a skipped one" time="0.1" status="notrun"><skipped/><system-out>SKIP: no engine here</system-out></testcase>\n')
    f.write('</testsuite>\n')
PY

for rc in 0 3; do
  set +e
  RR_REPORT_BUILD_DIR=$work bash -o pipefail "$here/scripts/run_report.sh" "$rc" 3000 45 \
    "setup 38 s" "build 778 s" "ctest 672 s" "timing 438 s" >"$work/out.txt" 2>&1
  got=$?
  set -e
  cat "$work/out.txt"
  [ "$got" = "$rc" ] || fail "run_report.sh exited $got for a run that ended $rc"
done
grep -q '^test: WARNING: the run took 50 min, over the budget of 45 min' "$work/out.txt" || fail "no budget warning"
grep -A3 'Slowest phases:' "$work/out.txt" | sed -n 2,4p | awk '{print $2}' | tr '\n' ' ' | grep -qx 'build ctest timing ' ||
  fail "slowest phases not build, ctest, timing"
slow=$(sed -n '/^test: slowest tests:/,$p' "$work/out.txt" | sed 1d)
[ "$(printf '%s\n' "$slow" | wc -l)" = 10 ] || fail "not 10 slowest tests"
printf '%s\n' "$slow" | head -1 | grep -q '499.90 s  suite: case 4999 ' || fail "the slowest test is not first"
grep -q '^  suite: a skipped one: SKIP: no engine here' "$work/out.txt" || fail "the skipped test and its reason"
grep -q '^test: phases: setup 38 s, build 778 s, ctest 672 s, timing 438 s, total 3000 s$' "$work/out.txt" || fail "phases line"

# Within budget: no warning, status kept.
RR_REPORT_BUILD_DIR=$work "$here/scripts/run_report.sh" 0 60 45 "setup 1 s" >"$work/out.txt" 2>&1 || fail "exit $? within budget"
! grep -q WARNING "$work/out.txt" || fail "a warning within budget"
echo PASS
