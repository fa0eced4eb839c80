#!/usr/bin/env bash
# The main job: installs what is missing for running (scripts/setup.sh run: no test tools), builds
# rr-gateway (release preset, tests off), builds
# the web dashboard when its build scripts exist (wasm-client/build.sh, then web/build.sh), and runs
# rr-gateway in the foreground. With no arguments the gateway starts its two embedded demo devices
# (experimental.create and experimental.createwebcam) and serves everything on http://localhost:8080/.
# Arguments go to rr-gateway, e.g. `./scripts/run.sh --config gateway-config/reynard.yaml` or `--port 9090`
# (see docs/gateway-config.md). RR_BUILD_DIR=build/x builds there instead of the preset's build/release.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh run

jobs=${RR_JOBS:-$(nproc)}
if [ -n "${RR_BUILD_DIR:-}" ]; then
  build=$RR_BUILD_DIR
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRR_BUILD_TESTS=OFF >/dev/null
  cmake --build "$build" -j "$jobs" --target rr-gateway
else
  build=build/release
  # Tests off: running needs no Catch2 (scripts/test.sh builds and runs them in build/debug).
  cmake --preset release -DRR_BUILD_TESTS=OFF >/dev/null
  cmake --build --preset release -j "$jobs" --target rr-gateway
fi

# The dashboard: other parts of the tree may not have it yet; the gateway runs without it (JSON API,
# RR over TCP and WebSocket), so a missing or failing dashboard build is reported, not fatal.
dashboard=ok
for step in wasm-client/build.sh web/build.sh; do
  if [ ! -f "$step" ]; then
    echo "run: $step not present, skipping"
    dashboard=absent
    continue
  fi
  echo "run: $step"
  if ! bash "$step"; then
    echo "run: WARNING: $step failed; starting the gateway without a fresh dashboard" >&2
    dashboard=failed
  fi
done
if [ "$dashboard" = ok ] && [ ! -f web/dist/index.html ]; then
  echo "run: WARNING: web/dist/index.html missing after the dashboard build" >&2
fi

# The URL to open: a --port / --robotraconteur-tcp-port flag, else 8080 unless a config file may set
# gateway.port (the gateway's own log line names the URL in every case).
port="" config=""
args=("$@")
for ((i = 0; i < ${#args[@]}; i++)); do
  case "${args[$i]}" in
    --port=* | --robotraconteur-tcp-port=*) port=${args[$i]#*=} ;;
    --port | --robotraconteur-tcp-port) port=${args[$((i + 1))]:-} ;;
    --config | --config=*) config=yes ;;
  esac
done
[ -z "$port" ] && [ -z "$config" ] && port=8080
if [ -n "$port" ]; then
  echo "run: starting rr-gateway: open http://localhost:$port/ (Ctrl-C stops it)"
else
  echo "run: starting rr-gateway ${args[*]} (its log line names the URL; Ctrl-C stops it)"
fi
exec "$build/server/app/rr-gateway" "$@"
