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
# rr-robdef for node: the package's `rr-robdef` command (src/rr_robdef.mjs, package.json "bin") runs it
copy_if_changed "$build/rr_robdef_node.cjs" "$dist/rr_robdef_node.cjs"
copy_if_changed "$build/rr_robdef_node.wasm" "$dist/rr_robdef_node.wasm"
for f in "$here"/src/*.mjs "$here"/src/*.d.ts; do copy_if_changed "$f" "$dist/$(basename "$f")"; done
chmod +x "$dist/rr_robdef.mjs"
copy_if_changed "$here/README.md" "$dist/README.md"
# The dashboard's folders that are packages of their own, each copied whole with its declarations and
# nothing else (they import nothing from outside their folder but each other: web/test/std_package.test.mjs):
#   web/src/std   -> dashboard/std   (standard-type renderers, image decoding, readable text):
#                    import { ... } from "robotraconteur-wasm/std" (dashboard/std/index.js)
#   web/src/robot -> dashboard/robot (forward kinematics, the three.js view, ...):
#                    import { ... } from "robotraconteur-wasm/robot/kinematics.js"
web="$root/web/src"
for folder in std robot; do
  mkdir -p "$dist/dashboard/$folder"
  for f in "$web/$folder"/*.js "$web/$folder"/*.d.ts; do [ -f "$f" ] && copy_if_changed "$f" "$dist/dashboard/$folder/$(basename "$f")"; done
  for f in "$dist/dashboard/$folder"/*; do [ -f "$web/$folder/$(basename "$f")" ] || rm -f "$f"; done
done
# what older builds put beside std/ (the page modules std once imported)
rm -f "$dist"/dashboard/*.js
# The standard service definitions as TypeScript (`rr-robdef ts`, robdef/typescript.hpp; the node build of
# rr-robdef from this build folder): dist/types/std/<service>.d.ts + .js, imported as
# "robotraconteur-wasm/std/<service>" (package.json exports "./std/*"; "./std" alone stays the dashboard's
# standard-type modules above). The definitions are never copied into the repo: they come from
# RR_ROBDEF_STANDARD if set, else the official robotraconteurcompanion package in .venv (PyPI, pinned in
# test/interop/requirements.txt; the same files the drivers load), else the shared folder next to the clone.
std_robdefs="${RR_ROBDEF_STANDARD:-}"
if [ -z "$std_robdefs" ]; then
  for d in "$root"/.venv/lib/python3*/site-packages/RobotRaconteurCompanion/StdRobDef \
           "$root/../shared/robdef-standard/group1"; do
    if compgen -G "$d/*.robdef" >/dev/null; then std_robdefs="$d"; break; fi
  done
fi
if compgen -G "$std_robdefs/*.robdef" >/dev/null; then
  gen="$build/std-types.tmp"
  rm -rf "$gen"
  # --no-experimental-fetch: emscripten 3.1.6 would fetch() the .wasm by path under node 18+
  node --no-experimental-fetch "$build/rr_robdef_node.cjs" ts --dts -o "$gen" "$std_robdefs"/*.robdef
  mkdir -p "$dist/types/std"
  for f in "$gen"/*; do copy_if_changed "$f" "$dist/types/std/$(basename "$f")"; done
  for f in "$dist"/types/std/*; do [ -f "$gen/$(basename "$f")" ] || rm -f "$f"; done
  rm -rf "$gen"
else
  echo "wasm-client/build.sh: no standard *.robdef found (RR_ROBDEF_STANDARD, .venv's robotraconteurcompanion, ../shared): the package has no standard TypeScript types (std/*)" >&2
fi
copy_if_changed "$here/src/package.dist.json" "$dist/package.json"
echo "wasm-client: package in $dist"
