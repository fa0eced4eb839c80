#!/bin/sh
# Runs a program under umockdev-wrapper (LD_PRELOAD of libumockdev-preload) for the emulated rr+usb
# tests; exits 77 (ctest: skipped) with the reason when umockdev is not installed.
if ! command -v umockdev-wrapper >/dev/null 2>&1; then
  echo "SKIP: umockdev-wrapper not found (install umockdev libumockdev-dev: scripts/setup.sh)"
  exit 77
fi
# ASan checks that its runtime comes first among the loaded libraries; the preload library does.
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0"
export ASAN_OPTIONS
exec umockdev-wrapper "$@"
