#!/usr/bin/env bash
# Runs nmdiff under `ulimit -v` at limits above the lowest it starts under (start_limit.sh) and
# checks that every run ends with exit 0, or with exit 4, one stderr line "error: ..." about memory
# and no heatmap or JSON left, never a signal or another code; and that some run is refused and
# some compares.
#   under_ulimit.sh NMDIFF OUT MAP OFFSET_MB...
set -u
nmdiff=$1 out=$2 map=$3
shift 3
source "$(dirname "$0")/../start_limit.sh"
find_start "$nmdiff" --help
failed=0 refused=0 compared=0
for offset in "$@"; do
  mb=$((start + offset))
  rm -f "$out/ulimit.png" "$out/ulimit.json"
  bash -c "ulimit -v $((mb * 1024)); exec \"\$0\" \"\$1\" \"\$1\" --heatmap \"\$2/ulimit.png\" --json \"\$2/ulimit.json\"" \
    "$nmdiff" "$map" "$out" >"$out/ulimit.stdout" 2>"$out/ulimit.stderr"
  code=$?
  err=$(cat "$out/ulimit.stderr")
  echo "ulimit -v ${mb} MB: exit $code ${err}"
  case $code in
    0) compared=1; [ -z "$err" ] || { echo "  FAIL: exit 0 with stderr"; failed=1; } ;;
    4) refused=1
       if [ "$(wc -l <"$out/ulimit.stderr")" != 1 ] || ! grep -q '^error: .*memory' "$out/ulimit.stderr"; then
         echo "  FAIL: exit 4 needs one 'error: ... memory ...' line"; failed=1
       fi
       if [ -e "$out/ulimit.png" ] || [ -e "$out/ulimit.json" ]; then echo "  FAIL: output left after exit 4"; failed=1; fi ;;
    *) echo "  FAIL: exit $code"; failed=1 ;;
  esac
done
[ $refused = 1 ] && [ $compared = 1 ] || { echo "FAIL: no limit was refused ($refused) or none compared ($compared)"; failed=1; }
exit $failed
