#!/usr/bin/env bash
# The benchmark suite in one command: builds the bench programs and rr-gateway (Release, build/bench by
# default; RR_BENCH_BUILD overrides) and runs bench/run.py, which writes bench/results/latest.json and
# bench/results/latest.md. Arguments go to run.py (--quick, --rounds R, --count N, --no-busy, ...).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${RR_BENCH_BUILD:-build/bench}
if ! .venv/bin/python -c "import RobotRaconteur" 2>/dev/null; then
  ./scripts/setup.sh
fi
start=$(date +%s)
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRR_BUILD_TESTS=OFF -DRR_BUILD_BENCH=ON >/dev/null
cmake --build "$BUILD" -j2 --target rr_bench rr-gateway
echo "[bench] build took $(( $(date +%s) - start )) s" >&2
exec .venv/bin/python bench/run.py --build "$BUILD" "$@"
