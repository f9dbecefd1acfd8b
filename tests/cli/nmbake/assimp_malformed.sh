#!/usr/bin/env bash
# Every malformed or odd file of the Assimp test set (issue 20: "every malformed file of the Assimp
# test set gives a one-line error naming the file and exit 2: no crash, no hang over 10 s, no
# output"), run from ../shared/data/meshes/assimp twice: as low-poly and high-poly at once
# (`nmbake FILE FILE`) and as the high-poly behind the bundled torus low-poly.
#   assimp_malformed.sh NMBAKE REPO SHARED_DATA WORK [SHARD SHARDS]
# With SHARD and SHARDS only the cases k (from 0) with k % SHARDS == SHARD run.
# Each run has 10 s and must
#   - exit 2 with exactly one stderr line, "error: ..." naming the file (its base name), nothing
#     on stdout, and nothing left in the output folder (neither the map nor a temporary), or
#   - for a file that is valid (the list says why), exit 0 with the map written and no temporary;
#   - "gap": a malformed file that the issue wants refused (exit 2) but that nmbake still bakes
#     (exit 0) because Assimp drops the bad part with only a log message. Such a run passes with
#     either code (checked as above for that code) and is printed as a known gap; a gap that now
#     exits 2 fails the script, so that the list is updated.
# A crash (exit >= 128), a hang (124, 137) or any other code fails. Exit 0 when every run passes,
# 1 when one fails, 77 (skipped) when the shared data is absent. The runs go through
# ../run_cases.sh: under ctest all in one process (nmbake_cases), else one nmbake each.
set -u
nmbake=$(realpath "$1") repo=$(realpath "$2") shared=$3 work=$4 shard=${5:-0} shards=${6:-1}
assimp=$shared/meshes/assimp
low_sample=$repo/data/sample/torus_low.obj
limit=10
if [ ! -d "$assimp" ]; then
  echo "assimp_malformed: $assimp absent: skipped"
  exit 77
fi
rm -rf "$work" && mkdir -p "$work"

# SELF HIGH PATH  reason. SELF: code of `nmbake FILE FILE`; HIGH: code of `nmbake torus_low FILE`.
# 0 = the file is valid and bakes (as low-poly it needs UVs), 2 = refused, gap = see above.
cases=$(
  cat <<'EOF'
2 2 invalid/OutOfMemory.off           face count far beyond the file
2 2 invalid/empty.3ds                 empty
2 2 invalid/empty.ase                 empty
2 2 invalid/empty.lwo                 empty
2 2 invalid/empty.md5mesh             empty
2 2 invalid/empty.obj                 empty
2 2 invalid/empty.off                 empty
2 2 invalid/empty.ply                 empty
2 2 invalid/empty.raw                 empty
2 2 invalid/empty.smd                 empty
2 2 invalid/empty.x                   empty
2 2 invalid/emptyIrrMesh.xml          an Irrlicht mesh without any buffer
2 2 invalid/malformed.obj             vertex indices 0 and out of range
2 2 invalid/malformed2.obj            a face without corners (and a material that does not exist)
2 0 glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb      zero normals: dropped with a warning, smooth ones computed; no UVs
2 2 glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb infinite coordinates
2 2 glTF2/IncorrectVertexArrays/Cube.gltf                   vertex arrays of 35 (not 3n) for triangles and lines: Assimp drops the partial triangle (refused: "malformed")
2 2 glTF2/IndexOutOfRange/AllIndicesOutOfRange.gltf         every index out of range
2 2 glTF2/IndexOutOfRange/IndexOutOfRange.gltf              one index out of range: Assimp drops that triangle (refused: "malformed")
2 2 glTF2/MissingBin/BoxTextured.gltf                       its .bin is missing
2 2 glTF2/RecursiveNodes/RecursiveNodes.gltf                a node cycle
2 2 glTF2/SchemaFailures/sceneWrongType.gltf                "scene" of the wrong JSON type
2 2 glTF2/TestNoRootNode/NoScene.gltf                       no scene
2 2 glTF2/TestNoRootNode/SceneWithoutNodes.gltf             a scene without nodes: no faces
2 2 glTF2/wrongTypes/badArray.gltf                          a member of the wrong JSON type
2 2 glTF2/wrongTypes/badExtension.gltf                      a member of the wrong JSON type
2 2 glTF2/wrongTypes/badNumber.gltf                         a member of the wrong JSON type
2 2 glTF2/wrongTypes/badObject.gltf                         a member of the wrong JSON type
2 2 glTF2/wrongTypes/badString.gltf                         a member of the wrong JSON type
2 2 glTF2/wrongTypes/badUint.gltf                           a member of the wrong JSON type
2 2 glTF2/issue_3269/texcoord_crash.gltf                    TEXCOORD sets not numbered from 0
2 0 glTF2/draco/2CylinderEngine.gltf                        valid: Draco named as used, not required (plain accessors too); no UVs
2 0 glTF2/cameras/Cameras.gltf                              valid: cameras and a square; no UVs
2 0 glTF2/simple_skin/simple_skin.gltf                      valid: a skinned strip (bind pose); no UVs
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_00.gltf  points only: no faces
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_01.gltf  lines only: no faces
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_02.gltf  line loop only: no faces
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_03.gltf  line strip only: no faces
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_04.gltf  valid: triangle strip; no UVs
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_05.gltf  valid: triangle fan; no UVs
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_06.gltf  valid: triangles; no UVs
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_07.gltf  indexed points only: no faces
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_08.gltf  indexed lines only: no faces
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_09.gltf  indexed line loop only: no faces
2 2 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_10.gltf  indexed line strip only: no faces
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_11.gltf  valid: indexed triangle strip; no UVs
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_12.gltf  valid: indexed triangle fan; no UVs
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_13.gltf  valid: 8-bit indices; no UVs
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_14.gltf  valid: 16-bit indices; no UVs
2 0 glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_15.gltf  valid: 32-bit indices; no UVs
2 0 FBX/boxWithCompressedCTypeArray.FBX                     valid: zlib-compressed arrays; no UVs
2 0 FBX/boxWithUncompressedCTypeArray.FBX                   valid: the same arrays uncompressed; no UVs
0 0 FBX/box_orphant_embedded_texture.fbx                    valid: an embedded texture no material uses
0 0 FBX/close_to_identity_transforms.fbx                    valid: node transforms within rounding of identity
0 0 FBX/cubes_nonames.fbx                                   valid: objects without names
0 0 FBX/cubes_with_mirroring_and_pivot.fbx                  valid: mirroring scale and pivots
0 0 FBX/cubes_with_outofrange_float.fbx                     valid: a float property beyond float range (not geometry)
2 0 Collada/ConcavePolygon.dae                              valid: one concave polygon; no UVs
2 0 Collada/cameras.dae                                     valid: cameras and a cube; no UVs
2 2 Collada/cube_UTF16LE.dae                                UTF-16 XML: Assimp's COLLADA reader reads it as malformed XML
2 0 Collada/cube_UTF8BOM.dae                                valid: a UTF-8 byte order mark; no UVs
2 0 Collada/cube_emptyTags.dae                              valid: empty optional elements; no UVs
2 0 Collada/cube_tristrips.dae                              valid: triangle strips; no UVs
2 0 Collada/cube_xmlspecialchars.dae                        valid: XML entities in names; no UVs
0 0 Collada/duck_nomanifest.zae                             valid: a zipped COLLADA without manifest
2 0 Collada/lights.dae                                      valid: lights and a cube; no UVs
0 0 3DS/CameraRollAnim.3ds                                  valid: a camera animation around a textured box
0 0 3DS/TargetCameraAnim.3ds                                valid: a target camera animation around a textured box
2 2 3DS/testFormatDetection                                 no file extension (a 3DS file nmbake does not guess)
2 2 3DS/textures.txt                                        not a mesh: unknown extension
EOF
)

source "$(dirname "$0")/../run_cases.sh"
cases_file=$work/cases.txt
: >"$cases_file"

# One run: queue_run DIR ARGS... adds it to the cases; check_run ROLE EXPECTED FILE DIR checks it
# after run_cases: prints one line, returns 1 on a failure.
queue_run() {
  local dir=$1
  shift
  mkdir -p "$dir"
  # Reading each file is the point: a model unrelated to the sample, or with every face on the whole
  # UV square, is not refused as a mistaken pair here (test_pair_checks covers that).
  cases=$cases_file case_line "$(realpath "$dir")" "$@" -o out.png --size 64 --allow-mismatch --allow-overlap
}
check_run() {
  local role=$1 expect=$2 file=$3 dir=$4
  local got ms name problems=() note=""
  case_result "$dir"
  name=$(basename "$file")
  if [ "$got" = none ]; then
    problems+=("never ended (crash or hang of the run before)")
  elif [ "$got" = 124 ] || [ "$got" = 137 ] || [ "$ms" -gt $((limit * 1000)) ]; then
    problems+=("hung: over ${limit}s")
  elif [ "$got" -ge 128 ]; then
    problems+=("crashed: exit $got")
  elif [ "$expect" = gap ]; then
    [ "$got" = 0 ] && note="KNOWN GAP (bakes; the issue wants exit 2)"
    [ "$got" = 2 ] && problems+=("a known gap now exits 2: update the list")
    [ "$got" = 0 ] || [ "$got" = 2 ] || problems+=("exit code $got, expected 0 (gap)")
  elif [ "$got" != "$expect" ]; then
    problems+=("exit code $got, expected $expect")
  fi
  local left
  left=$(cd "$dir" && ls -A | grep -v -x -e out.png -e stdout.txt -e stderr.txt -e code.txt)
  [ -z "$left" ] || problems+=("left in the output folder: $left")
  if [ "$got" = 0 ]; then
    [ -s "$dir/out.png" ] || problems+=("no map written")
  else
    local lines first
    lines=$(wc -l <"$dir/stderr.txt")
    first=$(head -n 1 "$dir/stderr.txt")
    [ "$lines" = 1 ] || problems+=("stderr has $lines lines, expected one")
    case "$first" in "error: "*) ;; *) problems+=("stderr does not start with 'error: '") ;; esac
    case "$first" in *"$name"*) ;; *) problems+=("the error does not name $name") ;; esac
    [ ! -s "$dir/stdout.txt" ] || problems+=("printed on stdout")
    [ ! -e "$dir/out.png" ] || problems+=("a map was written")
  fi
  if [ ${#problems[@]} -eq 0 ]; then
    [ "$got" = 0 ] || note=$(head -n 1 "$dir/stderr.txt" | cut -c1-200)
    printf 'ok   %-4s %s (%s ms, exit %s) %s\n' "$role" "${file#"$assimp"/}" "$ms" "$got" "$note"
    return 0
  fi
  printf 'FAIL %-4s %s (%s ms): %s\n' "$role" "${file#"$assimp"/}" "$ms" "$(
    IFS=';'
    echo "${problems[*]}"
  )"
  sed 's/^/     stderr: /' "$dir/stderr.txt" 2>/dev/null | head -n 5
  return 1
}

failed=0 ran=0 missing=0 n=0
checks=()
while read -r self high path reason; do
  n=$((n + 1))
  [ $(((n - 1) % shards)) = "$shard" ] || continue
  file=$assimp/$path
  if [ ! -e "$file" ]; then
    echo "FAIL      $path: not in $assimp"
    missing=$((missing + 1))
    continue
  fi
  queue_run "$work/case$n.self" "$file" "$file"
  queue_run "$work/case$n.high" "$low_sample" "$file"
  checks+=("self $self $work/case$n.self $file" "high $high $work/case$n.high $file")
done <<<"$cases"
run_cases "$nmbake" "$cases_file" "$limit"
for c in "${checks[@]}"; do
  read -r role expect dir file <<<"$c"
  check_run "$role" "$expect" "$file" "$dir" || failed=$((failed + 1))
  ran=$((ran + 1))
done
echo "assimp_malformed: $ran runs, $failed failed, $missing files missing"
[ "$failed" = 0 ] && [ "$missing" = 0 ]
