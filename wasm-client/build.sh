#!/usr/bin/env bash
# Builds the WebAssembly client package into wasm-client/dist (idempotent and incremental):
#   robotraconteur.mjs (JS API), robotraconteur_wasm.mjs + .wasm (Emscripten module), index.d.ts,
#   package.json, README.md. Build folder: build/wasm (private). Needs Debian's emscripten + node-acorn.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
build="$root/build/wasm"
dist="$here/dist"
export NODE_PATH=/usr/share/nodejs   # emscripten 3.1.6 finds acorn there (package node-acorn)

# One build at a time: scripts/test.sh, scripts/run.sh and people share this folder and dist/.
mkdir -p "$build"
exec 9>"$build.lock"
flock 9

if ! command -v emcmake >/dev/null; then
  echo "wasm-client/build.sh: emscripten (emcmake) not found; run scripts/setup.sh" >&2
  exit 77
fi
# MinSizeRel (-Os): half the .wasm of -O3 (450 KB against 930 KB), which matters more to a browser.
type="${RR_WASM_BUILD_TYPE:-MinSizeRel}"
if ! grep -qx "CMAKE_BUILD_TYPE:STRING=$type" "$build/CMakeCache.txt" 2>/dev/null; then
  emcmake cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="$type" \
    -DCMAKE_CROSSCOMPILING_EMULATOR=/usr/bin/node >/dev/null
fi
cmake --build "$build" -j "${RR_JOBS:-2}"

mkdir -p "$dist"
# Replace each file in one step (readers never see half a file).
copy_if_changed() { cmp -s "$1" "$2" 2>/dev/null || { cp "$1" "$2.tmp$$" && mv -f "$2.tmp$$" "$2"; }; }
copy_if_changed "$build/robotraconteur_wasm.mjs" "$dist/robotraconteur_wasm.mjs"
copy_if_changed "$build/robotraconteur_wasm.wasm" "$dist/robotraconteur_wasm.wasm"
for f in robotraconteur.mjs errors.mjs proxy.mjs index.d.ts; do copy_if_changed "$here/src/$f" "$dist/$f"; done
copy_if_changed "$here/README.md" "$dist/README.md"
# The dashboard's standard-type modules (web/src/std: renderers, image decoding, readable text) for
# the package's users, with the three page modules they import, in the same layout:
# import { ... } from "robotraconteur-wasm/std" (dist/dashboard/std/index.js).
web="$root/web/src"
mkdir -p "$dist/dashboard/std"
for f in rr_types.js value_codec.js robdef_outline.js; do copy_if_changed "$web/$f" "$dist/dashboard/$f"; done
for f in "$web"/std/*.js "$web"/std/index.d.ts; do copy_if_changed "$f" "$dist/dashboard/std/$(basename "$f")"; done
for f in "$dist"/dashboard/std/*.js; do [ -f "$web/std/$(basename "$f")" ] || rm -f "$f"; done
# The robot modules (web/src/robot: forward kinematics, the three.js view, ...), the whole folder with
# its declarations: import { ... } from "robotraconteur-wasm/robot/kinematics.js" (dashboard/robot/).
mkdir -p "$dist/dashboard/robot"
for f in "$web"/robot/*.js "$web"/robot/*.d.ts; do [ -f "$f" ] && copy_if_changed "$f" "$dist/dashboard/robot/$(basename "$f")"; done
for f in "$dist"/dashboard/robot/*; do [ -f "$web/robot/$(basename "$f")" ] || rm -f "$f"; done
copy_if_changed "$here/src/package.dist.json" "$dist/package.json"
echo "wasm-client: package in $dist"
