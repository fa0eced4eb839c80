#!/usr/bin/env bash
# Installs what the project needs. Idempotent: a second run installs nothing.
#
#   ./scripts/setup.sh            everything: building, running, testing (scripts/test.sh)
#   ./scripts/setup.sh run        only what building and running the gateway and its dashboard needs
#                                 (scripts/run.sh): compiler, libraries, Emscripten + node for the
#                                 dashboard's WebAssembly client, the dashboard's npm packages
#   ./scripts/setup.sh run python  and the Python venv (.venv: the official library, Reynard;
#                                 scripts/run-reynard.sh)
#
# Debian packages (apt), Python packages into ./.venv (pip, pinned), npm packages (npm ci in web/ and
# wasm-client/, pinned by their package-lock.json).
set -euo pipefail
cd "$(dirname "$0")/.."

parts=("$@")
((${#parts[@]})) || parts=(run python test)
wants() { local p; for p in "${parts[@]}"; do [ "$p" = "$1" ] && return 0; done; return 1; }

# Building and running: the server, and the dashboard (its WebAssembly client needs Emscripten, which
# also brings node; node-acorn is what Debian's emscripten 3.1.6 needs; npm for web/'s packages).
RUN_PACKAGES=(
  cmake ninja-build g++ pkg-config ccache
  libboost1.81-all-dev libssl-dev nlohmann-json3-dev libusb-1.0-0-dev libyaml-cpp-dev libjwt-dev
  libzstd-dev zlib1g-dev
  emscripten node-acorn
)
PYTHON_PACKAGES=(python3-venv)
# Testing only: Catch2, the USB device emulator, clang and lld for the debug preset (its sanitizer
# build is also the fuzz targets' build), Chromium for the browser tests, nginx/openssl/htpasswd for
# the reverse-proxy tests, podman & co. for the container image (docker/build.sh: no Docker daemon, the
# base made with mmdebstrap; busybox-static for the image made from a build on this machine); libgl1
# and libglib2.0-0, which the OpenCV wheel of the camera driver's browser test links (Chromium pulls
# them in too; named here so they do not depend on that); iproute2 (`ip netns`: the discovery tests
# between network namespaces) and procps (`sysctl`, `ps`), which a minimal image may lack; stress-ng,
# the load beside the tests in scripts/flaky.sh.
TEST_PACKAGES=(
  catch2
  umockdev libumockdev-dev
  clang-14 libclang-rt-14-dev lld
  chromium fonts-liberation libgl1 libglib2.0-0
  nginx openssl apache2-utils haproxy
  testssl.sh
  iproute2 procps stress-ng
  podman buildah runc mmdebstrap fuse-overlayfs slirp4netns uidmap busybox-static
)
APT_PACKAGES=()
wants run && APT_PACKAGES+=("${RUN_PACKAGES[@]}")
wants python && APT_PACKAGES+=("${PYTHON_PACKAGES[@]}")
wants test && APT_PACKAGES+=("${RUN_PACKAGES[@]}" "${PYTHON_PACKAGES[@]}" "${TEST_PACKAGES[@]}")

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing Debian packages: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  # Never pull libboost-dev: it means Boost 1.74, which conflicts with 1.81.
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# Python: the official Robot Raconteur package (pinned) for interop tests, in a project venv.
if wants python || wants test; then
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
req=test/interop/requirements.txt
stamp=.venv/.requirements.sha
want=$(sha256sum "$req" | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing Python packages from $req"
  .venv/bin/pip install -q --disable-pip-version-check -r "$req"
  echo "$want" > "$stamp"
fi
fi
# npm: the dashboard's packages (web/package.json, pinned; package-lock.json). No browser downloads:
# the browser tests use Debian's /usr/bin/chromium.
export PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1
if ! command -v npm >/dev/null; then   # (a nodesource nodejs brings its own npm; Debian's is separate)
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends nodejs npm
fi
lock=web/package-lock.json
stamp=web/node_modules/.lock.sha
want=$(sha256sum "$lock" | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing npm packages from $lock"
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
  echo "$want" > "$stamp"
fi
# npm: the WebAssembly client's test dependency (`ws`, wasm-client/package-lock.json).
if wants test; then
lock=wasm-client/package-lock.json
stamp=wasm-client/node_modules/.lock.sha
want=$(sha256sum "$lock" | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing npm packages from $lock"
  (cd wasm-client && npm ci --no-audit --no-fund --loglevel=error)
  echo "$want" > "$stamp"
fi
# npm: the React example's packages (react, react-dom, esbuild; examples/react/package-lock.json).
lock=examples/react/package-lock.json
stamp=examples/react/node_modules/.lock.sha
want=$(sha256sum "$lock" | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing npm packages from $lock"
  (cd examples/react && npm ci --no-audit --no-fund --loglevel=error)
  echo "$want" > "$stamp"
fi
fi
# npm: the TypeScript reference MCAP implementation for the MCAP interop test (test/mcap/package-lock.json).
if wants test; then
lock=test/mcap/package-lock.json
stamp=test/mcap/node_modules/.lock.sha
want=$(sha256sum "$lock" | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing npm packages from $lock"
  (cd test/mcap && npm ci --no-audit --no-fund --loglevel=error)
  echo "$want" > "$stamp"
fi
fi
# npm: the official Foxglove WebSocket client for the gateway's Foxglove tests (test/foxglove/package-lock.json).
if wants test; then
lock=test/foxglove/package-lock.json
stamp=test/foxglove/node_modules/.lock.sha
want=$(sha256sum "$lock" | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing npm packages from $lock"
  (cd test/foxglove && npm ci --no-audit --no-fund --loglevel=error)
  echo "$want" > "$stamp"
fi
fi
echo "setup: ok (${parts[*]})"
