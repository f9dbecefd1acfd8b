#!/usr/bin/env bash
# Runs nmbake under `ulimit -v` at limits above the lowest it starts under (start_limit.sh), each a
# few times, and checks that every run ends with exit 0 and no output on stderr, or with exit 4 and
# one stderr line "error: ...memory..." (or the --size budget's "needs about ... MiB"), with no map
# left behind; never a signal, a hang or another code; and that some run is refused and some bakes.
#   under_ulimit.sh NMBAKE OUT LOW HIGH REPEATS OFFSET_MB...
set -u
nmbake=$1 out=$2 low=$3 high=$4 repeats=$5
shift 5
source "$(dirname "$0")/../start_limit.sh"
mkdir -p "$out"
find_start "$nmbake" --version
failed=0 refused=0 baked=0
for offset in "$@"; do
  mb=$((start + offset))
  for ((rep = 0; rep < repeats; ++rep)); do
    rm -f "$out/ulimit.png"
    timeout 120 bash -c "ulimit -v $((mb * 1024)); exec \"\$0\" \"\$1\" \"\$2\" -o \"\$3/ulimit.png\" --size 2048 --samples 4 --quiet" \
      "$nmbake" "$low" "$high" "$out" >"$out/ulimit.stdout" 2>"$out/ulimit.stderr"
    code=$?
    err=$(cat "$out/ulimit.stderr")
    echo "ulimit -v ${mb} MB: exit $code ${err}"
    case $code in
      0) baked=1; [ -z "$err" ] || { echo "  FAIL: exit 0 with stderr"; failed=1; } ;;
      4) refused=1
         if [ "$(wc -l <"$out/ulimit.stderr")" != 1 ] || ! grep -qE '^error: .*(memory|needs about)' "$out/ulimit.stderr"; then
           echo "  FAIL: exit 4 needs one 'error: ... memory ...' line"; failed=1
         fi
         [ ! -e "$out/ulimit.png" ] || { echo "  FAIL: a map was left after exit 4"; failed=1; } ;;
      *) echo "  FAIL: exit $code"; failed=1 ;;
    esac
  done
done
[ $refused = 1 ] && [ $baked = 1 ] || { echo "FAIL: no limit was refused ($refused) or none baked ($baked)"; failed=1; }
exit $failed
