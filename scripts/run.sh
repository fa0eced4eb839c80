#!/usr/bin/env bash
# The main job. Until the gateway lands (issue 4) it builds the release preset and checks the 45
# standard service definitions together with the robdef checker, printing the verdict per file.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "${RR_JOBS:-$(nproc)}" --target rr-robdef
shared=${RR_SHARED_DIR:-../shared}
files=("$shared"/robdef-standard/group1/*.robdef)
echo "run: checking ${#files[@]} standard service definitions together"
./build/release/robdef/rr-robdef check "${files[@]}"
echo "run: all ${#files[@]} definitions verify"
