#!/usr/bin/env bash
# OpenImageIO's module is loaded only when an image needs it (baker/io/oiio_module.h).
#   oiio_module.sh NMBAKE NMDIFF REPO WORK
# 1. nmbake does not link OpenImageIO, and a PNG bake never loads it or the module.
# 2. An EXR bake loads the module, on 2 threads and on 1; its map is the PNG's within one 8-bit step.
# 3. A copy of nmbake outside the build tree with no module beside it: a PNG bake works; an EXR
#    bake exits 3 with one error line naming the map and the module, and leaves no file.
# 4. The same with a broken module beside it (not a shared library): exit 3, one line, no file.
set -u
nmbake=$(realpath "$1") nmdiff=$(realpath "$2") repo=$(realpath "$3") work=$4
low=$repo/data/sample/torus_low.obj high=$repo/data/sample/torus_high.ply
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fails=0
bad() { echo "FAIL: $*"; fails=$((fails + 1)); }

# 1.
if readelf -d "$nmbake" | grep -q 'NEEDED.*OpenImageIO'; then bad "nmbake links OpenImageIO"; fi
LD_DEBUG=files "$nmbake" "$low" "$high" -o map.png --size 64 --quiet 2>png_debug.txt || bad "the PNG bake failed"
if grep -q 'libnmbake-oiio\|libOpenImageIO' png_debug.txt; then bad "a PNG bake loaded OpenImageIO"; fi

# 2.
for threads in 2 1; do
  LD_DEBUG=files "$nmbake" "$low" "$high" -o "map$threads.exr" --size 64 --threads "$threads" --quiet 2>exr_debug.txt \
    || bad "the EXR bake on $threads threads failed"
  grep -q 'libnmbake-oiio.so' exr_debug.txt || bad "the EXR bake on $threads threads did not load the module"
  "$nmdiff" "map$threads.exr" map.png >diff.txt || { cat diff.txt; bad "the EXR map on $threads threads is not the PNG's"; }
done

# 3. and 4.
apart=$(mktemp -d /tmp/nmbake-oiio-module.XXXXXX)
trap 'rm -rf "$apart"' EXIT
cp "$nmbake" "$apart/nmbake"
refused() {  # refused WHAT TEXT: the EXR bake of the copy exits 3 with one line holding TEXT
  mkdir -p "$apart/out" && rm -f "$apart/out"/*
  "$apart/nmbake" "$low" "$high" -o "$apart/out/map.exr" --size 16 --quiet 2>err.txt
  local code=$?
  [ "$code" = 3 ] || bad "$1: exit $code, not 3"
  if [ "$(wc -l <err.txt)" != 1 ] || ! grep -q "^error: .*out/map.exr.*$2" err.txt; then
    cat err.txt
    bad "$1: not one line naming the map and '$2'"
  fi
  [ -z "$(ls -A "$apart/out")" ] || bad "$1: left $(ls -A "$apart/out")"
}
"$apart/nmbake" "$low" "$high" -o "$apart/map.png" --size 16 --quiet || bad "a copy without the module cannot bake a PNG"
refused "no module" "libnmbake-oiio.so not found"
echo "not a library" >"$apart/libnmbake-oiio.so"
refused "a broken module" "cannot load $apart/libnmbake-oiio.so"

[ "$fails" = 0 ] && echo "oiio module: passed"
[ "$fails" = 0 ]
