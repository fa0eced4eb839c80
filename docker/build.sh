#!/usr/bin/env bash
# Builds the rr-gateway image (docker/Containerfile) with podman, or buildah when podman is missing;
# no Docker daemon. Installs its tools from apt when missing (idempotent).
#
#   docker/build.sh [--smoke]        -> ${RR_IMAGE:-localhost/rr-gateway:latest}
#
# Base image: debian:bookworm from a registry when one answers; otherwise a local one made once with
# mmdebstrap from the Debian mirror and imported as localhost/debian:bookworm-local (set
# RR_BASE_IMAGE to choose). The build context is the committed tree (git archive HEAD) plus web/dist
# when the dashboard was built. --smoke then runs the image (runc, low ulimits: crun cannot set the
# default ones in this kind of VM) and checks /livez and the demo devices over HTTP.
set -euo pipefail
cd "$(dirname "$0")/.."

need=(podman buildah fuse-overlayfs slirp4netns uidmap runc mmdebstrap)
missing=()
for p in "${need[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

tool=podman
command -v podman >/dev/null || tool=buildah
image=${RR_IMAGE:-localhost/rr-gateway:latest}
run_opts=(--runtime runc --ulimit nofile=1024:1024 --ulimit nproc=1024:1024)

base=${RR_BASE_IMAGE:-}
if [ -z "$base" ]; then
  if $tool image exists docker.io/library/debian:bookworm 2>/dev/null ||
     timeout 60 $tool pull -q docker.io/library/debian:bookworm >/dev/null 2>&1; then
    base=docker.io/library/debian:bookworm
  else
    base=localhost/debian:bookworm-local
    if ! $tool image exists "$base"; then
      echo "build: no registry reachable; making $base with mmdebstrap"
      tar=$(mktemp --suffix=.tar)
      mmdebstrap --quiet --variant=apt --include=ca-certificates bookworm "$tar"
      $tool import "$tar" "$base" >/dev/null
      rm -f "$tar"
    fi
  fi
fi
echo "build: base image $base"

ctx=$(mktemp -d)
trap 'rm -rf "$ctx"' EXIT
# The committed tree (HEAD), so that edits in progress never reach the image.
git archive --format=tar HEAD | tar -xf - -C "$ctx"
if [ -f web/dist/index.html ]; then
  mkdir -p "$ctx/web/dist" && cp -r web/dist/. "$ctx/web/dist/"
else
  echo "build: web/dist not built; the image serves no dashboard (JSON API and RR only)"
fi

if [ "$tool" = podman ]; then
  podman build "${run_opts[@]}" --network host --build-arg "BASE=$base" -f "$ctx/docker/Containerfile" -t "$image" "$ctx"
else
  buildah bud --runtime runc --network host --build-arg "BASE=$base" -f "$ctx/docker/Containerfile" -t "$image" "$ctx"
fi
echo "build: $image"

if [ "${1:-}" = --smoke ]; then
  port=${RR_SMOKE_PORT:-18480}
  name=rr-gateway-smoke-$$
  podman run "${run_opts[@]}" --rm -d --name "$name" --network host "$image" --port "$port" >/dev/null
  trap 'podman stop -t 5 "$name" >/dev/null 2>&1 || true; rm -rf "$ctx"' EXIT
  for _ in $(seq 100); do
    curl -fsS "http://127.0.0.1:$port/readyz" >/dev/null 2>&1 && break
    sleep 0.2
  done
  curl -fsS "http://127.0.0.1:$port/livez"
  curl -fsS "http://127.0.0.1:$port/api/devices"
  echo
  echo "build: smoke test passed (rr-gateway in $image serves the demo devices)"
fi
