#!/bin/sh
# ctest: `rr-robdef check` on files with UTF-8 byte-order marks (issue 40; robdef/parser_test.cpp has the
# official verdict). One leading mark: accepted, as the official file readers accept it, with a warning
# naming it; a second mark: refused, the error naming it. Usage: bom_check_test.sh RR_ROBDEF
set -u
exe=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

printf '\357\273\277service t.bom\nstdver 0.10\nstruct S\n    field int32 x\nend\n' > "$dir/one.robdef"
out=$("$exe" check "$dir/one.robdef" 2>&1); rc=$?
echo "$out"
[ "$rc" -eq 0 ] || fail "one leading mark: exit status $rc, want 0 (the official file readers accept the file)"
echo "$out" | grep -q "one.robdef:1: warning: the file starts with a UTF-8 byte-order mark (bytes EF BB BF)" ||
    fail "one leading mark: no warning naming it"

printf '\357\273\277\357\273\277service t.bom\nstdver 0.10\n' > "$dir/two.robdef"
out=$("$exe" check "$dir/two.robdef" 2>&1); rc=$?
echo "$out"
[ "$rc" -eq 1 ] || fail "two marks: exit status $rc, want 1"
echo "$out" | grep -q "two.robdef:1: error: Service definition must contain only ASCII characters (a UTF-8 byte-order mark, bytes EF BB BF, at column 1)" ||
    fail "two marks: the error does not name the mark"
echo "ok"
