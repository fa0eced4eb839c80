#!/usr/bin/env bash
# The test command (docs/development.md "CI time" has the phases, their order and a measured run):
#   setup            scripts/setup.sh: the run packages and the test tools, the Python venv
#   wasm+dashboard   the WebAssembly client and the dashboard (the browser tests need them)
#   build            preset debug: clang-14 -O0, ASan + UBSan, every test program and the libFuzzer
#                    targets linked from the same objects
#   ctest            every test but the timing ones, RR_CTEST_JOBS at a time (default 4 per CPU: most
#                    tests wait on sockets, timers and child processes)
#   tsan             the server tests under ThreadSanitizer (preset tsan, built meanwhile)
#   fuzz             every libFuzzer target briefly, two at a time (scripts/fuzz.sh): those that need no
#                    server library from preset fuzz (-O1, built meanwhile), the server ones from the debug build
#   package          (meanwhile) preset package: the Release binaries and the Debian package, installed
#                    on a fresh Debian 12 root; the container image made from those binaries (no
#                    second compile) and its test; the Containerfile's from-source build only when
#                    its inputs changed (docker/from-source.verified)
#   timing           the tests labelled `timing` (they assert rates and latencies), two at a time, last:
#                    calm, with nothing built or fuzzed beside them, so their bounds can fail
# At the end (pass or fail): every skipped test with its reason. A failed test is never retried.
# Meanwhile = in the background at nice 19, one chain (and beside it the download of a fresh Debian
# root for the install test): the tsan build, the core fuzz targets, the package build, then
# the fresh-Debian, container and from-source steps, so they take the CPU the tests leave idle.
# Exits non-zero on any failure; prints how long each phase took, and warns, naming the slowest
# phases and tests, when the whole run passes RR_CI_BUDGET_MINUTES (45).
#   RR_TSAN=0, RR_FRESH_DEBIAN=0, RR_CONTAINER=0 leave those steps out; RR_FUZZ_SECONDS=N fuzzes each
#   target N seconds (0: no fuzzing); RR_FROM_SOURCE=1|0 forces the from-source image build on or off.
set -euo pipefail
cd "$(dirname "$0")/.."

budget_min=${RR_CI_BUDGET_MINUTES:-45}
t_phase=$SECONDS
phases=()
phase_done() { phases+=("$1 $((SECONDS - t_phase)) s"); t_phase=$SECONDS; }
bg_pid=
finish() {
  local rc=$?
  set +e +o pipefail
  if [ -n "$bg_pid" ]; then kill -- -"$bg_pid" 2>/dev/null; fi
  ./scripts/run_report.sh "$rc" "$SECONDS" "$budget_min" "${phases[@]}"
  exit "$rc"
}
trap finish EXIT
rm -f build/ctest-*.xml

echo "test: disk: $(df -h --output=avail . | tail -1 | tr -d ' ') free at the start"
./scripts/setup.sh
phase_done setup
jobs=${RR_JOBS:-$(nproc)}
ctest_jobs=${RR_CTEST_JOBS:-$((4 * $(nproc)))}

# The WebAssembly client package (wasm-client/dist; build folder build/wasm), tested by ctest.
./wasm-client/build.sh
# The dashboard (web/dist) on the client package, for the browser tests (they skip without it).
if [ -f wasm-client/dist/robotraconteur.mjs ]; then
  ./web/build.sh
else
  echo "test: wasm-client/dist missing: the browser tests will be skipped"
fi
phase_done wasm+dashboard

cmake --preset debug >/dev/null
cmake --build --preset debug -j "$jobs"
phase_done build

# The background chain (its own process group, nice 19; its steps' logs in build/bg-*.log, their
# outcomes in build/bg-status/<step>: "ok", "skipped: why" or "failed").
mkdir -p build/bg-status
rm -f build/bg-status/*
rm -rf build/bg-fresh-debian-root
container_ok=
if [ "${RR_CONTAINER:-1}" != 0 ] && command -v podman >/dev/null && podman info >/dev/null 2>&1; then container_ok=1; fi
# The from-source image build: only when its inputs differ from the last verified ones.
from_source=${RR_FROM_SOURCE:-}
if [ -z "$from_source" ]; then
  if [ "$(./docker/build.sh --print-from-source-key)" = "$(sed -n 's/^key //p' docker/from-source.verified 2>/dev/null)" ]; then
    from_source=0
    echo "test: the Containerfile's from-source build is skipped: its inputs (docker/, packaging/, cmake/,"
    echo "test:   the top CMakeLists.txt, the dependencies any CMakeLists.txt looks for)"
    echo "test:   are those verified at $(sed -n 's/^commit //p' docker/from-source.verified)"
  else
    from_source=1
    echo "test: the Containerfile's from-source build runs: its inputs changed since docker/from-source.verified"
  fi
fi
background_chain() {
  step() {  # step NAME COMMAND...: runs it, logs to build/bg-NAME.log, records its outcome (77: skipped)
    local name=$1; shift
    local t0=$SECONDS rc=0
    "$@" >"build/bg-$name.log" 2>&1 || rc=$?
    case $rc in
      0) echo "ok $((SECONDS - t0)) s" ;;
      77) echo "ok (skipped: $(grep -m1 -o 'SKIP.*' "build/bg-$name.log"))" ;;
      *) echo "failed $((SECONDS - t0)) s" ;;
    esac >"build/bg-status/$name"
  }
  # The fresh Debian root is downloaded meanwhile (network and disk, little CPU): the install test
  # below then waits only for the package, not for the mirror.
  local root_pid=
  if [ "${RR_FRESH_DEBIAN:-1}" != 0 ]; then
    step fresh-debian-root test/gateway/fresh_debian_test.sh --prepare-root "$PWD/build/bg-fresh-debian-root" &
    root_pid=$!
  fi
  if [ "${RR_TSAN:-1}" != 0 ]; then
    step tsan-build sh -c 'cmake --preset tsan >/dev/null && cmake --build --preset tsan -j "$1"' sh "$jobs"
  fi
  if [ "${RR_FUZZ_SECONDS:-}" != 0 ]; then
    # the fuzz targets that need no server library, at -O1 (scripts/fuzz.sh runs the others from build/debug)
    step fuzz-build sh -c 'cmake --preset fuzz >/dev/null && cmake --build --preset fuzz --target rr_fuzz_core_targets -j "$1"' sh "$jobs"
  fi
  step package-build sh -c 'cmake --preset package >/dev/null && cmake --build --preset package -j "$1"' sh "$jobs"
  if [ "${RR_FRESH_DEBIAN:-1}" != 0 ] && grep -q '^ok' build/bg-status/package-build; then
    # (the ctest test "install: the package on a fresh Debian 12 root", called directly: a second
    # ctest in build/debug while the main one runs would write over its logs)
    # (the root's download began with the chain and has ended by now, unless the mirror is slow)
    [ -z "$root_pid" ] || wait "$root_pid" || true
    step fresh-debian env RR_FRESH_DEBIAN=1 RR_FRESH_DEBIAN_ROOT="$PWD/build/bg-fresh-debian-root" \
      test/gateway/fresh_debian_test.sh build/package docs/deployment.md cpack &
  fi
  if [ -n "$container_ok" ] && grep -q '^ok' build/bg-status/package-build; then
    step container-image ./docker/build.sh --from-build build/package --tag localhost/rr-gateway:ci
  fi
  if [ -n "$container_ok" ] && [ "$from_source" = 1 ]; then
    step from-source ./docker/build.sh --tag localhost/rr-gateway:from-source --smoke --record-verified
  fi
  wait
  rm -rf build/bg-fresh-debian-root  # a root no test took (the package build failed)
}
setsid nice -n 19 bash -c "$(declare -f background_chain); jobs=$jobs container_ok=$container_ok from_source=$from_source background_chain" \
  >build/bg-chain.log 2>&1 &
bg_pid=$!
# Waits until the background step NAME has an outcome; fails the run (with its log's end) if it failed.
await_step() {
  local name=$1 what=$2
  while [ ! -f "build/bg-status/$name" ]; do
    if ! kill -0 "$bg_pid" 2>/dev/null; then
      [ -f "build/bg-status/$name" ] && break
      echo "test: FAILED: the background chain ended before $what (build/bg-chain.log)"; tail -n 20 build/bg-chain.log; exit 1
    fi
    sleep 2
  done
  if ! grep -q '^ok' "build/bg-status/$name"; then
    tail -n 60 "build/bg-$name.log"
    echo "test: FAILED: $what (log build/bg-$name.log)"
    exit 1
  fi
}

# ctest starts the longest tests first (their COST from test/schedule/costs.cmake; regenerate it from
# build/ctest-main.log and build/ctest-timing.log with test/schedule/ctest_costs.py when tests change).
# --output-on-failure: a failed test's own output is in the CI log (the second ctest run overwrites
# build/debug/Testing/Temporary/LastTest.log).
excluded='^(docker: the image|install: the package on a fresh Debian 12 root)'
# --output-junit: each test's outcome and output, for the list of skipped tests at the end.
junit=(--test-output-size-passed 65536 --output-junit)
ctest --preset debug -j "$ctest_jobs" -LE timing -E "$excluded" --output-on-failure \
  "${junit[@]}" "$PWD/build/ctest-main.xml" 2>&1 | tee build/ctest-main.log ||
  { echo "test: FAILED: ctest (build/ctest-main.log)"; exit 1; }
phase_done ctest

# ThreadSanitizer (issue 16): the threaded server tests ("server: " tests of rr_server_tests) built with
# -fsanitize=thread in build/tsan (preset tsan: a unity build of rr_server_tests only) and run; a data
# race fails the run (halt_on_error; test/support/tsan.supp holds only explained third-party false
# positives). On a failure it names the failed tests and prints each report (build/tsan/ctest.log).
if [ "${RR_TSAN:-1}" != 0 ]; then
  await_step tsan-build "the ThreadSanitizer build (preset tsan, build/tsan) did not compile"
  phase_done tsan-build-wait
  if ! ctest --preset tsan -j "$ctest_jobs" --output-log build/tsan/ctest.log >build/ctest-tsan.log 2>&1; then
    tail -n 5 build/ctest-tsan.log
    echo "test: FAILED: the ThreadSanitizer step (ctest --preset tsan; full log build/tsan/ctest.log)"
    echo "test: failed TSan tests (re-run one: ctest --preset tsan -R '<name>'):"
    sed 's/^[0-9]*:/  /' build/tsan/Testing/Temporary/LastTestsFailed.log 2>/dev/null || true
    echo "test: ThreadSanitizer reports:"
    awk '/WARNING: ThreadSanitizer|ERROR: ThreadSanitizer/,/SUMMARY: ThreadSanitizer/' build/tsan/ctest.log | head -n 400
    exit 1
  fi
  grep -E 'tests passed|Total Test time' build/ctest-tsan.log || true
  phase_done tsan
fi

# RR_FUZZ_SECONDS: seconds per target (0 = no fuzzing); unset = fuzz.sh's own CI times.
fuzz_seconds=${RR_FUZZ_SECONDS:-}
if [ "$fuzz_seconds" != 0 ]; then
  await_step fuzz-build "the -O1 build of the core fuzz targets (preset fuzz, build/fuzz)"
  # Fuzzing lasts its fixed seconds whatever CPU it gets, so from here the background chain (the rest
  # of the package build, the fresh-Debian install) shares the CPU instead of waiting at nice 19 for the
  # fuzzers to end: minutes less of the run, fewer inputs per target (needs root; else unchanged).
  renice -n 0 -g "$bg_pid" >/dev/null 2>&1 || true
  ./scripts/fuzz.sh $fuzz_seconds
  phase_done fuzz
fi

# What the background chain still does: the package, installed on a fresh Debian root; the image from
# it and its test; the from-source image build.
await_step package-build "the Release package build (preset package, build/package)"
if [ "${RR_FRESH_DEBIAN:-1}" != 0 ]; then
  await_step fresh-debian "the package on a fresh Debian 12 root"
  cat build/bg-status/fresh-debian
fi
if [ "${RR_CONTAINER:-1}" != 0 ]; then
  if [ -n "$container_ok" ]; then
    await_step container-image "docker/build.sh --from-build build/package"
    grep -E '^build: ' build/bg-container-image.log || true
  fi
  # The container test on that image (reports skipped, with the reason, where podman cannot run).
  RR_CONTAINER_PREBUILT=1 ctest --preset debug -R '^docker: the image' --output-on-failure \
    "${junit[@]}" "$PWD/build/ctest-container.xml" 2>&1 |
    tee build/ctest-container.log || { echo "test: FAILED: the container test"; exit 1; }
  if [ -n "$container_ok" ] && [ "$from_source" = 1 ]; then
    await_step from-source "the Containerfile's from-source build (docker/build.sh --smoke)"
    grep -E '^build: ' build/bg-from-source.log || true
    echo "test: the from-source build passed; docker/from-source.verified now holds its inputs (commit it)"
  fi
fi
phase_done package+container-wait

# The calm phase: the tests that assert rates and latencies, two at a time, with nothing built, fuzzed or
# installed beside them (every background step has ended above), so a bound they miss is a failure.
if [ -n "$bg_pid" ] && kill -0 "$bg_pid" 2>/dev/null; then
  echo "test: waiting for the background chain to end before the timing tests"
  while kill -0 "$bg_pid" 2>/dev/null; do sleep 2; done
fi
ctest --preset debug -j 2 -L timing -E "$excluded" --output-on-failure \
  "${junit[@]}" "$PWD/build/ctest-timing.xml" 2>&1 | tee build/ctest-timing.log ||
  { echo "test: FAILED: the timing tests (build/ctest-timing.log)"; exit 1; }
phase_done timing
echo "test: all passed"
