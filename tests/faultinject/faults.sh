#!/usr/bin/env bash
# Every failing file operation of a bake leaves the old outputs as they were.
#   faults.sh NMBAKE SHIM REPO WORK
# A small bake (the bundled sample, --size 64) over an old set of outputs (map, miss mask, cage,
# report) runs once to count its writes, closes, fsyncs, renames, file creations and allocations of
# 64 KiB or more (shim.cpp), then once per such call with that call failing (ENOSPC or EIO; ENOMEM
# for an allocation), and a few times with every write from the Nth on failing (a full disk). Each
# run must exit 0 (the failing call did not matter, e.g. closing an input), 3 for a file operation
# or 4 for an allocation; after a failure every old output must be byte-identical, and after any
# run no temporary may be left; a failure prints one line, "error: <output>: cannot write:
# <reason>", or for memory "error: ...out of memory..." (naming the file or the stage).
# Exit 77 (skipped) without the shim or under AddressSanitizer (LD_PRELOAD conflicts with it).
set -u
nmbake=$(realpath "$1") shim=$2 repo=$(realpath "$3") work=$4
if [ "$shim" = none ] || [ ! -e "$shim" ] || ldd "$nmbake" | grep -q -e libasan -e libubsan; then
  echo "skipped: no fault-injection shim (sanitizer build)"
  exit 77
fi
shim=$(realpath "$shim")
low=$repo/data/sample/torus_low.obj high=$repo/data/sample/torus_high.ply
max_runs=${NMBAKE_FAULT_MAX_RUNS:-25}  # per kind of call; ~0.5 s each
rm -rf "$work" && mkdir -p "$work/scene" "$work/old" && cd "$work/scene" || exit 1
log=$work
outputs="m.png miss.png cage.obj r.json"
bake() { "$nmbake" "$low" "$high" -o m.png --miss-mask miss.png --save-cage cage.obj --report r.json --quiet "$@"; }
state() { for f in $(ls -A | sort); do echo "$f $(md5sum <"$f")"; done; }

bake --size 32 || { echo "FAIL: the first bake"; exit 1; }
cp $outputs "$work/old/"
old=$(state)
NMBAKE_FAULT_COUNT=$log/counts.txt LD_PRELOAD=$shim bake --size 64 || { echo "FAIL: the counting bake"; exit 1; }
echo "calls of a bake: $(tr '\n' ' ' <"$log/counts.txt")"
cp "$work/old/"* .

fail=0 runs=0 failures=0
bad() { echo "FAIL: $*"; fail=1; }
# One run with NMBAKE_FAULT=$1; checks it and puts the old outputs back.
run() {
  local spec=$1 code err
  NMBAKE_FAULT=$spec LD_PRELOAD=$shim bake --size 64 >"$log/stdout.txt" 2>"$log/stderr.txt"
  code=$?
  runs=$((runs + 1))
  err=$(cat "$log/stderr.txt")
  local temps
  temps=$(ls -A | grep nmbake- || true)
  [ -z "$temps" ] || bad "$spec: temporaries left: $temps"
  case $code in
    0)
      for f in $outputs; do [ -s "$f" ] || bad "$spec: exit 0 without $f"; done
      [ -z "$err" ] || bad "$spec: exit 0 with stderr: $err"
      ;;
    3)
      failures=$((failures + 1))
      [ "$(state)" = "$old" ] || bad "$spec: exit 3 but the old outputs changed: $(ls -A | tr '\n' ' ')"
      [ "$(wc -l <"$log/stderr.txt")" = 1 ] || bad "$spec: stderr is not one line: $err"
      [ "${#err}" -lt 300 ] || bad "$spec: a ${#err}-byte error"
      echo "$err" | grep -qE "^error: (m\.png|miss\.png|cage\.obj|r\.json): cannot write: (No space left on device|Input/output error)$" ||
        bad "$spec: the error does not name an output and the system's reason: $err"
      ;;
    4)
      failures=$((failures + 1))
      [ "${spec%%:*}" = alloc ] || bad "$spec: exit 4 for a failing file operation"
      [ "$(state)" = "$old" ] || bad "$spec: exit 4 but the old outputs changed: $(ls -A | tr '\n' ' ')"
      [ "$(wc -l <"$log/stderr.txt")" = 1 ] || bad "$spec: stderr is not one line: $err"
      [ "${#err}" -lt 300 ] || bad "$spec: a ${#err}-byte error"
      echo "$err" | grep -qE "^error: .*out of memory" || bad "$spec: the error does not say out of memory: $err"
      ;;
    *) bad "$spec: exit $code ($err)" ;;
  esac
  printf '%-20s exit %s %s\n' "$spec" "$code" "$err"
  rm -f $outputs && cp "$work/old/"* .
}

errors=(ENOSPC EIO)
while read -r kind count; do
  step=$(((count + max_runs - 1) / max_runs))
  [ "$step" -ge 1 ] || step=1
  err_of() { if [ "$kind" = alloc ]; then echo ENOMEM; else echo "${errors[$(($1 % 2))]}"; fi; }
  for ((n = 1; n <= count; n += step)); do run "$kind:$n:$(err_of "$n")"; done
  [ "$count" -gt 0 ] && [ $(((count - 1) % step)) != 0 ] && run "$kind:$count:$(err_of 0)"
done <"$log/counts.txt"
# A disk that stays full from the Nth write on.
write_count=$(awk '$1 == "write" {print $2}' "$log/counts.txt")
for n in 1 2 $write_count; do run "write:$n+:ENOSPC"; done
# Memory that stays short from the Nth large allocation on.
alloc_count=$(awk '$1 == "alloc" {print $2}' "$log/counts.txt")
for n in 1 $((alloc_count / 2)) $((alloc_count - 5)); do run "alloc:$n+:ENOMEM"; done
# Renames that keep failing, so that the first output's rename cannot be undone: exit 3, and the
# error names the hidden copy that holds the old output, byte-identical; the next run keeps it.
NMBAKE_FAULT=rename:2+:EIO LD_PRELOAD=$shim bake --size 64 >"$log/stdout.txt" 2>"$log/stderr.txt"
code=$? err=$(cat "$log/stderr.txt")
echo "rename:2+:EIO        exit $code $err"
kept=$(echo "$err" | sed -n 's/.*; the old m\.png is kept as \(\.m\.png\.nmbake-old\.[0-9]*\)$/\1/p')
if [ "$code" != 3 ] || [ -z "$kept" ] || [ ! -f "$kept" ]; then
  bad "rename:2+:EIO: exit $code, expected 3 and the old map's copy named: $err"
else
  cmp -s "$kept" "$work/old/m.png" || bad "rename:2+:EIO: $kept is not the old map"
  bake --size 32 >/dev/null 2>&1 || bad "the bake after rename:2+:EIO failed"
  [ -f "$kept" ] || bad "the next run removed $kept, the only copy of the old map"
  rm -f "$kept"
fi
rm -f $outputs && cp "$work/old/"* .
[ "$failures" -gt 0 ] || bad "no run failed: the shim had no effect"
echo "fault injection: $runs runs, $failures failed as they should, $([ $fail = 0 ] && echo 'all checks passed' || echo 'some checks FAILED')"
exit $fail
