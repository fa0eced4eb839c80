#!/usr/bin/env bash
# The end of a scripts/test.sh run, pass or fail: every skipped test with its reason, how long each
# phase took, the disk left, and, when the run took longer than its budget, the slowest phases and tests.
# Exits with RC, the run's own status: the report never changes a run's outcome (a CI run that passed
# every test once ended 141 because `sort | head` here took a SIGPIPE under `set -o pipefail`).
#
#   run_report.sh RC ELAPSED_S BUDGET_MIN [PHASE...]     PHASE: "name seconds s", in order
#
# Reads the JUnit files BUILD/ctest-*.xml (test/schedule/ctest_report.py); BUILD: RR_REPORT_BUILD_DIR
# (default build/).
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
build=${RR_REPORT_BUILD_DIR:-$here/build}
rc=${1:?rc} elapsed=${2:?elapsed seconds} budget_min=${3:?budget minutes}
shift 3
phases=("$@")

shopt -s nullglob
xml=("$build"/ctest-*.xml)
if ((${#xml[@]})); then
  list=$(python3 "$here/test/schedule/ctest_report.py" skipped "${xml[@]}" 2>/dev/null)
  if [ -n "$list" ]; then
    echo "test: skipped tests ($(printf '%s\n' "$list" | wc -l)), with the reason each printed:"
    printf '%s\n' "$list"
  else
    echo "test: no test was skipped"
  fi
fi
joined=
for p in "${phases[@]}"; do joined+="$p, "; done
echo "test: phases: ${joined}total $elapsed s"
# CI's disk is finite (a landing failed with "No space left on device" while linking build/debug).
echo "test: disk: build/ $(du -sh "$build" 2>/dev/null | cut -f1), $(df -h --output=avail "$here" | tail -1 | tr -d ' ') left"
if ((elapsed > budget_min * 60)); then
  echo "test: WARNING: the run took $((elapsed / 60)) min, over the budget of $budget_min min (CI allows 90 on a"
  echo "test: fresh clone with an empty compiler cache; docs/development.md \"CI time\"). Slowest phases:"
  # sorted in full before any line is dropped (awk reads all its input: no writer gets a SIGPIPE)
  printf '%s\n' "${phases[@]}" | sort -k2 -rn | awk 'NR <= 3 { print "test:   " $0 }'
  if ((${#xml[@]})); then
    echo "test: slowest tests:"
    python3 "$here/test/schedule/ctest_report.py" slowest 10 "${xml[@]}" 2>/dev/null | sed 's/^ */test:   /'
  fi
fi
exit "$rc"
