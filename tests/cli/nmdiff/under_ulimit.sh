#!/usr/bin/env bash
# Runs nmdiff under `ulimit -v` at several limits (MB) and checks that every run ends with exit 0,
# or with exit 4, one stderr line "error: ..." about memory and no heatmap or JSON left, never a
# signal or another code.
#   under_ulimit.sh NMDIFF OUT MAP LIMIT_MB...
# OpenImageIO is a module nmdiff loads after checking the address space left: linked directly, its
# libraries failed in their static constructors before main below about 440 MB (exit 127, 134 or
# 139). Below about 30 MB the dynamic loader itself fails before main, for nmdiff's own libraries.
set -u
nmdiff=$1 out=$2 map=$3
shift 3
failed=0
for mb in "$@"; do
  rm -f "$out/ulimit.png" "$out/ulimit.json"
  bash -c "ulimit -v $((mb * 1024)); exec \"\$0\" \"\$1\" \"\$1\" --heatmap \"\$2/ulimit.png\" --json \"\$2/ulimit.json\"" \
    "$nmdiff" "$map" "$out" >"$out/ulimit.stdout" 2>"$out/ulimit.stderr"
  code=$?
  err=$(cat "$out/ulimit.stderr")
  echo "ulimit -v ${mb} MB: exit $code ${err}"
  case $code in
    0) [ -z "$err" ] || { echo "  FAIL: exit 0 with stderr"; failed=1; } ;;
    4) if [ "$(wc -l <"$out/ulimit.stderr")" != 1 ] || ! grep -q '^error: .*memory' "$out/ulimit.stderr"; then
         echo "  FAIL: exit 4 needs one 'error: ... memory ...' line"; failed=1
       fi
       if [ -e "$out/ulimit.png" ] || [ -e "$out/ulimit.json" ]; then echo "  FAIL: output left after exit 4"; failed=1; fi ;;
    *) echo "  FAIL: exit $code"; failed=1 ;;
  esac
done
exit $failed
