#!/usr/bin/env bash
# The test command: installs what is missing (scripts/setup.sh: the run packages and the test tools:
# Catch2, Chromium, nginx, clang, umockdev, the Python venv), builds the debug preset (ASan + UBSan),
# runs every test (unit, interop against the official library), the server tests again under
# ThreadSanitizer (with RR_TSAN=1), then builds the libFuzzer targets and runs each
# briefly (scripts/fuzz.sh; RR_FUZZ_SECONDS=N for N seconds each, 0 for none). Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh

jobs=${RR_JOBS:-$(nproc)}
cmake --preset debug >/dev/null
cmake --build --preset debug -j "$jobs"
# The WebAssembly client package (wasm-client/dist; build folder build/wasm), tested by ctest.
./wasm-client/build.sh
# The dashboard (web/dist) on the client package, for the browser tests (they skip without it).
if [ -f wasm-client/dist/robotraconteur.mjs ]; then
  ./web/build.sh
else
  echo "test: wasm-client/dist missing: the browser tests will be skipped"
fi
ctest --preset debug -j "$jobs"

# ThreadSanitizer (issue 16): the threaded server tests (node, client, gateway, transports: the
# "server: " tests of rr_server_tests) built with -fsanitize=thread in build/tsan (preset tsan builds
# only rr_server_tests) and run; a data race fails the run (halt_on_error; test/support/tsan.supp holds
# only explained third-party false positives). RR_TSAN=1 runs it. Off by default until a clean run has
# been recorded in docs/reliability.md: the build could not be completed on the loaded machine where
# this step was written, and an unverified race or TSan-slowed timeout must not block every CI run.
if [ "${RR_TSAN:-0}" != 0 ]; then
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan -j "$jobs"
  ctest --preset tsan -j "$jobs"
fi

# RR_FUZZ_SECONDS: seconds per target (0 = no fuzzing); unset = fuzz.sh's own CI times (~3.5 min).
fuzz_seconds=${RR_FUZZ_SECONDS:-}
if [ "$fuzz_seconds" != 0 ]; then
  ./scripts/fuzz.sh $fuzz_seconds
fi
echo "test: all passed"
