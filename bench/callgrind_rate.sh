#!/bin/bash
# callgrind of rr-gateway while 100 JSON clients get the device's 100 Hz wire at max_rate_hz 10, then without a
# rate: runs of 3 s and 6 s each, the steady cost is their difference (instructions and mallocs per delivered
# value). Usage: bench/callgrind_rate.sh BUILD NAME; BUILD is a build dir or a copy of its server/app/rr-gateway and
# bench/rr_bench_service, bench/rr_bench_ws_load; NAME names the dumps' folder, /tmp/callgrind-rate/NAME.
# Issue 56's rate groups (bench/results/rate56e, whose runs did not count mutex locks yet) and the
# once-per-value lever (bench/results/touch56) were measured with it.
set -u
B=$(realpath "$1"); NAME=$2; T=/tmp/callgrind-rate/$NAME; rm -rf $T; mkdir -p $T
cd "$(dirname "$0")/.."
$B/bench/rr_bench_service --tick-hz 100 --memory-mib 0.01 > $T/dev &
dev=$!
for _ in $(seq 1 600); do [ -s $T/dev ] && break; sleep 0.1; done
durl=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['url'])" $T/dev)
valgrind --tool=callgrind --callgrind-out-file=$T/gw.out $B/server/app/rr-gateway --no-demo --no-local --port 0 --log-level warning --device "bench=$durl" > $T/gw 2>> $T/valgrind.log &
gw=$!
for _ in $(seq 1 600); do [ -s $T/gw ] && break; sleep 0.1; done
gport=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['port'])" $T/gw)
sleep 3
$B/bench/rr_bench_ws_load --port $gport --clients 100 fanout --seconds 2 --max-rate-hz 10 > /dev/null
for run in "r10a 3 --max-rate-hz 10" "r10b 6 --max-rate-hz 10" "r100a 3" "r100b 6"; do
  set -- $run; tag=$1; secs=$2; shift 2
  callgrind_control -z $gw > /dev/null
  $B/bench/rr_bench_ws_load --port $gport --clients 100 fanout --seconds $secs "$@" > $T/$tag.json
  callgrind_control -d $gw > /dev/null
done
kill -TERM $gw; wait $gw; kill -TERM $dev; wait $dev
total_ir() { callgrind_annotate "$1" 2>/dev/null | awk '/PROGRAM TOTALS/ && !done { gsub(",", "", $1); print $1; done = 1 }'; }
dumps=($(ls -v $T/gw.out.*))
i=0
declare -A IR N M L
for tag in r10a r10b r100a r100b; do
  d=${dumps[$i]}; i=$((i+1))
  IR[$tag]=$(total_ir $d)
  N[$tag]=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(int(r['delivered_per_s'] * r['seconds']))" $T/$tag.json)
  M[$tag]=$(bench/callgrind_calls.py $d malloc | awk '{print $2}')
  # pthread_mutex_lock under whichever of its glibc names callgrind recorded (aliases: one is found)
  L[$tag]=$(bench/callgrind_calls.py $d pthread_mutex_lock ___pthread_mutex_lock 'pthread_mutex_lock@@GLIBC_2.2.5' | awk '{s += $2} END {print s}')
  echo "$NAME $tag delivered=${N[$tag]} instructions=${IR[$tag]} mallocs=${M[$tag]} mutex_locks=${L[$tag]}"
done
for r in 10 100; do
  a=r${r}a; b=r${r}b
  python3 -c "
ir=${IR[$b]}-${IR[$a]}; n=${N[$b]}-${N[$a]}; m=${M[$b]}-${M[$a]}; l=${L[$b]}-${L[$a]}
print('$NAME steady rate=$r: +3 s: %d values, %d instructions (%d per value, %.1f M per s), %.2f mallocs per value, %.2f mutex locks per value' % (n, ir, ir/n, ir/3e6, m/n, l/n))"
done
