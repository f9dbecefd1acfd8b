#!/usr/bin/env bash
# Output safety: an existing map is never left half-written.
#   interrupt.sh NMBAKE REPO WORK
# 1. A bake interrupted by SIGINT while it traces exits 130 with one "error:" line before any later
#    stage, leaves the existing map byte-identical and leaves no temporary file behind.
# 2. A bake that fails (a cage with the wrong topology) does the same with exit code 2.
set -u
nmbake=$(realpath "$1") repo=$(realpath "$2") work=$3
low=$repo/data/sample/torus_low.obj high=$repo/data/sample/torus_high.ply
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail=0
check() { if ! eval "$1"; then echo "FAIL: $2"; fail=1; fi; }
listing() { ls -A | sort | tr '\n' ' '; }

# The existing map: a real one, baked small.
"$nmbake" "$low" "$high" -o map.png --size 64 --quiet || { echo "FAIL: the first bake failed"; exit 1; }
cp map.png map.orig

# 1. A bake that would take several seconds (2048^2 texels, 16 samples each), interrupted once its
# progress line (--progress) says it is tracing: the bake stops there, at its next progress call,
# and no later stage (padding, writing) begins.
"$nmbake" "$low" "$high" -o map.png --size 2048 --samples 16 --threads 2 --progress >stdout.txt 2>progress.txt &
pid=$!
until grep -q 'nmbake: tracing' progress.txt || ! kill -0 "$pid" 2>/dev/null; do sleep 0.01; done
kill -INT "$pid" 2>/dev/null
deadline=$((SECONDS + 60))  # a bake that ignores SIGINT is killed after 60 s (and fails below)
while kill -0 "$pid" 2>/dev/null && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.05; done
kill -0 "$pid" 2>/dev/null && kill -KILL "$pid"
wait "$pid"
code=$?
# The progress line's redraws end in carriage returns: one line each, the blank clearing dropped.
tr '\r' '\n' <progress.txt | grep -v '^ *$' >lines.txt
grep -v '^nmbake: ' lines.txt >stderr.txt
rm progress.txt
echo "interrupt: SIGINT once tracing, exit $code; stages seen: $(sed -n 's/^nmbake: \([A-Za-z][A-Za-z ]*[A-Za-z]\).*/\1/p' lines.txt | uniq | tr '\n' ' ')"
check '[ "$code" = 130 ]' "exit code $code, expected 130"
check 'cmp -s map.png map.orig' "the existing map changed"
check '[ "$(grep -c "^error:" stderr.txt)" = 1 ] && [ "$(wc -l <stderr.txt)" = 1 ]' "expected one 'error:' line"
check 'grep -q "interrupted" stderr.txt' "the error does not say interrupted"
check '! grep -q -e "^nmbake: padding" -e "^nmbake: writing" lines.txt' "a stage after the trace began after SIGINT"
rm lines.txt
check '[ "$(listing)" = "map.orig map.png stderr.txt stdout.txt " ]' "files left behind: $(listing)"
sed 's/^/stderr: /' stderr.txt

# 2. A failing bake (the cage's topology is not the low-poly's).
"$nmbake" "$low" "$high" -o map.png --size 64 --cage "$high" >stdout.txt 2>stderr.txt
code=$?
check '[ "$code" = 2 ]' "failing bake: exit code $code, expected 2"
check 'cmp -s map.png map.orig' "failing bake: the existing map changed"
check '[ "$(listing)" = "map.orig map.png stderr.txt stdout.txt " ]' "failing bake: files left behind: $(listing)"
sed 's/^/stderr: /' stderr.txt
exit $fail
