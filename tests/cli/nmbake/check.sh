#!/usr/bin/env bash
# One command-line case: check.sh WORKDIR EXPECTED_EXIT EXPECTED_TEXT -- COMMAND ARGS...
# Passes when the command exits with EXPECTED_EXIT, its output contains EXPECTED_TEXT, a failing
# run prints exactly one "error:" line, and a failing run leaves no file behind in WORKDIR
# (neither the output nor a temporary).
set -u
work=$1 expect_code=$2 expect_text=$3
shift 3
[ "$1" = "--" ] && shift
rm -rf "$work" && mkdir -p "$work"
cd "$work" || exit 1
out=$("$@" 2>stderr.txt >stdout.txt; echo $?)
code=$out
fail=0
if [ "$code" != "$expect_code" ]; then echo "FAIL: exit code $code, expected $expect_code"; fail=1; fi
if ! grep -qF -- "$expect_text" stdout.txt stderr.txt; then echo "FAIL: output lacks: $expect_text"; fail=1; fi
if [ "$expect_code" != 0 ]; then
  n=$(grep -c '^error:' stderr.txt)
  if [ "$n" != 1 ]; then echo "FAIL: expected one 'error:' line, got $n"; fail=1; fi
  left=$(ls -A | grep -v -e '^stderr.txt$' -e '^stdout.txt$' -e '^keep' || true)
  if [ -n "$left" ]; then echo "FAIL: files left behind: $left"; fail=1; fi
fi
echo "--- stdout"; cat stdout.txt; echo "--- stderr"; cat stderr.txt
exit $fail
