#!/bin/bash
# Runs callgrind-rate.sh for main's gateway (build/base: a copy of the Release build of b349850) and this
# branch's (build/release), alternated, ROUNDS (default 2) rounds from FIRST (default 1); the load average
# before each. Appends to callgrind-rate.txt; each run's dumps stay in /tmp/callgrind-rate/<name><round>.
cd "$(dirname "$0")/../../.."
out=bench/results/touch56/callgrind-rate.txt
first=${1:-1}; rounds=${2:-2}
[ -s $out ] || { echo "# callgrind of rr-gateway: 100 JSON clients on the 100 Hz Ticks wire, runs of 3 s and 6 s (steady = difference)" > $out
                 echo "# base = main's gateway (Release build of b349850), new = touch56" >> $out; }
for r in $(seq $first $((first + rounds - 1))); do
  for run in "build/base base$r" "build/release new$r"; do
    set -- $run
    echo "# $2 start $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $out
    nice -n 10 bench/callgrind_rate.sh $1 $2 2>&1 | grep -v '^sending command' >> $out
  done
done
echo "# end $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $out
