#!/usr/bin/env bash
# Output files that are refused, and how they are written.
#   outputs.sh NMBAKE REPO WORK
# 1. An output that is an input or another output (by identity: symbolic and hard links, "./",
#    another spelling of the folder) is refused with exit 1 before anything is written.
# 2. An output that is a special file (a symbolic link to /dev/full, /dev/null, a FIFO), a symbolic
#    link to nothing, or whose name leaves no room for its temporary file's is refused with exit 3.
# 3. An output that is a symbolic link to a regular file is written through: the link stays.
# 4. --strict with a warning exits 5 and writes nothing; warnings print under --quiet, not under
#    --quiet --quiet or --no-warnings; the report has "warnings", "command", "started", "version"
#    and the dropped normals of each mesh.
# Each refused case must print one "error:" line naming the file and leave every file in the folder
# as it was (contents, links) with no temporary behind.
set -u
nmbake=$(realpath "$1") repo=$(realpath "$2") work=$3
high=$repo/data/sample/torus_high.ply
# shellcheck source=../scene_state.sh
. "$(dirname "$(realpath "$0")")/../scene_state.sh"

# The scene: a low-poly copy, links to it, an old set of outputs.
cp "$repo/data/sample/torus_low.obj" low.obj
ln -s low.obj low_link.obj
ln low.obj low_hard.obj
cp low.obj cage.obj
"$nmbake" low.obj "$high" -o m.png --size 16 --miss-mask miss.png --report r.json --quiet || bad "the first bake failed"
ln -s m.png m_link.png
ln -s /dev/full full.png
ln -s no_such_file.png dangling.png
mkfifo fifo.png
long240=$(printf 'a%.0s' $(seq 1 236)).png
long260=$(printf 'a%.0s' $(seq 1 256)).png

# refused CODE TEXT ARGS...: exit CODE, one line "error: ..." containing TEXT, nothing changed.
refused() {
  local code=$1 text=$2
  shift 2
  local before after got
  before=$(state)
  "$nmbake" "$@" --size 16 --quiet >"$log/stdout.txt" 2>"$log/stderr.txt"
  got=$?
  after=$(state)
  local err
  err=$(cat $log/stderr.txt)
  if [ "$got" != "$code" ]; then bad "$*: exit $got, expected $code ($err)"
  elif [ "$(grep -c '^error:' $log/stderr.txt)" != 1 ] || [ "$(wc -l <$log/stderr.txt)" != 1 ]; then bad "$*: expected one error line: $err"
  elif [ "${err#*"$text"}" = "$err" ]; then bad "$*: error lacks '$text': $err"
  elif [ "$before" != "$after" ]; then bad "$*: files changed: $(diff <(echo "$before") <(echo "$after") | tr '\n' ' ')"
  else echo "ok   exit $got: $err"; fi
}

# 1. Outputs that are inputs or each other: exit 1.
refused 1 "--report low.obj is the same file as low.obj; nothing written" low.obj "$high" -o m.png --report low.obj
refused 1 "--report low_link.obj is the same file as low.obj" low.obj "$high" -o m.png --report low_link.obj
refused 1 "--report low_hard.obj is the same file as low.obj" low.obj "$high" -o m.png --report low_hard.obj
refused 1 "--report ./low.obj is the same file as low.obj" low.obj "$high" -o m.png --report ./low.obj
refused 1 "--report ../scene/low.obj is the same file as low.obj" low.obj "$high" -o m.png --report ../scene/low.obj
refused 1 "--report $work/scene/cage.obj is the same file as cage.obj" low.obj "$high" -o m.png --cage cage.obj \
  --report "$work/scene/cage.obj"
refused 1 "--output low.obj is the same file as low.obj" low.obj "$high" -o low.obj
refused 1 "--report m.png is the same file as m.png" low.obj "$high" -o m.png --report m.png
refused 1 "--miss-mask ./m.png is the same file as m.png" low.obj "$high" -o m.png --miss-mask ./m.png
refused 1 "--suspect-mask m_link.png is the same file as m.png" low.obj "$high" -o m.png --suspect-mask m_link.png
refused 1 "--suspect-mask ./new_mask.png is the same file as new_mask.png" low.obj "$high" -o m.png --miss-mask new_mask.png \
  --suspect-mask ./new_mask.png
refused 1 "--save-cage low_hard.obj is the same file as low.obj" low.obj "$high" -o m.png --save-cage low_hard.obj
refused 1 "--report ./new.obj is the same file as new.obj" low.obj "$high" -o m.png --save-cage new.obj --report ./new.obj

# 2. Special files, links to nothing, names too long: exit 3, up front.
refused 3 "full.png: cannot write the map: it is a symbolic link to a character device (/dev/full)" low.obj "$high" -o full.png
refused 3 "/dev/full: cannot write the map: it is a character device" low.obj "$high" -o /dev/full
refused 3 "/dev/null: cannot write the report: it is a character device" low.obj "$high" -o m.png --report /dev/null
refused 3 "fifo.png: cannot write the miss mask: it is a FIFO" low.obj "$high" -o m.png --miss-mask fifo.png
refused 3 "dangling.png: cannot write the map: it is a symbolic link to a missing file" low.obj "$high" -o dangling.png
refused 3 "cannot write the map: its name is 240 bytes long, more than the 235 that leave room for its temporary file" \
  low.obj "$high" -o "$long240"
refused 3 "cannot write the report: its name is 260 bytes long, more than the folder allows (255)" low.obj "$high" -o m.png \
  --report "$long260"
[ -L full.png ] && [ "$(readlink full.png)" = /dev/full ] || bad "full.png is no longer a link to /dev/full"

# 3. A symbolic link to a regular file is written through.
cp m.png m.old
"$nmbake" low.obj "$high" -o m_link.png --size 24 --quiet 2>stderr.txt || bad "bake through m_link.png failed: $(cat stderr.txt)"
[ -L m_link.png ] && [ "$(readlink m_link.png)" = m.png ] || bad "m_link.png is no longer a link to m.png"
cmp -s m.png m.old && bad "m.png (the link's target) was not rewritten"
file_size=$(stat -c %s m.png)
[ "$file_size" -gt 0 ] || bad "m.png is empty"
echo "ok   a link to a regular file is written through (m.png now $file_size bytes, the link kept)"
rm -f m.old stderr.txt

# 4. Warnings, --quiet, --strict and the report's fields.
mixed=$repo/data/defects/mixed_normals.obj
warning="warning: $mixed: 1 of 2 faces has no normals: all the file's normals were dropped and smooth normals computed (hard edges lost)"
before=$(state)
"$nmbake" low.obj "$mixed" -o m.png --size 16 --miss-mask miss.png --report r.json --quiet --strict >"$log/stdout.txt" 2>"$log/stderr.txt"
code=$?
[ "$code" = 5 ] || bad "--strict: exit $code, expected 5"
grep -qxF "nmbake: $warning" $log/stderr.txt || bad "--strict: the warning is not printed: $(cat $log/stderr.txt)"
grep -q "^error: --strict: 1 warning, the first: $mixed: 1 of 2 faces has no normals.*; nothing written$" $log/stderr.txt ||
  bad "--strict: no error line: $(cat $log/stderr.txt)"
[ "$before" = "$(state)" ] || bad "--strict: files changed"
echo "ok   --strict: exit $code, nothing written"
for q in "" "--quiet" "--quiet --quiet" "--no-warnings"; do
  # shellcheck disable=SC2086
  SOURCE_DATE_EPOCH=1795575845 "$nmbake" low.obj "$mixed" -o m.png --size 16 --report r.json $q >stdout.txt 2>stderr.txt ||
    bad "warnings with '$q': the bake failed"
  printed=$(grep -cxF "nmbake: $warning" stderr.txt)
  expect=1
  case "$q" in *"--quiet --quiet"* | *--no-warnings*) expect=0 ;; esac
  [ "$printed" = "$expect" ] || bad "with '$q' the warning printed $printed times, expected $expect"
  python3 - "$warning" "$nmbake" "$q" <<'EOF' || bad "the report with '$q' lacks its fields"
import json, sys
r = json.load(open("r.json"))
warning, exe, q = sys.argv[1], sys.argv[2], sys.argv[3]
assert warning in r["warnings"], r["warnings"]
assert r["started"] == "2026-11-25T03:04:05Z", r["started"]
assert r["version"] == r["nmbake_version"], (r["version"], r["nmbake_version"])
assert r["command"][0] == exe and r["command"][1:5] == ["low.obj", r["options"]["high"], "-o", "m.png"], r["command"]
assert r["high_mesh"]["normals_dropped"] is True and r["high_mesh"]["faces_without_normals"] == 1, r["high_mesh"]
assert r["high_mesh"]["uvs_dropped"] is False and r["high_mesh"]["faces_without_uvs"] == 0, r["high_mesh"]
assert r["low_mesh"]["normals_dropped"] is False and r["low_mesh"]["faces_without_normals"] == 0, r["low_mesh"]
EOF
  echo "ok   warnings with '$q': printed $printed"
done
rm -f stdout.txt stderr.txt
left=$(ls -A | grep nmbake- || true)
[ -z "$left" ] || bad "temporaries left: $left"
exit $fail
