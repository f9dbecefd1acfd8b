#!/usr/bin/env bash
# Every numeric option of nmbake and of nmbake --batch refuses a value that is not wholly a number
# (issue 34, item 12: `--front ''` was taken as 0): exit 1, one "error:" line naming the option,
# nothing written. Leading zeros are decimal (--padding 010 is 10, not octal 8). The refusals go
# through ../run_cases.sh: under ctest all in one process (nmbake_cases), else one nmbake each.
#   numbers.sh NMBAKE LOW HIGH WORK
set -u
nmbake=$1 low=$2 high=$3 work=$(realpath -m "$4")
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail=0
source "$(dirname "$0")/../run_cases.sh"
cases=$work/cases.txt
: >"$cases"
k=0
queued=()
refused() {  # refused OPTION VALUE [more args]: exit 1, one line naming OPTION, no output
  local option=$1 value=$2
  shift 2
  k=$((k + 1))
  mkdir -p "$work/case$k"
  case_line "$work/case$k" "$@" "$option" "$value"
  queued+=("$option '$value'")
}
bake=("$low" "$high" -o out.png --size 8 --quiet)
for option in --front --rear --padding --threads --uv-set --bits --samples; do
  for value in '' ' ' '  ' '1 ' ' 1' $'1\n' '1x' 'x1' '0x10' '1,5' '--1'; do refused "$option" "$value" "${bake[@]}"; done
done
for value in '' ' ' '1 ' '1e' '.'; do refused --max-error "$value" "${bake[@]}" --samples auto; done
for value in '1.5' '1e3' '08.'; do refused --padding "$value" "${bake[@]}"; done
# The batch's own --threads, and a number given as a string in the jobs file.
echo '{"jobs": []}' >jobs.json
for value in '' ' ' '2x'; do refused --threads "$value" --batch "$work/jobs.json"; done
run_cases "$nmbake" "$cases" 60
for ((i = 1; i <= k; ++i)); do
  dir=$work/case$i what=${queued[i - 1]}
  case_result "$dir"
  lines=$(wc -l <"$dir/stderr.txt" 2>/dev/null || echo none)
  if [ "$got" != 1 ] || [ "$lines" != 1 ] || ! grep -qF -- "${what%% *}" "$dir/stderr.txt" || [ -e "$dir/out.png" ]; then
    echo "FAIL: $what: exit $got, $lines lines: $(head -c 300 "$dir/stderr.txt")"
    fail=1
  fi
done
printf '{"jobs": [{"low": "%s", "high": "%s", "output": "out.png", "options": {"size": 8, "front": ""}}]}' "$low" "$high" >front.json
"$nmbake" --batch front.json --quiet >stdout.txt 2>stderr.txt
code=$?
if [ "$code" != 1 ] || ! grep -qF -- "--front: expected a number, got ''" stderr.txt || [ -e out.png ]; then
  echo "FAIL: batch \"front\": \"\": exit $code: $(head -c 300 stderr.txt)"
  fail=1
fi
# Values that are numbers still work: a sign, an exponent, leading zeros read as decimal.
"$nmbake" "${bake[@]}" --front +0.05e0 --rear 5E-2 --padding 010 --report r.json || fail=1
grep -q '"padding": 10' r.json || { echo "FAIL: --padding 010 is not 10: $(grep padding r.json)"; fail=1; }
exit $fail
