#!/usr/bin/env bash
# SIGTERM, SIGHUP and SIGINT during the bake or during the writes, and SIGKILL during the writes.
#   signals.sh NMBAKE REPO WORK
# 1. SIGTERM / SIGHUP while the bake runs (sent when its progress line, --progress, names the trace):
#    exit 143 / 129, one "error: interrupted by ..." line besides the progress line, the old map,
#    miss mask and report byte-identical, no temporary left.
# 2. SIGTERM and SIGINT once the map's temporary file exists (the writes have begun): the same
#    (exit 143 / 130).
# 3. SIGKILL during the writes leaves only temporaries named ".<name>.nmbake-tmp.<pid>"; the next
#    run over the same outputs removes them, and a live process's temporary is left alone, as is an
#    old copy that differs from its output (the only copy of it).
set -u
nmbake=$(realpath "$1") repo=$(realpath "$2") work=$3
low=$repo/data/sample/torus_low.obj high=$repo/data/sample/torus_high.ply
rm -rf "$work" && mkdir -p "$work/scene" && cd "$work/scene" || exit 1
log=$work
fail=0
bad() { echo "FAIL: $*"; fail=1; }
state() { for f in $(ls -A | sort); do echo "$f $(md5sum <"$f")"; done; }

"$nmbake" "$low" "$high" -o m.png --size 32 --miss-mask miss.png --report r.json --quiet || { echo "FAIL: the first bake"; exit 1; }
old=$(state)

# run_and_signal SIGNAL WHEN: starts a bake over the old outputs, sends SIGNAL once WHEN holds
# ("bake": the progress line says it is tracing; "write": the map's temporary exists), waits, sets
# $code. The waits are for those events, not for a time.
run_and_signal() {
  local sig=$1 when=$2
  # 2048^2 texels: the trace, padding and writes after the trace's first line take about 0.5 s
  # (several times that under ASan), against the few milliseconds the signal takes to be sent. The
  # map's temporary lives from its write to the renaming of every output: about 20 ms at 2048^2 (the
  # masks' encoders share the threads), which a poller sharing two cores with other tests can miss;
  # the writes' cases bake 4096^2 (about 60 ms) and poll with shell builtins alone, no sleep.
  local size=2048
  [ "$when" = write ] && size=4096
  "$nmbake" "$low" "$high" -o m.png --size "$size" --threads 2 --miss-mask miss.png --report r.json --progress \
    >"$log/stdout.txt" 2>"$log/stderr.txt" &
  pid=$!
  local seen=0 until=$((SECONDS + 120))
  while [ "$SECONDS" -lt "$until" ]; do
    kill -0 "$pid" 2>/dev/null || break
    if [ "$when" = bake ]; then
      grep -q 'nmbake: tracing' "$log/stderr.txt" && { seen=1; break; }
      sleep 0.005
    elif [ -e ".m.png.nmbake-tmp.$pid" ]; then
      seen=1
      break
    fi
  done
  [ "$seen" = 1 ] || bad "$sig during the $when: the moment never came"
  kill -s "$sig" "$pid" 2>/dev/null
  local deadline=$((SECONDS + 60))
  while kill -0 "$pid" 2>/dev/null && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.05; done
  kill -0 "$pid" 2>/dev/null && kill -KILL "$pid"
  wait "$pid"
  code=$?
}

# A test started with SIGHUP ignored (nohup) passes that on to nmbake, which keeps it ignored by
# design (command.h): the SIGHUP case cannot run then, and says so.
hup_ignored=$((0x$(awk '/^SigIgn:/ {print $2}' /proc/self/status) & 1))
for case in TERM:bake:143 HUP:bake:129 TERM:write:143 INT:write:130; do
  IFS=: read -r sig when expect <<<"$case"
  if [ "$sig" = HUP ] && [ "$hup_ignored" = 1 ]; then
    echo "skip SIGHUP during the bake: SIGHUP is ignored in this test's process (nohup), so nmbake ignores it too"
    continue
  fi
  run_and_signal "$sig" "$when"
  # Less the progress line (its redraws end in carriage returns) and the clearing of it.
  err=$(tr '\r' '\n' <"$log/stderr.txt" | grep -v -e '^ *$' -e '^nmbake: ')
  [ "$code" = "$expect" ] || bad "SIG$sig during the $when: exit $code, expected $expect ($err)"
  [ "$err" = "error: interrupted by SIG$sig; no output written" ] || bad "SIG$sig during the $when: stderr: $err"
  [ "$(state)" = "$old" ] || bad "SIG$sig during the $when: files changed or left: $(ls -A | tr '\n' ' ')"
  echo "ok   SIG$sig during the $when: exit $code: $err"
done

# 3. SIGKILL: the temporaries stay, named for the output and the process; the next run removes
# them (not a live process's).
run_and_signal KILL write
[ "$code" = 137 ] || bad "SIGKILL: exit $code"
stale=$(ls -A | grep -c "^\.m\.png\.nmbake-tmp\.$pid$")
[ "$stale" = 1 ] || bad "SIGKILL: no .m.png.nmbake-tmp.$pid left: $(ls -A | tr '\n' ' ')"
others=$(ls -A | grep -v -e '^m\.png$' -e '^miss\.png$' -e '^r\.json$' -e "^\.[a-z.]*\.nmbake-tmp\.$pid$" || true)
[ -z "$others" ] || bad "SIGKILL: unrecognisable files left: $others"
sleep 1000 &
alive=$!
# A dead run's second name of r.json goes; its copy of an old miss.png that differs from miss.png is
# the only copy of an old output (a commit that could not be undone) and stays.
touch ".m.png.nmbake-tmp.$alive" ".other.png.nmbake-tmp.4"
ln r.json ".r.json.nmbake-old.99999999"
echo "an old mask" >".miss.png.nmbake-old.99999998"
"$nmbake" "$low" "$high" -o m.png --size 32 --miss-mask miss.png --report r.json --quiet || bad "the bake after SIGKILL failed"
left=$(ls -A | grep nmbake- | sort | tr '\n' ' ')
[ "$left" = ".m.png.nmbake-tmp.$alive .miss.png.nmbake-old.99999998 .other.png.nmbake-tmp.4 " ] || bad "after SIGKILL, the next run left: $left"
kill "$alive"
echo "ok   SIGKILL left only .NAME.nmbake-tmp.$pid files; the next run removed them (kept: $left)"
exit $fail
