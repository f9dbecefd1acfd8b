#!/usr/bin/env bash
# nmdiff's and nmview's numeric options refuse a value that is not wholly a number, as nmbake's do
# (issue 34, item 12; cli/numbers.h): an empty value, blanks, trailing characters, hex. Exit CODE
# (the tool's bad-command-line code), one "error:" line naming the option, nothing written.
#   tool_numbers.sh nmdiff|nmview EXE REPO WORK
set -u
tool=$1 exe=$2 repo=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
map=$repo/data/golden/torus_256.png
low=$repo/data/sample/torus_low.obj high=$repo/data/sample/torus_high.ply
case "$tool" in
  nmdiff) code=2 options=(--max-mean --max-p99 --max-deg --heatmap-scale --max-abs --max-share) args=("$map" "$map" --json out.json) out=out.json ;;
  nmview) code=1 options=(--uv-set --diff-scale) args=("$low" "$map" "$high" --screenshot out.png --size 64x32) out=out.png ;;
  *) echo "usage: tool_numbers.sh nmdiff|nmview EXE REPO WORK"; exit 1 ;;
esac
fail=0
# Each case in its own folder, through ../run_cases.sh: nmdiff's all in one process under ctest
# (nmbake_cases --nmdiff), nmview's one process each (each starts a window).
source "$(dirname "$0")/run_cases.sh"
cases=$work/cases.txt
: >"$cases"
marker=()
[ "$tool" = nmdiff ] && marker=(--nmdiff)
values=('' ' ' '1 ' ' 1' '1x' '0x1' '1,5')
k=0
for option in "${options[@]}"; do
  for value in "${values[@]}"; do
    mkdir -p "$work/case$k"
    case_line "$work/case$k" "${marker[@]}" "${args[@]}" "$option" "$value"
    k=$((k + 1))
  done
done
if [ "$tool" = nmdiff ]; then run_cases "$exe" "$cases" 60; else NMBAKE_CASES='' run_cases "$exe" "$cases" 60; fi
k=0
for option in "${options[@]}"; do
  for value in "${values[@]}"; do
    dir=$work/case$k
    k=$((k + 1))
    case_result "$dir"
    err=$dir/stderr.txt
    [ -e "$err" ] || : >"$err"
    lines=$(wc -l <"$err")
    if [ "$got" != "$code" ] || [ "$lines" != 1 ] || ! grep -q '^error: ' "$err" || ! grep -qF -- "$option" "$err" ||
      [ -e "$dir/$out" ]; then
      echo "FAIL: $tool $option '$value': exit $got (expected $code), $lines lines: $(head -c 300 "$err")"
      fail=1
    fi
  done
done
# A number still works (a leading zero is decimal).
"$exe" "${args[@]}" "${options[0]}" 0 >stdout.txt 2>stderr.txt || { echo "FAIL: $tool ${options[0]} 0: $(head -c 300 stderr.txt)"; fail=1; }
[ -s "$out" ] || { echo "FAIL: $tool ${options[0]} 0 wrote no $out"; fail=1; }
[ "$fail" = 0 ] && echo "ok: $tool's numeric options take numbers only"
exit $fail
