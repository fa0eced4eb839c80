#!/bin/sh
# rr-gateway's entry point in the container image: turns RR_GATEWAY_* variables into rr-gateway flags,
# then runs it with the container's arguments last (so they win over the variables).
#   RR_GATEWAY_CONFIG       configuration file (default /etc/rr-gateway/gateway.yaml when mounted)
#   RR_GATEWAY_LISTEN       listen address (default ::, every address of both IP families, as rr-gateway's
#                           own default, so that a published port reaches it whatever a mounted file says;
#                           0.0.0.0 on a kernel without IPv6)
#   RR_GATEWAY_PORT         RR + HTTP + WebSocket port (default 8080; the HEALTHCHECK uses it too)
#   RR_GATEWAY_LOG_LEVEL    trace, debug, info, warning, error
#   RR_GATEWAY_LOG_FORMAT   text or json
#   RR_GATEWAY_WEB_ROOT     dashboard files (default /usr/local/share/rr-gateway/web)
set -eu
config=${RR_GATEWAY_CONFIG:-}
if [ -z "$config" ] && [ -f /etc/rr-gateway/gateway.yaml ]; then config=/etc/rr-gateway/gateway.yaml; fi
set -- --web-root "${RR_GATEWAY_WEB_ROOT:-/usr/local/share/rr-gateway/web}" "$@"
[ -n "${RR_GATEWAY_LOG_FORMAT:-}" ] && set -- --log-format "$RR_GATEWAY_LOG_FORMAT" "$@"
[ -n "${RR_GATEWAY_LOG_LEVEL:-}" ] && set -- --log-level "$RR_GATEWAY_LOG_LEVEL" "$@"
[ -n "${RR_GATEWAY_PORT:-}" ] && set -- --port "$RR_GATEWAY_PORT" "$@"
set -- --listen "${RR_GATEWAY_LISTEN:-::}" "$@"
[ -n "$config" ] && set -- --config "$config" "$@"
exec /usr/local/bin/rr-gateway "$@"
