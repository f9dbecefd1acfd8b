#!/usr/bin/env bash
# --estimate-error: estimate_error.sh WORKDIR on|off NMBAKE LOW HIGH
# on: the report has "error_estimate" with mean_deg, p95_deg, max_deg, texels, seconds and stderr
# has one "error estimate:" line; off: neither.
set -u
work=$1 mode=$2 exe=$3 low=$4 high=$5
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
flag=()
[ "$mode" = on ] && flag=(--estimate-error)
"$exe" "$low" "$high" -o out.png --size 64x32 --report r.json "${flag[@]}" >stdout.txt 2>stderr.txt || { echo "FAIL: nmbake failed"; cat stderr.txt; exit 1; }
fail=0
lines=$(grep -c 'error estimate:' stderr.txt)
# The block as nlohmann::json dumps it (keys sorted, 4-space indent inside the top-level object).
block=$(sed -n '/^  "error_estimate": {/,/^  }/p' r.json)
if [ "$mode" = on ]; then
  [ "$lines" = 1 ] || { echo "FAIL: expected one 'error estimate:' line on stderr, got $lines"; fail=1; }
  [ -n "$block" ] || { echo "FAIL: report has no error_estimate block"; fail=1; }
  for key in mean_deg p95_deg max_deg texels seconds; do
    echo "$block" | grep -Eq "^    \"$key\": [0-9]" || { echo "FAIL: error_estimate lacks a number for $key"; fail=1; }
  done
  echo "$block" | grep -Eq '^    "texels": [1-9][0-9]*,?$' || { echo "FAIL: error_estimate.texels is not positive"; fail=1; }
else
  [ "$lines" = 0 ] || { echo "FAIL: 'error estimate:' printed without --estimate-error"; fail=1; }
  if grep -q '"error_estimate"' r.json; then echo "FAIL: error_estimate in the report without --estimate-error"; fail=1; fi
fi
echo "--- stderr"; cat stderr.txt; echo "--- error_estimate"; echo "$block"
exit $fail
