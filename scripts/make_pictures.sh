#!/usr/bin/env bash
# Makes the README's pictures in docs/images/ with the build's own programs (build/, or
# NMBAKE_BUILD_DIR; build it first with scripts/build.sh, the viewer on):
#   sample_normal.png   the bundled sample baked at 256^2 (8-bit PNG)
#   viewer_compare.png  nmview's headless screenshot of that map: low-poly + map | high-poly
# Software rendering (llvmpipe) keeps the screenshot the same on every machine. Each picture must
# stay small enough to commit (under 150 KB).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_BUILD_DIR:-$root/build}
out=$root/docs/images
low=$root/data/sample/torus_low.obj
high=$root/data/sample/torus_high.ply
for exe in baker/nmbake viewer/nmview; do
  [ -x "$build/$exe" ] || { echo "error: make_pictures.sh: $build/$exe not built (scripts/build.sh, NMBAKE_VIEWER=ON)" >&2; exit 1; }
done
mkdir -p "$out"
"$build/baker/nmbake" "$low" "$high" -o "$out/sample_normal.png" --size 256 --quiet
LIBGL_ALWAYS_SOFTWARE=1 "$build/viewer/nmview" "$low" "$out/sample_normal.png" "$high" \
  --screenshot "$out/viewer_compare.png" --size 800x400 --view 30,20
for picture in "$out/sample_normal.png" "$out/viewer_compare.png"; do
  bytes=$(stat -c %s "$picture")
  if [ "$bytes" -gt 153600 ]; then echo "error: make_pictures.sh: $picture is $bytes bytes (limit 150 KB)" >&2; exit 1; fi
  echo "wrote $picture ($((bytes / 1024)) KB)"
done
