#!/bin/bash
# perf stat and /proc user/system time of rr-gateway (a Release build dir, default build/bench) while 1,000 JSON clients get the
# device's 100 Hz Ticks wire without a rate, at max_rate_hz 10 and at 1, two runs each, a fresh gateway per run, 4 s measured
# after 3 s. Outputs in $2 (default /tmp/perf56): perf.TAG.csv, ticks.TAG (utime stime before and after, 10 ms ticks), load.TAG.json.
set -u
B=$(realpath ${1:-build/bench}); mkdir -p ${2:-/tmp/perf56} && cd ${2:-/tmp/perf56}
printf 'gateway:\n  limits:\n    connections_per_address: 0\n' > gw.yaml
$B/bench/rr_bench_service --tick-hz 100 > dev &
dev=$!
for _ in $(seq 1 100); do [ -s dev ] && break; sleep 0.1; done
durl=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['url'])" dev)
EV=task-clock,context-switches,syscalls:sys_enter_sendto,sched:sched_wakeup,sched:sched_waking,syscalls:sys_enter_epoll_wait
for run in "none1" "r10a --max-rate-hz 10" "r1a --max-rate-hz 1" "none2" "r10b --max-rate-hz 10" "r1b --max-rate-hz 1"; do
  set -- $run; tag=$1; shift
  $B/server/app/rr-gateway --no-demo --no-local --port 0 --log-level warning --device "bench=$durl" --config gw.yaml > gw.$tag &
  gw=$!
  for _ in $(seq 1 100); do [ -s gw.$tag ] && break; sleep 0.1; done
  sleep 1
  gport=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['port'])" gw.$tag)
  $B/bench/rr_bench_ws_load --port $gport --clients 1000 fanout --hz 100 --seconds 8 "$@" > load.$tag.json &
  lg=$!
  sleep 3
  a=$(awk '{print $14, $15}' /proc/$gw/stat)
  perf stat -e $EV -p $gw -x, -o perf.$tag.csv -- sleep 4
  b=$(awk '{print $14, $15}' /proc/$gw/stat)
  echo "$a $b" > ticks.$tag
  wait $lg
  kill -TERM $gw; wait $gw
done
kill -TERM $dev; wait $dev
