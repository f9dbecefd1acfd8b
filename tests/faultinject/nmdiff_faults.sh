#!/usr/bin/env bash
# Every failing file operation or allocation of nmdiff leaves each old output as it was or complete.
#   nmdiff_faults.sh NMDIFF SHIM A B WORK
# nmdiff A B --heatmap h.png --json d.json over old outputs (those of comparing A with itself) runs
# once to count its calls (shim.cpp), once cleanly for the new outputs, then once per call with that
# call failing (ENOSPC or EIO; ENOMEM for an allocation of 64 KiB or more). Each output is written
# to a temporary, and both are renamed into place together (io/output_files.h): after any run each is
# byte-identical to the old one or to the new one, and no temporary is left. A run exits as the
# clean one did, with every output new, or with 3 (a file operation) or 4 (memory) and one short
# "error: ..." line. Exit 77 (skipped) without the shim.
set -u
nmdiff=$(realpath "$1") shim=$2 a=$(realpath "$3") b=$(realpath "$4") work=$5
if [ "$shim" = none ] || [ ! -e "$shim" ] || ldd "$nmdiff" | grep -q -e libasan -e libubsan; then
  echo "skipped: no fault-injection shim (sanitizer build)"
  exit 77
fi
shim=$(realpath "$shim")
max_runs=${NMBAKE_FAULT_MAX_RUNS:-20}  # per kind of call
rm -rf "$work" && mkdir -p "$work/scene" "$work/old" "$work/new" && cd "$work/scene" || exit 1
log=$work
outputs="h.png d.json"
diff_maps() { "$nmdiff" "$1" "$2" --heatmap h.png --json d.json; }

diff_maps "$a" "$a" >/dev/null || { echo "FAIL: the first comparison"; exit 1; }
cp $outputs "$work/old/"
diff_maps "$a" "$b" >/dev/null
clean=$?
[ "$clean" -le 1 ] || { echo "FAIL: the clean comparison exited $clean"; exit 1; }
cp $outputs "$work/new/"
cp "$work/old/"* .
NMBAKE_FAULT_COUNT=$log/counts.txt LD_PRELOAD=$shim diff_maps "$a" "$b" 2>&1 >/dev/null | cat
echo "calls of a comparison: $(tr '\n' ' ' <"$log/counts.txt")"
cp "$work/old/"* .

fail=0 runs=0 failures=0
bad() { echo "FAIL: $*"; fail=1; }
run() {
  local spec=$1 code err f
  # stdout to /dev/null and stderr through a pipe: the shim counts writes to regular files only.
  NMBAKE_FAULT=$spec LD_PRELOAD=$shim diff_maps "$a" "$b" 2>&1 >/dev/null | cat >"$log/stderr.txt"
  code=${PIPESTATUS[0]}
  runs=$((runs + 1))
  err=$(cat "$log/stderr.txt")
  [ -z "$(ls -A | grep -v -x -e h.png -e d.json)" ] || bad "$spec: files left: $(ls -A | tr '\n' ' ')"
  for f in $outputs; do
    cmp -s "$f" "$work/old/$f" || cmp -s "$f" "$work/new/$f" || bad "$spec: $f is neither the old nor the new one"
  done
  if [ "$code" = "$clean" ]; then
    for f in $outputs; do cmp -s "$f" "$work/new/$f" || bad "$spec: exit $code but $f is not the new one"; done
  elif [ "$code" = 3 ] || [ "$code" = 4 ]; then
    failures=$((failures + 1))
    [ "$(wc -l <"$log/stderr.txt")" = 1 ] || bad "$spec: stderr is not one line: $err"
    [ "${#err}" -lt 300 ] || bad "$spec: a ${#err}-byte error"
    case "$spec:$code" in
      alloc:*:4) echo "$err" | grep -q "^error: .*out of memory" || bad "$spec: no 'out of memory': $err" ;;
      alloc:*) bad "$spec: exit $code for an allocation" ;;
      *:3) echo "$err" | grep -qE "^error: (h\.png|d\.json): cannot write: " || bad "$spec: the error names no output: $err" ;;
      *) bad "$spec: exit $code for a file operation" ;;
    esac
  else
    bad "$spec: exit $code ($err)"
  fi
  printf '%-20s exit %s %s\n' "$spec" "$code" "$err"
  rm -f $outputs && cp "$work/old/"* .
}

errors=(ENOSPC EIO)
while read -r kind count; do
  step=$(((count + max_runs - 1) / max_runs))
  [ "$step" -ge 1 ] || step=1
  for ((n = 1; n <= count; n += step)); do
    if [ "$kind" = alloc ]; then run "$kind:$n:ENOMEM"; else run "$kind:$n:${errors[$((n % 2))]}"; fi
  done
done <"$log/counts.txt"
run "write:1+:ENOSPC"
[ "$failures" -gt 0 ] || bad "no run failed: the shim had no effect"
echo "fault injection: $runs runs, $failures failed as they should, $([ $fail = 0 ] && echo 'all checks passed' || echo 'some checks FAILED')"
exit $fail
