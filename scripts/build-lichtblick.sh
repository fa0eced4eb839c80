#!/usr/bin/env bash
# Builds the Lichtblick web app (the open-source Foxglove Studio, github.com/lichtblick-suite/lichtblick)
# from a source tree, for test/record/lichtblick_open_test.mjs (docs/recording.md "Opening a recording
# in Foxglove or Lichtblick"). Not run by setup.sh or CI: Lichtblick's sources come from GitHub.
#
#   scripts/build-lichtblick.sh SRC_DIR [OUT_DIR]
#     SRC_DIR  a git work tree of Lichtblick (tested: 1.10.8, `git clone <lichtblick repo> SRC_DIR`)
#              (1.28.1 did not install here: the npm registry reachable from these machines lacks
#              flatbuffers_reflection 1.3.0 and @lichtblick/rosbag2 1.0.7, which 1.10.8 does not need)
#     OUT_DIR  where the built app is copied (replaced if present); default ~/.cache/rr-gateway/lichtblick-web,
#              where the test finds it without LICHTBLICK_WEB
#   ctest --preset debug -R lichtblick     (or LICHTBLICK_WEB=OUT_DIR ctest ... for another folder)
#
# What it does, in SRC_DIR (idempotent; about 2 min of yarn install and 2 min of webpack on 2 vCPUs):
# - yarn 3 through corepack, fetched from the npm registry (COREPACK_NPM_REGISTRY), and packages from
#   registry.npmjs.org; the repository's yarn plugins are dropped from .yarnrc.yml when they are Git LFS
#   pointers (a source snapshot without LFS objects): install and build do not use them;
# - fonts that are Git LFS pointers are replaced by DejaVu fonts compressed with woff2_compress
#   (Debian packages fonts-dejavu-core and woff2): the app loads its fonts at start and stays blank
#   when they do not decode. Other LFS pointers (icons, thumbnails) only show as broken images;
# - no Electron, Playwright or Puppeteer binary downloads; then `yarn web:build:prod`.
# The app is SRC_DIR/web/.webpack: static files, served by any HTTP server.
set -euo pipefail

src=${1:?usage: scripts/build-lichtblick.sh SRC_DIR [OUT_DIR]}
out=$(realpath -m "${2:-$HOME/.cache/rr-gateway/lichtblick-web}")
cd "$src"
[ -f package.json ] && grep -q '"name": "lichtblick"' package.json || { echo "build-lichtblick: $src is not a Lichtblick source tree" >&2; exit 2; }

is_lfs_pointer() { head -c 100 "$1" | grep -q '^version https://git-lfs.github.com/spec/v1'; }

# yarn plugins that are LFS pointers: out of .yarnrc.yml
if grep -q '^plugins:' .yarnrc.yml && is_lfs_pointer .yarn/plugins/@yarnpkg/plugin-workspace-tools.cjs; then
  python3 - <<'EOF'
import re
s = open(".yarnrc.yml").read()
s = re.sub(r"^plugins:\n(?:  .*\n)+\n?", "", s, flags=re.M)
open(".yarnrc.yml", "w").write(s)
EOF
fi
grep -q '^npmRegistryServer:' .yarnrc.yml || printf '\nnpmRegistryServer: "https://registry.npmjs.org"\n' >> .yarnrc.yml

# fonts that are LFS pointers: DejaVu instead (same file names, so the CSS and imports are unchanged)
dejavu=/usr/share/fonts/truetype/dejavu
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for f in $(find packages -name '*.woff2' -not -path '*/node_modules/*'); do
  is_lfs_pointer "$f" || continue
  command -v woff2_compress > /dev/null || { echo "build-lichtblick: woff2_compress missing (apt-get install woff2)" >&2; exit 2; }
  name=$(basename "$f" .woff2)
  family=DejaVuSans; case "$name" in PlexMono*) family=DejaVuSansMono ;; esac
  style=""
  case "$name" in *BoldItalic|*SemiBoldItalic) style=-BoldOblique ;; *Bold|*SemiBold) style=-Bold ;; *Italic) style=-Oblique ;; esac
  cp "$dejavu/$family$style.ttf" "$tmp/$name.ttf"
  woff2_compress "$tmp/$name.ttf" > /dev/null 2>&1
  cp "$tmp/$name.woff2" "$f"
done

export COREPACK_NPM_REGISTRY=https://registry.npmjs.org COREPACK_ENABLE_DOWNLOAD_PROMPT=0
export ELECTRON_SKIP_BINARY_DOWNLOAD=1 PUPPETEER_SKIP_DOWNLOAD=1 PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1
corepack yarn install
corepack yarn web:build:prod
[ -f web/.webpack/index.html ] || { echo "build-lichtblick: webpack wrote no web/.webpack/index.html" >&2; exit 1; }
if [ -n "$out" ] && [ "$out" != "$(realpath web/.webpack)" ]; then
  rm -rf "$out"
  mkdir -p "$(dirname "$out")"
  cp -a web/.webpack "$out"
fi
echo "build-lichtblick: built ${out:-$PWD/web/.webpack}"
