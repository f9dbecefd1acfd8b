#!/usr/bin/env bash
# A real full disk: a bake onto a 64 KiB tmpfs (mounted in a private mount namespace, so nothing
# outlives the test) that holds a small old set of outputs but not the new map.
#   disk_full.sh NMBAKE REPO WORK
# Must exit 3 with one line "error: m.png: cannot write: No space left on device", leave the old
# map, miss mask and report byte-identical and no temporary behind. Exit 77 (skipped) where
# tmpfs cannot be mounted (not root, no unshare).
set -u
nmbake=$(realpath "$1") repo=$(realpath "$2") work=$3
rm -rf "$work" && mkdir -p "$work/disk" || exit 1
if [ "$(id -u)" != 0 ] || ! command -v unshare >/dev/null || ! unshare -m true 2>/dev/null; then
  echo "skipped: mounting a tmpfs needs root and unshare"
  exit 77
fi
export nmbake repo work
unshare -m bash -c '
  mount -t tmpfs -o size=64k tmpfs "$work/disk" || exit 77
  cd "$work/disk" || exit 1
  low=$repo/data/sample/torus_low.obj high=$repo/data/sample/torus_high.ply
  bake() { "$nmbake" "$low" "$high" -o m.png --miss-mask miss.png --report r.json --quiet "$@"; }
  bake --size 32 || { echo "FAIL: the old outputs do not fit"; exit 1; }
  old=$(md5sum m.png miss.png r.json)
  bake --size 512 2>"$work/stderr.txt"
  code=$?
  err=$(cat "$work/stderr.txt")
  fail=0
  [ "$code" = 3 ] || { echo "FAIL: exit $code, expected 3"; fail=1; }
  [ "$err" = "error: m.png: cannot write: No space left on device" ] || { echo "FAIL: stderr: $err"; fail=1; }
  [ "$(md5sum m.png miss.png r.json)" = "$old" ] || { echo "FAIL: the old outputs changed"; fail=1; }
  [ "$(ls -A | tr "\n" " ")" = "m.png miss.png r.json " ] || { echo "FAIL: files left: $(ls -A)"; fail=1; }
  echo "disk full: exit $code: $err"
  exit $fail
'
