#!/usr/bin/env bash
# Soak of rr-gateway (issue 16; not a CI test): client churn over rr+tcp, rr+ws, rr+local, JSON
# WebSockets and REST; the demo devices killed and restarted; stalled and slow consumers; hostile peers;
# while sampling the gateway's RSS, open fds, threads and request latency (test/gateway/soak.py says
# what and the bounds). Fails on growth beyond the bounds.
#
# Usage: scripts/soak.sh [SECONDS]   (default 1800 = 30 min; RR_SOAK_BUILD=release|debug, default debug)
# Writes build/soak-<time>.csv (the samples) and prints a JSON summary as its last line.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-${RR_SOAK_SECONDS:-1800}}
preset=${RR_SOAK_BUILD:-debug}
jobs=${RR_JOBS:-2}
cmake --preset "$preset" >/dev/null
cmake --build "build/$preset" --target rr-gateway rr-demo-devices -j "$jobs"
python=.venv/bin/python
[ -x "$python" ] || python=python3
csv="build/soak-$(date -u +%Y%m%dT%H%M%SZ).csv"
echo "soak: ${seconds} s on the $preset build; load average now: $(cut -d' ' -f1-3 /proc/loadavg); samples in $csv" >&2
exec "$python" test/gateway/soak.py --gateway "build/$preset/server/app/rr-gateway" \
  --devices "build/$preset/server/demo/rr-demo-devices" --seconds "$seconds" --csv "$csv"
