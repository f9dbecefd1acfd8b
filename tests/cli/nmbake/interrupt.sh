#!/usr/bin/env bash
# Output safety: an existing map is never left half-written.
#   interrupt.sh NMBAKE REPO WORK
# 1. A bake interrupted by SIGINT while it runs exits 130 with one "error:" line, leaves the
#    existing map byte-identical and leaves no temporary file behind.
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

# 1. A bake that would take several seconds (2048^2 texels, 16 samples each), interrupted once it
# is under way: its worker threads exist (Embree's BVH build or the trace), so the SIGINT handler,
# installed before loading, is in place.
start=$(date +%s%N)
"$nmbake" "$low" "$high" -o map.png --size 2048 --samples 16 --threads 2 --quiet >stdout.txt 2>stderr.txt &
pid=$!
for _ in $(seq 1 600); do
  threads=$(awk '/^Threads:/ {print $2}' "/proc/$pid/status" 2>/dev/null || echo 0)
  [ "${threads:-0}" -gt 1 ] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.05
done
sleep 0.2
sent=$(date +%s%N)
kill -INT "$pid" 2>/dev/null
deadline=$((SECONDS + 60))  # a bake that ignores SIGINT is killed after 60 s (and fails below)
while kill -0 "$pid" 2>/dev/null && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.05; done
end=$(date +%s%N)
kill -0 "$pid" 2>/dev/null && kill -KILL "$pid"
wait "$pid"
code=$?
echo "interrupt: SIGINT after $(( (sent - start) / 1000000 )) ms (threads seen: ${threads:-0}), exit $code $(( (end - sent) / 1000000 )) ms later"
check '[ "$code" = 130 ]' "exit code $code, expected 130"
check 'cmp -s map.png map.orig' "the existing map changed"
check '[ "$(grep -c "^error:" stderr.txt)" = 1 ] && [ "$(wc -l <stderr.txt)" = 1 ]' "expected one 'error:' line"
check 'grep -q "interrupted" stderr.txt' "the error does not say interrupted"
check '[ "$(listing)" = "map.orig map.png stderr.txt stdout.txt " ]' "files left behind: $(listing)"
check '[ $(( (end - sent) / 1000000 )) -lt 10000 ]' "took more than 10 s to stop after SIGINT"
sed 's/^/stderr: /' stderr.txt

# 2. A failing bake (the cage's topology is not the low-poly's).
"$nmbake" "$low" "$high" -o map.png --size 64 --cage "$high" >stdout.txt 2>stderr.txt
code=$?
check '[ "$code" = 2 ]' "failing bake: exit code $code, expected 2"
check 'cmp -s map.png map.orig' "failing bake: the existing map changed"
check '[ "$(listing)" = "map.orig map.png stderr.txt stdout.txt " ]' "failing bake: files left behind: $(listing)"
sed 's/^/stderr: /' stderr.txt
exit $fail
