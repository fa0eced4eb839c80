#!/bin/sh
# Build stage helper (docker/Containerfile): gathers the runtime image's root file system in OUT from
# the build folder BUILD and the source tree SRC: binaries, the shared libraries they load (as ldd
# resolves them, plus the dynamic loader), static busybox, CA bundle, the user rr-gateway (10001).
# The folders the gateway writes go to OUT-rw instead: the Containerfile copies them with
# --chown=10001:10001 (a plain COPY --from makes everything root's).
#   rootfs.sh BUILD SRC OUT
set -eu
build=$1 src=$2 out=$3
mkdir -p "$out/usr/local/bin" "$out/bin" "$out/etc/rr-gateway/examples" "$out/etc/ssl/certs" \
         "$out/usr/local/share/rr-gateway/web" "$out/tmp" \
         "$out-rw/run/rr-gateway" "$out-rw/var/lib/rr-gateway"
cp "$build/server/app/rr-gateway" "$build/server/demo/rr-demo-devices" "$out/usr/local/bin/"
strip "$out/usr/local/bin/rr-gateway" "$out/usr/local/bin/rr-demo-devices"
cp "$src/docker/entrypoint.sh" "$out/usr/local/bin/rr-gateway-entrypoint"
chmod 755 "$out/usr/local/bin/rr-gateway-entrypoint"
# Shared libraries: every resolved path from ldd (and the loader), copied to the same path.
for bin in "$out/usr/local/bin/rr-gateway" "$out/usr/local/bin/rr-demo-devices"; do
  ldd "$bin" | awk '/=> \// {print $3} /^\t\/[^ ]+ \(/ {print $1}'
done | sort -u | while read -r lib; do
  mkdir -p "$out$(dirname "$lib")"
  cp -L "$lib" "$out$lib"
done
# Debian's loader path (/lib64/ld-linux-x86-64.so.2 on amd64) may be a symlink into /lib/...; -L above
# copied the file itself. /lib is a symlink to usr/lib on bookworm: keep that layout.
[ -e "$out/lib" ] || ln -s usr/lib "$out/lib"
cp /bin/busybox "$out/bin/busybox"
for applet in sh wget id cat ls; do ln -s busybox "$out/bin/$applet"; done
cp /etc/ssl/certs/ca-certificates.crt "$out/etc/ssl/certs/"
printf 'root:x:0:0:root:/root:/sbin/nologin\nrr-gateway:x:10001:10001:rr-gateway:/var/lib/rr-gateway:/sbin/nologin\n' >"$out/etc/passwd"
printf 'root:x:0:\nrr-gateway:x:10001:\n' >"$out/etc/group"
cp "$src"/gateway-config/*.yaml "$out/etc/rr-gateway/examples/" 2>/dev/null || true
if [ -d "$src/web/dist" ]; then cp -r "$src/web/dist/." "$out/usr/local/share/rr-gateway/web/"; fi
chmod 700 "$out-rw/run/rr-gateway" "$out-rw/var/lib/rr-gateway"
chmod 1777 "$out/tmp"
