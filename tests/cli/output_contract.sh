#!/usr/bin/env bash
# The output contract of the three commands (io/output_files.h; issue 34, items 7 and 10), run for
# each one on the same cases:
#   output_contract.sh nmbake|nmdiff|nmview EXE REPO WORK
# 1. An output that is an input or another output (by identity: symbolic and hard links, "./") is
#    refused before anything is written: nmbake and nmview exit 1, nmdiff 2 (its 1 is "outside").
# 2. An output that is a folder, a device, a FIFO, /dev/null, a symbolic link to /dev/full or to
#    nothing, or whose name leaves no room for its temporary file's is refused with exit 3.
# 3. An output that is a symbolic link to a regular file is written through: the link stays.
# 4. Under ulimit -f (a file size limit) a write past it is exit 3 with one error line naming the
#    file ("File too large"), never a SIGXFSZ death; the old outputs stay as they were.
# Each refused case prints one "error:" line naming the file and leaves every file in the folder as
# it was (contents, links), with no temporary behind. Exit 77 (skipped) where nmview cannot render.
set -u
tool=$1 exe=$(realpath "$2") repo=$(realpath "$3") work=$4
high=$repo/data/sample/torus_high.ply
# shellcheck source=scene_state.sh
. "$(dirname "$(realpath "$0")")/scene_state.sh"

# The tool's command line writing OUT (and OUT2 where it has a second output), its input file in
# the folder, and its exit status for an output that is an input.
cp "$repo/data/sample/torus_low.obj" low.obj
cp "$repo/data/golden/torus_256.png" a.png
case $tool in
  nmbake) input=low.obj same=1 second=1
    run() { "$exe" low.obj "$high" -o "$1" --size 64 --quiet ${2:+--report "$2"}; } ;;
  nmdiff) input=a.png same=2 second=1
    run() { "$exe" a.png a.png --heatmap "$1" ${2:+--json "$2"}; } ;;
  nmview) input=a.png same=1 second=0
    run() { "$exe" low.obj a.png "$high" --screenshot "$1" --size 64x32; } ;;
  *) echo "unknown tool $tool"; exit 1 ;;
esac
run out.png out.json >"$log/stdout.txt" 2>"$log/stderr.txt"
code=$?
if [ "$tool" = nmview ] && [ "$code" != 0 ] && grep -qi "egl\|display" "$log/stderr.txt"; then
  echo "skipped: nmview cannot render here: $(cat "$log/stderr.txt")"
  exit 77
fi
[ "$code" = 0 ] || { echo "FAIL: the first run failed ($code): $(cat "$log/stderr.txt")"; exit 1; }
ln -s "$input" input_link.png
ln "$input" input_hard.png
ln -s out.png out_link.png
ln -s /dev/full full.png
ln -s no_such_file.png dangling.png
mkfifo fifo.png
mkdir folder.png
long240=$(printf 'a%.0s' $(seq 1 236)).png

# refused CODE TEXT OUT [OUT2]: exit CODE, one "error:" line containing TEXT, nothing changed.
refused() {
  local code=$1 text=$2
  shift 2
  local before after got err
  before=$(state)
  run "$@" >"$log/stdout.txt" 2>"$log/stderr.txt"
  got=$?
  after=$(state)
  err=$(grep '^error:' "$log/stderr.txt")
  if [ "$got" != "$code" ]; then bad "$*: exit $got, expected $code ($(cat "$log/stderr.txt"))"
  elif [ "$(grep -c '^error:' "$log/stderr.txt")" != 1 ] || [ "$(wc -l <"$log/stderr.txt")" != 1 ]; then
    bad "$*: expected one error line: $(cat "$log/stderr.txt")"
  elif [ "${err#*"$text"}" = "$err" ]; then bad "$*: error lacks '$text': $err"
  elif [ "$before" != "$after" ]; then bad "$*: files changed: $(diff <(echo "$before") <(echo "$after") | tr '\n' ' ')"
  else echo "ok   exit $got: $err"; fi
}

# 1. Outputs that are inputs or each other.
refused $same "$input is the same file as" "$input"
refused $same "./$input is the same file as" "./$input"
refused $same "input_link.png is the same file as" input_link.png
refused $same "input_hard.png is the same file as" input_hard.png
refused $same "../scene/$input is the same file as" "../scene/$input"
if [ "$second" = 1 ]; then
  refused $same "out.png is the same file as out.png; nothing written" out.png out.png
  refused $same "out_link.png is the same file as out.png" out.png out_link.png
  refused $same "./new.png is the same file as new.png" new.png ./new.png
fi

# 2. Files that are not regular, links to nothing, folders, names too long: exit 3.
refused 3 "full.png: cannot write the" full.png
refused 3 "it is a symbolic link to a character device (/dev/full)" full.png
refused 3 "/dev/full: cannot write the" /dev/full
refused 3 "/dev/null: cannot write the" /dev/null
refused 3 "fifo.png: cannot write the" fifo.png
refused 3 "it is a FIFO" fifo.png
refused 3 "dangling.png: cannot write the" dangling.png
refused 3 "it is a symbolic link to a missing file" dangling.png
refused 3 "it is a directory" folder.png
refused 3 "folder no/such does not exist" no/such/out.png
refused 3 "its name is 240 bytes long, more than the 235 that leave room for its temporary file" "$long240"
if [ "$second" = 1 ]; then refused 3 "fifo.png: cannot write the" out.png fifo.png; fi
[ -L full.png ] && [ "$(readlink full.png)" = /dev/full ] || bad "full.png is no longer a link to /dev/full"
[ -p fifo.png ] || bad "fifo.png is no longer a FIFO"

# 3. A symbolic link to a regular file is written through.
echo old >target.png
ln -s target.png through.png
run through.png >"$log/stdout.txt" 2>"$log/stderr.txt" || bad "writing through through.png failed: $(cat "$log/stderr.txt")"
[ -L through.png ] && [ "$(readlink through.png)" = target.png ] || bad "through.png is no longer a link to target.png"
cmp -s target.png out.png || bad "target.png (the link's target) differs from out.png"
echo "ok   a link to a regular file is written through"

# 4. ulimit -f: every output here is larger than 1 KiB (nmdiff's JSON is not, its heatmap is).
before=$(state)
(ulimit -f 1 && run out.png out.json) >"$log/stdout.txt" 2>"$log/stderr.txt"
code=$?
err=$(grep '^error:' "$log/stderr.txt")
if [ "$code" != 3 ]; then bad "ulimit -f: exit $code, expected 3: $(cat "$log/stderr.txt")"
elif [ "$(grep -c '^error:' "$log/stderr.txt")" != 1 ] || [ "${err#*out.png: cannot write: File too large}" = "$err" ]; then
  bad "ulimit -f: expected one line naming out.png: $(cat "$log/stderr.txt")"
elif [ "$before" != "$(state)" ]; then bad "ulimit -f: files changed: $(diff <(echo "$before") <(state) | tr '\n' ' ')"
else echo "ok   ulimit -f: exit $code: $err"; fi

left=$(ls -A | grep -e nmbake- -e '\.tmp-' || true)
[ -z "$left" ] || bad "temporaries left: $left"
exit $fail
