#!/usr/bin/env bash
# Bakes the bundled sample and the sculpts of ../shared/data/sculpts with a spread of options and
# keeps every map, mask, cage and report (timings, memory and paths left out) in DIR, or checks that
# a second build gives byte-identical files. Used to show that a refactoring changes no output.
#
#   scripts/compare_outputs.sh save  NMBAKE DIR   # bake with NMBAKE (a binary), keep outputs in DIR
#   scripts/compare_outputs.sh check NMBAKE DIR   # bake again, compare with DIR; exit 1 on any difference
set -euo pipefail
export SOURCE_DATE_EPOCH=0  # EXR and TIFF stamp the time otherwise
mode=${1:?save or check}
nmbake=$(realpath "${2:?path to nmbake}")
dir=${3:?output folder}
root=$(cd "$(dirname "$0")/.." && pwd)
sculpts=$root/../shared/data/sculpts

mkdir -p "$dir"
out=$dir
[[ $mode == check ]] && out=$(mktemp -d) && trap 'rm -rf "$out"' EXIT

normalize() {  # a report without what differs from run to run, absolute paths cut to their file names
  jq -S 'del(.seconds, .peak_memory_bytes, .rays_per_second, .options.low, .options.high, .options.output,
             .options.cage, .options.miss_mask, .options.suspect_mask, .error_estimate.seconds, .udim.tiles[]?.file)
         | walk(if type == "string" then gsub("(?<s>^| )/[^ ]*/"; "\(.s)") else . end)' "$1" > "$1.tmp"
  mv "$1.tmp" "$1"
}

bake() {  # name extension low high [options...]
  local name=$1 ext=$2 low=$3 high=$4
  shift 4
  "$nmbake" "$low" "$high" -o "$out/$name.$ext" --report "$out/$name.json" --miss-mask "$out/$name.miss.exr" \
    --suspect-mask "$out/$name.suspect.png" --quiet "$@"
  normalize "$out/$name.json"
}

sample=$root/data/sample
bake sample png "$sample/torus_low.obj" "$sample/torus_high.ply" --size 512 --save-cage "$out/sample.cage.obj"
bake sample_cage png "$sample/torus_low.obj" "$sample/torus_high.ply" --size 512 --cage "$out/sample.cage.obj"
bake sample_s4_float exr "$sample/torus_low.obj" "$sample/torus_high.ply" --size 256 --samples 4 --estimate-error
bake sample_green png "$sample/torus_low.obj" "$sample/torus_high.ply" --size 256 --green down --bitangent vertex --threads 1
bake sample_object png "$sample/torus_low.obj" "$sample/torus_high.ply" --size 256 --space object
# The golden maps' bakes (tests/test_golden.cpp).
bake golden_torus_256 png "$sample/torus_low.obj" "$sample/torus_high.ply" --size 256
bake golden_torus_128_s4_green_down png "$sample/torus_low.obj" "$sample/torus_high.ply" --size 128 --samples 4 --green down --padding 4
# UDIM tiles 1001 and 1002 (the sample's upper half of UVs moved one tile right), each estimated.
awk '$1 == "vt" && $3 >= 0.5 { printf "vt %.9g %s\n", $2 + 1, $3; next } { print }' "$sample/torus_low.obj" > "$out/sample_udim.low.obj"
"$nmbake" "$out/sample_udim.low.obj" "$sample/torus_high.ply" -o "$out/sample_udim.<UDIM>.png" --size 256 --estimate-error \
  --report "$out/sample_udim.json" --quiet
normalize "$out/sample_udim.json"
if [[ -d $sculpts ]]; then
  for s in $(ls "$sculpts"); do
    bake "$s" png "$sculpts/$s/low.obj" "$sculpts/$s/high.ply" --size 1024 --save-cage "$out/$s.cage.obj"
    bake "${s}_closest" png "$sculpts/$s/low.obj" "$sculpts/$s/high.ply" --size 512 --policy closest --samples 4
    bake "${s}_keep" png "$sculpts/$s/low.obj" "$sculpts/$s/high.ply" --size 512 --keep-backfaces --no-cull
    bake "${s}_global" png "$sculpts/$s/low.obj" "$sculpts/$s/high.ply" --size 512 --front 0.05
    # --estimate-error: --samples auto (the automatic cage, the hit rule); two rays per sample; one
    # fixed distance without the hit rule.
    bake "${s}_estimate" png "$sculpts/$s/low.obj" "$sculpts/$s/high.ply" --size 512 --samples auto --estimate-error
    bake "${s}_estimate_closest" png "$sculpts/$s/low.obj" "$sculpts/$s/high.ply" --size 256 --policy closest --samples 4 \
      --estimate-error
    bake "${s}_estimate_keep" exr "$sculpts/$s/low.obj" "$sculpts/$s/high.ply" --size 256 --samples 2 --keep-backfaces \
      --front 0.05 --rear 0.05 --estimate-error
  done
else
  echo "compare_outputs: $sculpts not found; sample only" >&2
fi

# Byte for byte, but for a report kept before its absolute paths were cut (cut now) and a cage's
# first line, which names its meshes' paths.
same() {  # kept new
  case $1 in
    *.json) cp "$1" "$out/kept.json" && normalize "$out/kept.json" && cmp -s "$out/kept.json" "$2" ;;
    *.cage.obj) cmp -s <(tail -n +2 "$1") <(tail -n +2 "$2") ;;
    *) cmp -s "$1" "$2" ;;
  esac
}

if [[ $mode == check ]]; then
  status=0
  for f in "$dir"/*; do
    name=$(basename "$f")
    if ! same "$f" "$out/$name"; then
      echo "differs: $name" >&2
      status=1
    fi
  done
  [[ $status == 0 ]] && echo "compare_outputs: $(ls "$dir" | wc -l) files identical"
  exit $status
fi
echo "compare_outputs: $(ls "$dir" | wc -l) files kept in $dir"
