#!/usr/bin/env bash
# install.sh CMAKE BUILD WORK SAMPLE_DIR BINDIR VIEWER(0|1) LIBDIR
# Installs BUILD into a prefix under WORK, checks the layout, bakes the bundled sample with the
# installed nmbake from another folder (by PATH), moves the prefix and bakes again, and runs the
# installed nmdiff on that map and nmview --help. An EXR bake and its nmdiff check that the
# installed programs find OpenImageIO's module (baker/io/oiio_module.h) in the moved tree: a
# program outside the build tree never falls back to the build's module. Leaves nothing behind: WORK's scratch folder is removed and
# BUILD's install_manifest.txt, which `cmake --install` rewrites, is put back as it was.
set -euo pipefail
cmake=$1 build=$2 work=$3 sample=$4 bindir=$5 viewer=$6 libdir=$7
scratch=$(mktemp -d "$work/install-test.XXXXXX")
manifest=$build/install_manifest.txt
had_manifest=0
if [ -e "$manifest" ]; then had_manifest=1; cp -p "$manifest" "$scratch/manifest.saved"; fi
cleanup() {
  if [ "$had_manifest" = 1 ]; then cp -p "$scratch/manifest.saved" "$manifest"; else rm -f "$manifest"; fi
  rm -rf "$scratch"
}
trap cleanup EXIT
fail() { echo "install test: $*" >&2; exit 1; }

prefix=$scratch/prefix
"$cmake" --install "$build" --prefix "$prefix" >"$scratch/install.log" || { cat "$scratch/install.log"; fail "cmake --install failed"; }

# The layout: the commands in BINDIR.
expected="nmbake nmdiff"
[ "$viewer" = 1 ] && expected="nmbake nmdiff nmview"
[ "$(ls "$prefix/$bindir" | sort | tr '\n' ' ')" = "$expected " ] || fail "$bindir holds: $(ls "$prefix/$bindir" | tr '\n' ' ')"
[ "$(find "$prefix/$libdir/nmbake" -type f | wc -l)" = 1 ] && [ -f "$prefix/$libdir/nmbake/libnmbake-oiio.so" ] \
  || fail "$libdir/nmbake holds: $(ls "$prefix/$libdir/nmbake" 2>&1 | tr '\n' ' ')"

bake() {  # bake PREFIX FOLDER [MAP]: the installed nmbake, found by PATH, run in FOLDER
  local map=${3:-map.png}
  mkdir -p "$2"
  (cd "$2" && PATH="$1/$bindir:$PATH" nmbake "$sample/torus_low.obj" "$sample/torus_high.ply" -o "$map" --size 64 --quiet) \
    || fail "installed nmbake exited $? in $2 (-o $map)"
  [ -s "$2/$map" ] || fail "no $map in $2"
}
bake "$prefix" "$scratch/elsewhere"
mv "$prefix" "$scratch/moved"
bake "$scratch/moved" "$scratch/elsewhere2"
bake "$scratch/moved" "$scratch/elsewhere2" map.exr

"$scratch/moved/$bindir/nmdiff" --help >/dev/null || fail "installed nmdiff --help failed"
(cd "$scratch/elsewhere2" && "$scratch/moved/$bindir/nmdiff" map.png map.png >/dev/null) || fail "installed nmdiff could not compare maps"
(cd "$scratch/elsewhere2" && "$scratch/moved/$bindir/nmdiff" map.exr map.png >/dev/null) || fail "installed nmdiff could not compare an EXR map"
if [ "$viewer" = 1 ]; then "$scratch/moved/$bindir/nmview" --help >/dev/null || fail "installed nmview --help failed"; fi
echo "install test: passed"
