#!/usr/bin/env bash
# Where the time of a Nop() round trip goes: runs rr_bench_service under valgrind's callgrind, zeroes
# its counters after a warm-up, drives N Nop() calls with rr_bench_client (rr+tcp), dumps, and writes
# the top functions by inclusive and self instruction count to bench/results/profile_nop.txt.
# Instruction counts do not depend on machine load. Needs valgrind (apt-get install valgrind) and a
# build from bench/run.sh (RR_BENCH_BUILD, default build/bench).
# Usage: bench/profile.sh [N]   (default 5000)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${RR_BENCH_BUILD:-build/bench}
N=${1:-5000}
OUT=bench/results
command -v valgrind >/dev/null || { echo "profile.sh: valgrind is not installed (apt-get install valgrind)" >&2; exit 2; }
mkdir -p "$OUT"
tmp=$(mktemp -d)
trap 'kill $svc 2>/dev/null || true; rm -rf "$tmp"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" --dump-instr=no \
  "$BUILD/bench/rr_bench_service" --memory-mib 0.01 --threads 2 > "$tmp/ready" 2> "$tmp/valgrind.log" &
svc=$!
for _ in $(seq 1 600); do [ -s "$tmp/ready" ] && break; sleep 0.1; done
url=$(.venv/bin/python -c "import json,sys; print(json.load(open(sys.argv[1]))['url'])" "$tmp/ready")
"$BUILD/bench/rr_bench_client" --url "$url" --count 200 --ops nop > /dev/null   # warm-up
callgrind_control -z "$svc" > /dev/null
"$BUILD/bench/rr_bench_client" --url "$url" --count "$N" --ops nop | tee "$tmp/client.json"
callgrind_control -d "$svc" > /dev/null
sleep 1
kill -TERM "$svc"; wait "$svc" || true
dump=$(ls -t "$tmp"/cg.out.* 2>/dev/null | head -1)
{
  echo "# callgrind of rr_bench_service while serving $N Nop() calls (plus connect/close of one client session)"
  echo "# Ir per call = total Ir / $N"
  callgrind_annotate --inclusive=yes "$dump" 2>/dev/null | head -60
  echo
  echo "# self cost"
  callgrind_annotate "$dump" 2>/dev/null | head -45
} > "$OUT/profile_nop.txt"
echo "wrote $OUT/profile_nop.txt" >&2
