#!/usr/bin/env bash
# Assembles the dashboard in web/dist (or $1): the page and its ES modules, the RR client package
# (wasm-client/dist -> vendor/rr/), uPlot from node_modules (-> vendor/uplot/) and the parts of three.js
# the robot panel's 3D view loads (-> vendor/three/: the module build, OrbitControls, the licence;
# index.html's import map names them).
# Needs: wasm-client/dist built (wasm-client/build.sh) and `npm ci` run in web/ (scripts/setup.sh).
set -euo pipefail
cd "$(dirname "$0")"
out=${1:-dist}
rr=../wasm-client/dist
if [ ! -f "$rr/robotraconteur.mjs" ]; then
  echo "web/build.sh: $rr/robotraconteur.mjs missing: build the client package first (wasm-client/build.sh)" >&2
  exit 1
fi
if [ ! -f node_modules/uplot/dist/uPlot.esm.js ] || [ ! -f node_modules/three/build/three.module.js ]; then
  echo "web/build.sh: node_modules missing: run scripts/setup.sh (npm ci in web/)" >&2
  exit 1
fi
tmp=$(mktemp -d "${out%/}.tmp.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/vendor/rr" "$tmp/vendor/uplot" "$tmp/vendor/three/addons/controls"
cp index.html login.html style.css "$tmp/"
cp -R src "$tmp/src"
cp -R "$rr"/. "$tmp/vendor/rr/"
rm -rf "$tmp/vendor/rr/dashboard"   # the package's copy of src/std: the page has its own
cp node_modules/uplot/dist/uPlot.esm.js node_modules/uplot/dist/uPlot.min.css node_modules/uplot/LICENSE "$tmp/vendor/uplot/"
cp node_modules/three/build/three.module.js node_modules/three/build/three.core.js node_modules/three/LICENSE "$tmp/vendor/three/"
cp node_modules/three/examples/jsm/controls/OrbitControls.js "$tmp/vendor/three/addons/controls/"
rm -rf "$out"
mv "$tmp" "$out"
trap - EXIT
echo "web/build.sh: dashboard in web/$out"
