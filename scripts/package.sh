#!/usr/bin/env bash
# Builds the Debian package build/package/rr-gateway_VERSION_ARCH.deb (docs/deployment.md §1): installs
# what building needs (scripts/setup.sh run), builds the WebAssembly client and the dashboard (the
# package ships it in /usr/share/rr-gateway/web), then the Release build and CPack
# (cmake --workflow --preset package, which refuses to pack without the dashboard).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh run
./wasm-client/build.sh
./web/build.sh
cmake --workflow --preset package
ls -1 build/package/*.deb
