#!/usr/bin/env bash
# Builds the rr-gateway image (docker/Containerfile) with podman, or buildah when podman is missing;
# no Docker daemon, and no container registry unless you name a base image that lives in one.
#
#   docker/build.sh [--base IMAGE] [--tag IMAGE] [--smoke] [--print-key] [--from-build DIR]
#                   [--record-verified] [--print-from-source-key]
#
#   --base IMAGE   the build stage's base (also RR_BASE_IMAGE), e.g. docker.io/library/debian:bookworm
#                  where a registry answers. Default: localhost/debian:bookworm-local, made once from
#                  Debian's packages with mmdebstrap (the Debian mirror, no registry) and imported.
#   --tag IMAGE    the result (also RR_IMAGE; default localhost/rr-gateway:latest)
#   --smoke        then run it once: /livez and the demo devices over HTTP
#   --print-key    print the inputs key (below) and exit
#   --record-verified  after a from-source build (and --smoke) passed, write docker/from-source.verified:
#                  the key of what that build's success depends on beyond the sources the package build
#                  compiles too (docker/, packaging/, cmake/, the top CMakeLists.txt,
#                  and what any CMakeLists.txt looks for on the system: find_package and the like, as a
#                  new dependency must reach the Containerfile's package list), and the commit.
#                  scripts/test.sh skips the from-source build while that key is unchanged
#   --print-from-source-key  print that key and exit
#   --from-build DIR  no compile: the runtime image from the Release binaries of build folder DIR
#                  (e.g. build/package, which scripts/test.sh has built anyway), its root file system
#                  gathered here by docker/rootfs.sh and given as the build context named
#                  "build", which replaces the Containerfile's build stage. This host's
#                  libraries go into the image, so DIR must come from a Debian 12 host like the base
#                  image's. Label rr.inputs=prebuilt-<sha256 of the root file system>
#
# The runtime stage is FROM scratch (docker/rootfs.sh gathers its files), so nothing else is pulled.
# The build context is the committed tree (git archive HEAD) of what the binaries are built from, plus
# web/dist when the dashboard was built. The image carries the label rr.inputs=<sha256 of that context
# and the base>: test/container reuses an image whose label matches instead of building again.
# Installs podman, buildah, runc and mmdebstrap from apt when missing (idempotent).
set -euo pipefail
cd "$(dirname "$0")/.."

base=${RR_BASE_IMAGE:-}
image=${RR_IMAGE:-localhost/rr-gateway:latest}
smoke="" print_key="" from_build="" record="" print_fs_key=""
while (($#)); do
  case "$1" in
    --base) base=$2; shift 2 ;;
    --base=*) base=${1#*=}; shift ;;
    --tag) image=$2; shift 2 ;;
    --tag=*) image=${1#*=}; shift ;;
    --smoke) smoke=1; shift ;;
    --print-key) print_key=1; shift ;;
    --record-verified) record=1; shift ;;
    --print-from-source-key) print_fs_key=1; shift ;;
    --from-build) from_build=$2; shift 2 ;;
    --from-build=*) from_build=${1#*=}; shift ;;
    *) echo "build: unknown argument $1" >&2; exit 2 ;;
  esac
done
local_base=localhost/debian:bookworm-local
[ -n "$base" ] || base=$local_base

# What the image is built from (keep in step with the Containerfile's COPY and rootfs.sh).
inputs=(CMakeLists.txt CMakePresets.json cmake base core robdef server packaging gateway-config
        docker/Containerfile docker/rootfs.sh docker/entrypoint.sh docker/build.sh)
key() {
  {
    echo "base=$base"
    git ls-tree -r HEAD -- "${inputs[@]}"
    if [ -f web/dist/index.html ]; then (cd web/dist && find . -type f -print0 | sort -z | xargs -0 sha256sum); fi
  } | sha256sum | cut -d' ' -f1
}
if [ -n "$print_key" ] && [ -z "$from_build" ]; then key; exit 0; fi
verified=docker/from-source.verified
from_source_key() {
  {
    git ls-tree -r HEAD -- docker packaging cmake CMakeLists.txt | grep -v "	$verified\$"
    # What every other CMakeLists.txt asks of the system: a new dependency must reach the Containerfile.
    git grep -h -E 'find_package|pkg_check_modules|find_library|find_program|find_path' HEAD -- '*CMakeLists.txt' | sort
  } | sha256sum | cut -d' ' -f1
}
if [ -n "$print_fs_key" ]; then from_source_key; exit 0; fi

need=(podman buildah fuse-overlayfs slirp4netns uidmap runc mmdebstrap busybox-static)
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
# crun cannot set podman's default ulimits in this kind of VM; runc with low ones works (TOOLCHAIN §5).
run_opts=(--runtime runc --ulimit nofile=1024:1024 --ulimit nproc=1024:1024)

ctx=$(mktemp -d)
trap 'rm -rf "$ctx"' EXIT

# podman build / buildah bud with the options this VM needs (TOOLCHAIN §5).
build_image() {
  if [ "$tool" = podman ]; then
    podman build "${run_opts[@]}" --format docker "$@"
  else
    buildah bud --runtime runc --format docker "$@"
  fi
}

if [ -n "$from_build" ]; then
  [ -x "$from_build/server/app/rr-gateway" ] && [ -x "$from_build/server/demo/rr-demo-devices" ] ||
    { echo "build: $from_build has no rr-gateway and rr-demo-devices (build them first)" >&2; exit 1; }
  [ -x /bin/busybox ] || { echo "build: /bin/busybox missing (apt-get install busybox-static)" >&2; exit 1; }
  # The root file system the build stage would make, from DIR's binaries, this tree and web/dist.
  mkdir -p "$ctx/docker" "$ctx/rootfs"
  cp docker/Containerfile "$ctx/docker/"
  sh docker/rootfs.sh "$from_build" . "$ctx/rootfs/out" >/dev/null
  k=prebuilt-$( (cd "$ctx/rootfs" && find . -type f -print0 | sort -z | xargs -0 sha256sum) | sha256sum | cut -d' ' -f1)
  if [ -n "$print_key" ]; then echo "$k"; exit 0; fi
  build_image --pull=never --build-context "build=$ctx/rootfs" --label "rr.inputs=$k" -f "$ctx/docker/Containerfile" -t "$image" "$ctx"
  echo "build: from $from_build, no compile"
else
  pull=(--pull=never)
  if [ "$base" = "$local_base" ]; then
    if ! $tool image exists "$base" 2>/dev/null; then
      echo "build: making $base from Debian's packages (mmdebstrap, no registry)"
      tar=$(mktemp --suffix=.tar)
      # The mirror apt uses on this machine (mmdebstrap's default otherwise).
      mirror=$(grep -rhoE '^(URIs:|deb) +https?://[^ ]+' /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null |
               awk '{print $2}' | grep -E '/debian/?$' | head -1 || true)
      mmdebstrap --quiet --variant=apt --include=ca-certificates bookworm "$tar" ${mirror:+"$mirror"}
      $tool import "$tar" "$base" >/dev/null
      rm -f "$tar"
    fi
  else
    pull=(--pull=missing)   # a base the user named: the engine pulls it if it is not here yet
  fi
  echo "build: base image $base"

  # The committed tree (HEAD), so that edits in progress never reach the image.
  git archive --format=tar HEAD -- "${inputs[@]}" | tar -xf - -C "$ctx"
  if [ -f web/dist/index.html ]; then
    mkdir -p "$ctx/web/dist" && cp -r web/dist/. "$ctx/web/dist/"
  else
    echo "build: web/dist not built; the image serves no dashboard (JSON API and RR only)"
  fi
  k=$(key)
  build_image "${pull[@]}" --network host --build-arg "BASE=$base" --label "rr.inputs=$k" \
    -f "$ctx/docker/Containerfile" -t "$image" "$ctx"
fi
size=$($tool image inspect --format '{{.Size}}' "$image" 2>/dev/null || echo 0)
echo "build: $image ($((size / 1000000)) MB, rr.inputs=$k)"

if [ -n "$smoke" ]; then
  port=${RR_SMOKE_PORT:-18480}
  name=rr-gateway-smoke-$$
  podman run "${run_opts[@]}" --rm -d --name "$name" -p "127.0.0.1:$port:8080" "$image" >/dev/null
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

if [ -n "$record" ] && [ -z "$from_build" ]; then
  {
    echo "# The Containerfile's from-source build (docker/build.sh${smoke:+ --smoke}) passed with these inputs;"
    echo "# scripts/test.sh skips that build while they are unchanged (docker/build.sh --record-verified)."
    echo "key $(from_source_key)"
    echo "commit $(git rev-parse HEAD)"
    echo "date $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  } >"$verified"
  echo "build: wrote $verified"
fi
