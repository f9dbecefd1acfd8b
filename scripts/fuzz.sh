#!/usr/bin/env bash
# Builds the libFuzzer target fuzz_mesh_load (tests/fuzz) with clang, ASan and UBSan in
# build-fuzz/ and runs it for a bounded time (NMBAKE_FUZZ_SECONDS, default 60) from the corpus in
# tests/fuzz/corpus. New inputs go to build-fuzz/fuzz-run/corpus, never into the repository. A
# crash, leak, timeout or out-of-memory stops the run with a non-zero exit; the input is saved in
# build-fuzz/fuzz-run/artifacts/ (minimise it with `fuzz_mesh_load -minimize_crash=1 FILE`, fix
# the loader, and add it to tests/fuzz/corpus and data/defects).
# NMBAKE_FUZZ_SECONDS is a budget of CPU seconds, spread over NMBAKE_FUZZ_WORKERS fuzzers at once
# (libFuzzer's -jobs/-workers, each for SECONDS/WORKERS, sharing the new-input folder; default 1).
# Several workers do not run as many inputs: on 2 cores two workers of 30 s ran 71,052 + 69,587
# inputs where one worker of 60 s runs ~247,000 (most likely as each worker starts over from the seeds), so the
# test command keeps one. Any worker's crash, leak or timeout fails the run. With "all" readers:
# one worker, in fork mode.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_FUZZ_BUILD_DIR:-$root/build-fuzz}
seconds=${NMBAKE_FUZZ_SECONDS:-60}
# Which readers the timed run fuzzes: "own" (OBJ, PLY, OFF, STL; the default, as CI runs it) or
# "all" (Assimp's formats too, whose own unchecked allocations and memory errors, tests/fuzz/README,
# stop a run within seconds; with "all" out-of-memory inputs and timeouts are noted, not fatal).
readers=${NMBAKE_FUZZ_READERS:-own}
jobs=$(nproc 2>/dev/null || echo 2)
workers=${NMBAKE_FUZZ_WORKERS:-1}
[[ "$workers" =~ ^[1-9][0-9]*$ ]] || { echo "error: fuzz: NMBAKE_FUZZ_WORKERS must be a positive integer, got '$workers'" >&2; exit 1; }
extra=()
if [ "$readers" = all ]; then
  # Fork mode (one worker) notes out-of-memory inputs and timeouts instead of stopping.
  extra=(-fork=1 -ignore_ooms=1 -ignore_timeouts=1)
  workers=1 per_worker=$seconds
else
  per_worker=$(((seconds + workers - 1) / workers))
  [ "$workers" = 1 ] || extra=(-jobs="$workers" -workers="$workers")
fi
export NMBAKE_FUZZ_READERS=$readers
cxx=${NMBAKE_FUZZ_CXX:-$(command -v clang++-14 || command -v clang++ || true)}
[ -n "$cxx" ] || { echo "error: fuzz: clang++ not found (scripts/packages.txt lists clang-14)" >&2; exit 1; }
cmake -S "$root" -B "$build" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNMBAKE_FUZZ=ON \
  -DNMBAKE_TESTS=OFF -DNMBAKE_BENCH=OFF -DNMBAKE_VIEWER=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target fuzz_mesh_load
run=$build/fuzz-run
rm -rf "$run" && mkdir -p "$run/corpus" "$run/artifacts"
echo "fuzz: running fuzz_mesh_load, ${workers} worker(s) for ${per_worker}s each, from tests/fuzz/corpus ($(ls "$root/tests/fuzz/corpus" | wc -l) seeds; readers: $readers)"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# The workers write their logs (fuzz-N.log) into the current folder.
cd "$run"
"$build/tests/fuzz/fuzz_mesh_load" -max_total_time="$per_worker" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
  -use_value_profile=1 -dict="$root/tests/fuzz/mesh.dict" -artifact_prefix="$run/artifacts/" \
  -print_final_stats=1 "${extra[@]}" "$run/corpus" "$root/tests/fuzz/corpus" 2>"$run/log.txt" || {
  code=$?
  tail -n 60 "$run/log.txt" "$run"/fuzz-*.log 2>/dev/null
  echo "error: fuzz: fuzz_mesh_load failed (exit $code); inputs: $(ls "$run/artifacts")" >&2
  exit 1
}
grep -h -E '^(#[0-9]+[[:space:]]+DONE|Done|stat::(number_of_executed_units|new_units_added|peak_rss_mb))' "$run/log.txt" "$run"/fuzz-*.log 2>/dev/null ||
  tail -n 5 "$run/log.txt"
echo "fuzz: no crash, leak or hang in ${workers} x ${per_worker}s; $(ls "$run/corpus" | wc -l) new corpus inputs (not kept)"
