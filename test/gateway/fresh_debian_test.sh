#!/usr/bin/env bash
# The Debian package on a fresh Debian 12 root (docs/deployment.md §1): packs this build tree (prefix
# /usr), makes a minimal bookworm root with mmdebstrap, runs the page's install command in it (apt
# fetches the dependencies from the Debian mirror), then checks what the package promises: the
# rr-gateway user, /etc/rr-gateway/gateway.yaml 0640 root:rr-gateway, the unit, the gateway started as
# that user with that file and answering /readyz, and `apt-get purge` removing it all.
#
#   fresh_debian_test.sh BUILD_DIR DOC CPACK     (RR_PACKAGE_BUILD=DIR overrides BUILD_DIR)
#   fresh_debian_test.sh --prepare-root DIR      only makes the fresh root (with its package lists) in
#                                                DIR, for a later run with RR_FRESH_DEBIAN_ROOT=DIR,
#                                                which takes it (scripts/test.sh: the download runs
#                                                while the package is still compiling)
#
# Downloads about 100 MB and takes minutes, so it runs only with RR_FRESH_DEBIAN=1 (and as root, with
# mmdebstrap installed); otherwise it reports skipped (77) with the reason.
set -euo pipefail
# A minimal bookworm root with its package lists (an installed Debian machine has them) in $1.
make_root() {
  mmdebstrap --quiet --variant=apt bookworm "$1"
  cp /etc/resolv.conf "$1/etc/resolv.conf"
  chroot "$1" apt-get update -q >/dev/null
}
if [ "${1:-}" = --prepare-root ]; then
  dir=${2:?--prepare-root DIR}
  [ "$(id -u)" = 0 ] || { echo "SKIP: needs root (chroot)"; exit 77; }
  command -v mmdebstrap >/dev/null || { echo "SKIP: mmdebstrap not installed (apt-get install mmdebstrap)"; exit 77; }
  rm -rf "$dir"
  make_root "$dir" || { rm -rf "$dir"; exit 1; }
  touch "$dir/.rr-fresh-root-ready"
  echo "ok: a fresh bookworm root in $dir"
  exit 0
fi
build=$1 doc=$2 cpack=$3
# RR_PACKAGE_BUILD: pack that build folder instead (scripts/test.sh: its Release package build, so that
# what is installed is the package a user gets, not the sanitizer build the tests ran).
build=${RR_PACKAGE_BUILD:-$build}
echo "packing $build"

[ "${RR_FRESH_DEBIAN:-}" = 1 ] || { echo "SKIP: set RR_FRESH_DEBIAN=1 to run (downloads ~100 MB from the Debian mirror, several minutes)"; exit 77; }
[ "$(id -u)" = 0 ] || { echo "SKIP: needs root (chroot)"; exit 77; }
command -v mmdebstrap >/dev/null || { echo "SKIP: mmdebstrap not installed (apt-get install mmdebstrap)"; exit 77; }

work=$(mktemp -d /tmp/rr-fresh-debian-XXXXXX)
root=$work/root
gw=
cleanup() {
  [ -n "$gw" ] && kill "$gw" 2>/dev/null && wait "$gw" 2>/dev/null
  mountpoint -q "$root/proc" && umount "$root/proc"
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }

# The page's one install command, as written (without sudo: we are root in the chroot).
install_cmd=$(grep -E '^sudo apt-get install \./build/package/rr-gateway_.*\.deb$' "$doc" | head -1 | sed 's/^sudo //')
[ -n "$install_cmd" ] || fail "no 'sudo apt-get install ./build/package/…deb' line in $doc"
deb_path=$(echo "$install_cmd" | awk '{print $NF}')

"$cpack" --config "$build/CPackConfig.cmake" -G DEB -B "$work/pack" -D CPACK_INSTALL_PREFIX=/usr \
  -D CPACK_DEBIAN_COMPRESSION_TYPE=none >/dev/null
made=$(ls "$work"/pack/*.deb)
[ "$(basename "$made")" = "$(basename "$deb_path")" ] || fail "the page installs $(basename "$deb_path"), cpack made $(basename "$made")"

# A root made beforehand (--prepare-root) is taken, once: it is fresh until this run installs into it.
if [ -n "${RR_FRESH_DEBIAN_ROOT:-}" ] && [ -f "$RR_FRESH_DEBIAN_ROOT/.rr-fresh-root-ready" ]; then
  rm "$RR_FRESH_DEBIAN_ROOT/.rr-fresh-root-ready"
  mv "$RR_FRESH_DEBIAN_ROOT" "$root"
  echo "using the root prepared in $RR_FRESH_DEBIAN_ROOT"
else
  make_root "$root"
fi
mkdir -p "$root/root/$(dirname "$deb_path")"
cp "$made" "$root/root/$deb_path"
# -y: apt asks before installing (a person answers Y).
chroot "$root" sh -c "cd /root && DEBIAN_FRONTEND=noninteractive ${install_cmd/apt-get install/apt-get install -y}" >"$work/install.log" 2>&1 ||
  { tail -20 "$work/install.log"; fail "$install_cmd"; }
echo "ok: $install_cmd"

chroot "$root" getent passwd rr-gateway >/dev/null || fail "no rr-gateway user"
perm=$(chroot "$root" stat -c '%a %U:%G' /etc/rr-gateway/gateway.yaml)
[ "$perm" = "640 root:rr-gateway" ] || fail "gateway.yaml is $perm"
grep -q '^ExecStart=/usr/bin/rr-gateway --config /etc/rr-gateway/gateway.yaml$' "$root/lib/systemd/system/rr-gateway.service" ||
  fail "unit ExecStart"
echo "ok: user rr-gateway, gateway.yaml 640 root:rr-gateway, the unit"

mount -t proc proc "$root/proc"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
# As the unit runs it: user rr-gateway, the installed configuration (a free port instead of 8080), the
# unit's RuntimeDirectory and StateDirectory (systemd makes them, owned by the user, and sets
# STATE_DIRECTORY: the recordings root's default) and its Environment= line with systemd's %t (/run) and
# %S (/var/lib) filled in. No systemd runs in the root.
unit="$root/lib/systemd/system/rr-gateway.service"
run_dir=$(sed -n 's/^RuntimeDirectory=//p' "$unit")
state_dir=$(sed -n 's/^StateDirectory=//p' "$unit")
unit_env=$(sed -n 's/^Environment=//p' "$unit" | sed -e 's#%t#/run#g' -e 's#%S#/var/lib#g')
[ -n "$run_dir" ] && [ -n "$state_dir" ] || fail "the unit has no RuntimeDirectory/StateDirectory"
chroot "$root" install -d -o rr-gateway -g rr-gateway -m 0755 "/run/$run_dir" "/var/lib/$state_dir"
# shellcheck disable=SC2086  # the unit's VAR=value words, split as systemd does (no quotes in them)
chroot "$root" setpriv --reuid=rr-gateway --regid=rr-gateway --init-groups \
  env HOME=/nonexistent STATE_DIRECTORY="/var/lib/$state_dir" $unit_env \
  /usr/bin/rr-gateway --config /etc/rr-gateway/gateway.yaml --port "$port" --log-level warning >"$work/gw.out" 2>&1 &
gw=$!
for _ in $(seq 150); do
  curl -fsS "http://127.0.0.1:$port/readyz" >/dev/null 2>&1 && break
  sleep 0.2
done
curl -fsS "http://127.0.0.1:$port/api/devices" | grep -q '"create"' || { cat "$work/gw.out"; fail "the installed gateway does not serve its demo devices"; }
chroot "$root" find "/run/$run_dir" -type s | grep -q . || fail "no rr+local socket in /run/$run_dir (the unit's Environment=)"
# A recording goes below the state directory's recordings folder (docs/recording.md "Where recordings go").
for _ in $(seq 50); do
  code=$(curl -sS -o "$work/rec.json" -w '%{http_code}' -X POST "http://127.0.0.1:$port/api/recordings" \
    -d '{"device": "create", "members": ["packets"], "directory": "check", "duration_s": 1}' 2>/dev/null) || code=000
  [ "$code" = 201 ] && break
  sleep 0.2
done
[ "$code" = 201 ] || { cat "$work/rec.json" "$work/gw.out"; fail "a recording does not start (HTTP $code)"; }
chroot "$root" find "/var/lib/$state_dir/recordings/check" -name 'create-*.mcap' | grep -q . ||
  fail "no recording in /var/lib/$state_dir/recordings/check"
kill "$gw"
wait "$gw" || fail "the gateway exited with $? on SIGTERM"
gw=
umount "$root/proc"
echo "ok: the installed gateway ran as rr-gateway with /etc/rr-gateway/gateway.yaml and the unit's environment, recording into /var/lib/$state_dir/recordings"

chroot "$root" sh -c 'DEBIAN_FRONTEND=noninteractive apt-get purge -y rr-gateway' >/dev/null 2>&1 || fail "apt-get purge"
[ ! -e "$root/etc/rr-gateway" ] && [ ! -e "$root/usr/bin/rr-gateway" ] || fail "files left after purge"
echo "ok: apt-get purge removes it"
echo "PASS"
