#!/usr/bin/env bash
# The benchmark suite in one command: builds the bench programs and rr-gateway (Release, build/bench by
# default; RR_BENCH_BUILD overrides) and runs bench/run.py, which writes bench/results/latest.json and
# bench/results/latest.md. Arguments go to run.py (--quick, --rounds R, --count N, --no-busy, ...).
#
# bench/run.sh --compare REV [compare.py arguments]: also builds the commit REV (from `git archive`, in
# build/compare/REV-SHA) and runs bench/compare.py, both builds interleaved, with the ratio of each figure.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${RR_BENCH_BUILD:-build/bench}
if ! .venv/bin/python -c "import RobotRaconteur" 2>/dev/null; then
  ./scripts/setup.sh
fi
configure_and_build() {  # SOURCE BUILD
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRR_BUILD_TESTS=OFF -DRR_BUILD_BENCH=ON >/dev/null
  cmake --build "$2" -j2 --target rr_bench rr-gateway
}
start=$(date +%s)
if [ "${1:-}" = "--compare" ]; then
  rev=${2:?usage: bench/run.sh --compare REV [compare.py arguments]}
  shift 2
  sha=$(git rev-parse --short "$rev^{commit}")
  src=build/compare/src-$sha
  if [ ! -f "$src/CMakeLists.txt" ]; then
    rm -rf "$src" && mkdir -p "$src"
    git archive "$sha" | tar -x -C "$src"
  fi
  configure_and_build "$src" "build/compare/$sha"
  configure_and_build . "$BUILD"
  echo "[bench] builds took $(( $(date +%s) - start )) s" >&2
  exec .venv/bin/python bench/compare.py --base "build/compare/$sha" --base-name "$rev ($sha)" \
    --new "$BUILD" --new-name "working tree" "$@"
fi
configure_and_build . "$BUILD"
echo "[bench] build took $(( $(date +%s) - start )) s" >&2
exec .venv/bin/python bench/run.py --build "$BUILD" "$@"
