#!/usr/bin/env bash
# Runs nmbake on every hostile or odd input file of a list and checks each run.
#   hostile.sh NMBAKE REPO WORK LIST [SHARD SHARDS]
# With SHARD and SHARDS, only the cases k (counted from 0) with k % SHARDS == SHARD run, so that
# ctest can run the shards of a list in parallel.
# LIST has one case a line: ROLE CODE PATH TEXT...
#   ROLE  low (the file is the low-poly, the bundled sample's high-poly is the high-poly) or high
#   CODE  the exit code nmbake must return
#   PATH  relative to REPO; "shared:" + a path means REPO/../shared/data/<path> (or
#         $NMBAKE_SHARED_DATA_DIR/<path>); "abs:" + a path is taken as is
#   TEXT  for CODE 0, "-" or words stderr must contain (a warning); otherwise words the error
#         line must contain
# A failing case must print exactly one line on stderr, "error: ..." naming the file (its base
# name), contain TEXT, and leave nothing behind in its work folder (neither the map, the miss mask
# nor the report, nor a temporary); a successful one must write all three. Every case must end within the time limit
# (NMBAKE_HOSTILE_SECONDS, default 20; a hang is killed by timeout and fails). The cases run
# through ../run_cases.sh: under ctest all in one process (nmbake_cases), else one nmbake each.
# Exit 0 when every case passes, 1 when one fails, 77 (skipped) when the list only names shared
# files and ../shared is absent.
set -u
nmbake=$(realpath "$1") repo=$(realpath "$2") work=$3 list=$4 shard=${5:-0} shards=${6:-1}
shared=${NMBAKE_SHARED_DATA_DIR:-$repo/../shared/data}
limit=${NMBAKE_HOSTILE_SECONDS:-20}
low_sample=$repo/data/sample/torus_low.obj
high_sample=$repo/data/sample/torus_high.ply
rm -rf "$work" && mkdir -p "$work"
source "$(dirname "$0")/../run_cases.sh"
cases=$work/cases.txt
: >"$cases"
failed=0 ran=0 skipped=0 n=0
roles=() codes=() paths=() texts=() files=() dirs=()
while read -r role code path text; do
  case "$role" in ''|\#*) continue ;; esac
  n=$((n + 1))
  [ $(((n - 1) % shards)) = "$shard" ] || continue
  case "$path" in
    shared:*) file=$shared/${path#shared:} ;;
    abs:*) file=${path#abs:} ;;
    *) file=$repo/$path ;;
  esac
  if [ "${path#shared:}" != "$path" ] && [ ! -e "$file" ]; then skipped=$((skipped + 1)); continue; fi
  dir=$(realpath -m "$work/case$n")
  mkdir -p "$dir"
  if [ "$role" = low ]; then args=("$file" "$high_sample"); else args=("$low_sample" "$file"); fi
  # The cases are about reading each file: a file unrelated to the sample is not a mistaken pair
  # here (the pair's checks have their own tests, test_pair_checks).
  case_line "$dir" "${args[@]}" --allow-mismatch --allow-overlap -o map.png --size 32 --padding 2 --miss-mask miss.png \
    --report report.json
  roles+=("$role") codes+=("$code") paths+=("$path") texts+=("$text") files+=("$file") dirs+=("$dir")
done <"$list"
run_cases "$nmbake" "$cases" "$limit"
for k in "${!dirs[@]}"; do
  role=${roles[k]} code=${codes[k]} path=${paths[k]} text=${texts[k]} file=${files[k]} dir=${dirs[k]}
  case_result "$dir"
  ran=$((ran + 1))
  problems=()
  [ "$got" = none ] && problems+=("never ended (crash or hang of the run before)")
  [ "$got" = 124 ] || [ "$got" = 137 ] || [ "$ms" -gt $((limit * 1000)) ] && problems+=("hung: over ${limit}s")
  [ "$got" = "$code" ] || problems+=("exit code $got, expected $code")
  name=$(basename "$file")
  if [ "$code" = 0 ]; then
    for out in map.png miss.png report.json; do [ -s "$dir/$out" ] || problems+=("no $out written"); done
    [ "$text" = "-" ] || grep -qF -- "$text" "$dir/stderr.txt" || problems+=("stderr lacks: $text")
  else
    lines=$(wc -l <"$dir/stderr.txt")
    [ "$lines" = 1 ] || problems+=("stderr has $lines lines, expected one")
    first=$(head -n 1 "$dir/stderr.txt")
    case "$first" in "error: "*) ;; *) problems+=("stderr does not start with 'error: '") ;; esac
    case "$first" in *"$name"*) ;; *) problems+=("error does not name $name") ;; esac
    case "$first" in *"$text"*) ;; *) problems+=("error lacks: $text") ;; esac
    left=$(cd "$dir" && ls -A | grep -v -e '^stderr.txt$' -e '^stdout.txt$' -e '^code.txt$' || true)
    [ -z "$left" ] || problems+=("files left behind: $left")
  fi
  if [ ${#problems[@]} -eq 0 ]; then
    printf 'ok   %-5s %s (%s ms, exit %s) %s\n' "$role" "$path" "$ms" "$got" "$(head -c 200 "$dir/stderr.txt" | head -n 1)"
  else
    failed=$((failed + 1))
    printf 'FAIL %-5s %s (%s ms): %s\n' "$role" "$path" "$ms" "$(IFS=';'; echo "${problems[*]}")"
    sed 's/^/     stderr: /' "$dir/stderr.txt" 2>/dev/null | head -n 5
  fi
done
echo "hostile: $ran cases run, $failed failed, $skipped skipped (../shared absent)"
if [ "$ran" = 0 ] && [ "$skipped" -gt 0 ]; then exit 77; fi
[ "$failed" = 0 ]
