#!/usr/bin/env bash
# Thread identity: every map nmbake writes is identical, byte for byte, with --threads 1 and
# --threads 2. Bakes the bundled sample and a generated displaced sphere at a few sizes, sample
# counts and options, as PNG (8-bit) and EXR (32-bit float, so no rounding can hide a difference).
#   test-threads.sh [NMBAKE [WORK]]
# ctest runs it (threads.identical, label robustness); by default it uses the nmbake of the normal
# build (build/, or NMBAKE_BUILD_DIR; run scripts/build.sh first).
# SOURCE_DATE_EPOCH pins the DateTime the EXR writer would otherwise stamp with the current time.
set -euo pipefail
export SOURCE_DATE_EPOCH=0
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_BUILD_DIR:-$root/build}
nmbake=${1:-$build/baker/nmbake}
work=${2:-$build/thread-identity}
[ -x "$nmbake" ] || { echo "error: test-threads: $nmbake not built (run scripts/build.sh)" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"

# A UV sphere (low: 32x16 quads with UVs and normals) and a displaced one (high: 192x96 quads).
sphere() {  # sphere NU NV AMPLITUDE -> OBJ on stdout
  awk -v nu="$1" -v nv="$2" -v amp="$3" 'BEGIN {
    pi = 3.14159265358979
    for (j = 0; j <= nv; j++) for (i = 0; i <= nu; i++) {
      th = 2 * pi * i / nu; ph = pi * j / nv
      r = 1 + amp * sin(7 * th) * sin(5 * ph) * sin(ph)
      x = sin(ph) * cos(th); y = sin(ph) * sin(th); z = cos(ph)
      printf "v %.7f %.7f %.7f\nvn %.7f %.7f %.7f\nvt %.7f %.7f\n", r * x, r * y, r * z, x, y, z, i / nu, 1 - j / nv
    }
    for (j = 0; j < nv; j++) for (i = 0; i < nu; i++) {
      a = j * (nu + 1) + i + 1; b = a + 1; c = a + nu + 2; d = a + nu + 1
      if (j > 0) printf "f %d/%d/%d %d/%d/%d %d/%d/%d\n", a, a, a, d, d, d, b, b, b
      if (j < nv - 1) printf "f %d/%d/%d %d/%d/%d %d/%d/%d\n", b, b, b, d, d, d, c, c, c
    }
  }'
}
sphere 32 16 0 >"$work/sphere_low.obj"
sphere 192 96 0.04 >"$work/sphere_high.obj"

sample_low=$root/data/sample/torus_low.obj sample_high=$root/data/sample/torus_high.ply
sphere_low=$work/sphere_low.obj sphere_high=$work/sphere_high.obj
failed=0 n=0
run_case() {  # run_case NAME EXT LOW HIGH ARGS...
  local name=$1 ext=$2 low=$3 high=$4
  shift 4
  n=$((n + 1))
  local t
  for t in 1 2; do
    "$nmbake" "$low" "$high" -o "$work/$name.t$t.$ext" --miss-mask "$work/$name.mask.t$t.exr" --threads "$t" --quiet "$@"
  done
  if cmp -s "$work/$name.t1.$ext" "$work/$name.t2.$ext" && cmp -s "$work/$name.mask.t1.exr" "$work/$name.mask.t2.exr"; then
    echo "ok   $name ($*): map and miss mask identical with 1 and 2 threads"
  else
    echo "FAIL $name ($*): maps differ between --threads 1 and --threads 2"
    failed=$((failed + 1))
  fi
}
run_case sample_256 png "$sample_low" "$sample_high" --size 256
run_case sample_200x120_s5 exr "$sample_low" "$sample_high" --size 200x120 --samples 5
run_case sample_128_s4_closest_object exr "$sample_low" "$sample_high" --size 128 --samples 4 --policy closest --space object
run_case sphere_256 png "$sphere_low" "$sphere_high" --size 256
run_case sphere_96x160_s9 exr "$sphere_low" "$sphere_high" --size 96x160 --samples 9 --padding 4
run_case sample_192_auto exr "$sample_low" "$sample_high" --size 192 --samples auto --max-error 1
run_case sphere_256_auto png "$sphere_low" "$sphere_high" --size 256 --samples auto
run_case sphere_512_s2_green_down png "$sphere_low" "$sphere_high" --size 512 --samples 2 --green down --bits 16
echo "test-threads: $n cases, $failed differ"
[ "$failed" = 0 ]
