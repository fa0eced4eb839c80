#!/usr/bin/env bash
# Where the time of a Nop() round trip goes, counted in instructions (valgrind's callgrind: the counts
# do not depend on machine load).
#   service side: rr_bench_service runs under callgrind; its counters are zeroed after a warm-up and
#                 dumped after N Nop() calls over rr+tcp: instructions per call = total / N.
#   client side:  rr_bench_client runs under callgrind twice (N and 2N calls): per call = difference / N
#                 (connect and close cancel out).
#   gateway fan-out: rr-gateway runs under callgrind while 20 JSON WebSocket clients receive a 100 Hz
#                 device wire for 4 s: instructions and mallocs per delivered message.
#   raw RR fan-out: the same with 20 native RR clients over rr+ws (rr_bench_rr_fanout): instructions
#                 and mallocs per delivered value.
#   gateway hop:  rr-gateway runs under callgrind while the client makes N, then 2N Nop() calls
#                 through it (rr+tcp both sides): instructions and mallocs per forwarded call =
#                 difference / N.
# Writes bench/results/profile_nop.txt (per-call counts, then the top functions, inclusive and self;
# the gateway hop at its end) and bench/results/profile_fanout.txt (both fan-outs).
# Needs valgrind (apt-get install valgrind) and a build from bench/run.sh (RR_BENCH_BUILD, default
# build/bench).  Usage: bench/profile.sh [N]   (default 2000)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${RR_BENCH_BUILD:-build/bench}
N=${1:-2000}
OUT=bench/results
command -v valgrind >/dev/null || { echo "profile.sh: valgrind is not installed (apt-get install valgrind)" >&2; exit 2; }
mkdir -p "$OUT"
tmp=$(mktemp -d)
svc=""
trap '[ -n "$svc" ] && kill $svc 2>/dev/null; rm -rf "$tmp"' EXIT
total_ir() { callgrind_annotate "$1" 2>/dev/null | awk '/PROGRAM TOTALS/ && !done { gsub(",", "", $1); print $1; done = 1 }'; }

valgrind --tool=callgrind --callgrind-out-file="$tmp/svc.out" \
  "$BUILD/bench/rr_bench_service" --memory-mib 0.01 --threads 2 > "$tmp/ready" 2> "$tmp/valgrind.log" &
svc=$!
for _ in $(seq 1 600); do [ -s "$tmp/ready" ] && break; sleep 0.1; done
url=$(.venv/bin/python -c "import json,sys; print(json.load(open(sys.argv[1]))['url'])" "$tmp/ready")
"$BUILD/bench/rr_bench_client" --url "$url" --count 200 --ops nop > /dev/null   # warm-up
callgrind_control -z "$svc" > /dev/null
"$BUILD/bench/rr_bench_client" --url "$url" --count "$N" --ops nop > /dev/null
callgrind_control -d "$svc" > /dev/null
for c in "$N" $((2 * N)); do
  valgrind --tool=callgrind --callgrind-out-file="$tmp/client.$c.out" \
    "$BUILD/bench/rr_bench_client" --url "$url" --count "$c" --ops nop > /dev/null 2>> "$tmp/valgrind.log"
done
kill -TERM "$svc"; wait "$svc" || true; svc=""
# System calls per call on the service side, on a service without valgrind (valgrind makes its own
# system calls); strace slows the calls down, only the counts matter.
if command -v strace > /dev/null; then
  "$BUILD/bench/rr_bench_service" --memory-mib 0.01 --threads 2 > "$tmp/ready2" &
  plain=$!
  for _ in $(seq 1 600); do [ -s "$tmp/ready2" ] && break; sleep 0.1; done
  url2=$(.venv/bin/python -c "import json,sys; print(json.load(open(sys.argv[1]))['url'])" "$tmp/ready2")
  "$BUILD/bench/rr_bench_client" --url "$url2" --count 200 --ops nop > /dev/null
  strace -f -c -o "$tmp/strace.txt" -p "$plain" 2> /dev/null &
  st=$!
  sleep 1
  "$BUILD/bench/rr_bench_client" --url "$url2" --count "$N" --ops nop > /dev/null
  kill -INT "$st"; wait "$st" || true
  kill -TERM "$plain"; wait "$plain" || true
fi
dump=$(ls -t "$tmp"/svc.out.* | head -1)
svc_ir=$(total_ir "$dump")
c1=$(total_ir "$tmp/client.$N.out"); c2=$(total_ir "$tmp/client.$((2 * N)).out")
# Annotations only for frames in our code (names start with rr::) and the allocator, to stay readable.
annotate() { callgrind_annotate --threshold=100 "$@" 2>/dev/null | grep -E '^ *[0-9,]+ \(' | grep -E 'rr::|malloc|free|operator new|operator delete|asio' | cut -c1-240 | sed -n 1,40p; }
{
  echo "# callgrind instruction counts for Nop() over rr+tcp (our client -> our service), N = $N"
  echo "service instructions per call: $((svc_ir / N))"
  echo "client instructions per call:  $(((c2 - c1) / N))   (blocking layer: the caller thread waits for an I/O thread to complete the call)"
  bench/callgrind_calls.py "$dump" malloc free | awk -v n="$N" '{ printf "service %s calls per call: %.1f\n", $1, $2 / n }'
  paste <(bench/callgrind_calls.py "$tmp/client.$N.out" malloc) <(bench/callgrind_calls.py "$tmp/client.$((2 * N)).out" malloc) |
    awk -v n="$N" '{ printf "client malloc calls per call: %.1f\n", ($4 - $2) / n }'
  if [ -s "$tmp/strace.txt" ]; then
    echo
    echo "## service system calls per call (strace -c, $N calls; the first lines of its table)"
    awk -v n="$N" 'NR > 2 && $NF != "total" && $4 ~ /^[0-9]+$/ { printf "%-16s %.2f\n", $NF, $4 / n }' "$tmp/strace.txt" | sort -k2 -rn | head -8
  fi
  echo
  echo "## service, inclusive (top frames in rr::, asio and the allocator)"
  annotate --inclusive=yes "$dump"
  echo
  echo "## service, self"
  annotate --inclusive=no "$dump"
  echo
  echo "## client ($((2 * N)) calls plus one connect), self"
  annotate --inclusive=no "$tmp/client.$((2 * N)).out"
} > "$OUT/profile_nop.txt"

# device_and_gateway NAME SERVICE_ARGS...: a fresh rr_bench_service (SERVICE_ARGS) and a fresh
# rr-gateway in front of it under callgrind (dumps $tmp/NAME.out.*); sets dev, gw and gport.
device_and_gateway() {
  local name=$1; shift
  "$BUILD/bench/rr_bench_service" "$@" > "$tmp/$name.dev" &
  dev=$!
  for _ in $(seq 1 600); do [ -s "$tmp/$name.dev" ] && break; sleep 0.1; done
  local durl
  durl=$(.venv/bin/python -c "import json,sys; print(json.load(open(sys.argv[1]))['url'])" "$tmp/$name.dev")
  valgrind --tool=callgrind --callgrind-out-file="$tmp/$name.out" "$BUILD/server/app/rr-gateway" --no-demo --no-local \
    --port 0 --log-level warning --device "bench=$durl" > "$tmp/$name.gw" 2>> "$tmp/valgrind.log" &
  gw=$!
  for _ in $(seq 1 600); do [ -s "$tmp/$name.gw" ] && break; sleep 0.1; done
  gport=$(.venv/bin/python -c "import json,sys; print(json.load(open(sys.argv[1]))['port'])" "$tmp/$name.gw")
  sleep 3
}

# Gateway fan-out.
device_and_gateway gw --tick-hz 100 --memory-mib 0.01
"$BUILD/bench/rr_bench_ws_load" --port "$gport" --clients 20 fanout --seconds 2 > /dev/null   # warm-up
callgrind_control -z "$gw" > /dev/null
"$BUILD/bench/rr_bench_ws_load" --port "$gport" --clients 20 fanout --seconds 4 > "$tmp/fanout.json"
callgrind_control -d "$gw" > /dev/null
# Raw RR fan-out through the same gateway.
"$BUILD/bench/rr_bench_rr_fanout" --url "rr+ws://127.0.0.1:$gport/?service=bench" --clients 20 --seconds 2 > /dev/null
callgrind_control -z "$gw" > /dev/null
"$BUILD/bench/rr_bench_rr_fanout" --url "rr+ws://127.0.0.1:$gport/?service=bench" --clients 20 --seconds 4 > "$tmp/rrfanout.json"
callgrind_control -d "$gw" > /dev/null
kill -TERM "$gw"; wait "$gw" || true
kill -TERM "$dev"; wait "$dev" || true
gdump=$(ls -v "$tmp"/gw.out.* | head -1)   # the first dump: JSON; the second: raw RR
rdump=$(ls -v "$tmp"/gw.out.* | sed -n 2p)
values=$(.venv/bin/python -c "import json,sys; r=json.load(open(sys.argv[1])); print(int(r['delivered_per_s'] * r['seconds']))" "$tmp/rrfanout.json")
msgs=$(.venv/bin/python -c "import json,sys; r=json.load(open(sys.argv[1])); print(int(r['delivered_per_s'] * r['seconds']))" "$tmp/fanout.json")
# fanout_report TITLE DUMP COUNT UNIT: instructions and mallocs per delivered UNIT, then the top frames.
fanout_report() {
  echo "# callgrind of rr-gateway: $1"
  echo "# (under valgrind the gateway is slower: counts matter, not rates)"
  echo "delivered ${4}s: $3"
  echo "gateway instructions per delivered $4: $(( $(total_ir "$2") / $3 ))"
  bench/callgrind_calls.py "$2" malloc | awk -v n="$3" -v u="$4" '{ printf "gateway malloc calls per delivered %s: %.1f\n", u, $2 / n }'
  echo
  echo "## inclusive (top frames)"
  callgrind_annotate --inclusive=yes --threshold=100 "$2" 2>/dev/null | grep -E '^ *[0-9,]+ \(' |
    grep -E 'rr::|nlohmann|beast|malloc|free' | cut -c1-240 | sed -n 1,45p
}
{
  fanout_report "a 100 Hz device wire fanned out to 20 JSON WebSocket clients for 4 s" "$gdump" "$msgs" message
  echo
  fanout_report "the same wire fanned out to 20 native RR clients over rr+ws for 4 s (rr_bench_rr_fanout)" "$rdump" "$values" value
} > "$OUT/profile_fanout.txt"

# Gateway hop: one Nop() forwarded by the gateway, a fresh gateway in front of a fresh device.
device_and_gateway hop --memory-mib 0.01 --threads 2
hop_url="rr+tcp://127.0.0.1:$gport/?service=bench"
"$BUILD/bench/rr_bench_client" --url "$hop_url" --count 200 --ops nop > /dev/null   # warm-up
# N then 2N calls, each run a connection of its own: per call = difference / N (the connect cancels out).
for c in "$N" $((2 * N)); do
  callgrind_control -z "$gw" > /dev/null
  "$BUILD/bench/rr_bench_client" --url "$hop_url" --count "$c" --ops nop > /dev/null
  callgrind_control -d "$gw" > /dev/null
done
kill -TERM "$gw"; wait "$gw" || true
kill -TERM "$dev"; wait "$dev" || true
h1=$(ls -v "$tmp"/hop.out.* | head -1)
h2=$(ls -v "$tmp"/hop.out.* | sed -n 2p)
{
  echo
  echo "# callgrind of rr-gateway: Nop() calls forwarded (our client -> gateway -> rr_bench_service, rr+tcp), $N and $((2 * N)) calls"
  echo "gateway instructions per forwarded call: $(( ($(total_ir "$h2") - $(total_ir "$h1")) / N ))"
  paste <(bench/callgrind_calls.py "$h1" malloc) <(bench/callgrind_calls.py "$h2" malloc) |
    awk -v n="$N" '{ printf "gateway malloc calls per forwarded call: %.1f\n", ($4 - $2) / n }'
  echo
  echo "## gateway hop ($((2 * N)) calls plus one connect), inclusive (top frames in rr::, asio and the allocator)"
  annotate --inclusive=yes "$h2"
} >> "$OUT/profile_nop.txt"
echo "wrote $OUT/profile_nop.txt and $OUT/profile_fanout.txt" >&2
