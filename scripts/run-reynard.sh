#!/usr/bin/env bash
# Reynard the Robot (PyPI reynard-the-robot, from .venv) behind the gateway, next to the demo devices:
# starts Reynard headless (RR service `reynard` on 127.0.0.1:29200, its own web UI on
# http://localhost:29201/), then ./scripts/run.sh --config gateway-config/reynard.yaml, which serves
# it as rr+tcp://localhost:8080/?service=reynard and rr+ws://localhost:8080/?service=reynard.
# Extra arguments go to rr-gateway. Stopping the gateway (Ctrl-C) stops Reynard too.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh run python

rr_port=${REYNARD_RR_PORT:-29200}
http_port=${REYNARD_HTTP_PORT:-29201}
# No local transport (it claims the node name system-wide) and no discovery broadcasts.
.venv/bin/python -u -m reynard_the_robot --disable-ascii-socket --http-port "$http_port" \
  --robotraconteur-tcp-port="$rr_port" --robotraconteur-tcp-listen-localhost=true \
  --robotraconteur-local-enable=false \
  --robotraconteur-tcp-ipv4-discovery=false --robotraconteur-tcp-ipv6-discovery=false &
reynard_pid=$!
config=gateway-config/reynard.yaml
cleanup() {
  local rc=$?  # the gateway's exit status is the script's
  # SIGTERM: a background job of a non-interactive shell ignores SIGINT.
  kill -TERM "$reynard_pid" 2>/dev/null || true
  wait "$reynard_pid" 2>/dev/null || true
  [ "$config" = gateway-config/reynard.yaml ] || rm -f "$config"
  exit "$rc"
}
trap cleanup EXIT
echo "run-reynard: Reynard starting (RR port $rr_port, web UI http://localhost:$http_port/)"

if [ "$rr_port" != 29200 ]; then
  config=$(mktemp --suffix=.yaml)
  sed "s/localhost:29200/localhost:$rr_port/" gateway-config/reynard.yaml > "$config"
fi
# Not exec: the trap stops Reynard when the gateway ends.
./scripts/run.sh --config "$config" "$@"
