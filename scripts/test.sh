#!/usr/bin/env bash
# Command 2: install what is missing, then run every test configuration:
#   lint     the sources follow .clang-format (tests/check_format.sh): seconds, so first
#   unit     the normal Release build (build/, with the bench programs) and its whole test suite with
#            ctest, the thread identity check among it (threads.identical)
#   asan     an ASan+UBSan build (build-asan/) and the whole test suite again (scripts/test-sanitize.sh)
#   fuzz     the mesh-loading fuzz target for 60 s (build-fuzz/, scripts/fuzz.sh)
# NMBAKE_TEST_PARTS picks some of them (default "lint unit asan fuzz"; "threads" runs the thread
# check alone, in an existing build/); the first failing part stops the run. Each part's wall time
# is printed at the end.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_BUILD_DIR:-$root/build}
parts=${NMBAKE_TEST_PARTS:-lint unit asan fuzz}
NMBAKE_TEST_DEPS=1 bash "$root/scripts/install-deps.sh"
# A compiler cache (ccache, tests/packages.txt) for the three builds, kept outside the checkout
# (ccache's own default, ~/.cache/ccache): a run on a machine that ran the tests before compiles only
# what changed, wherever the checkout is (paths under the checkout are hashed relative to it; the
# precompiled headers' defines and timestamps are not hashed, so their users hit too).
# NMBAKE_CCACHE=0, or a CMAKE_CXX_COMPILER_LAUNCHER of one's own, turns this off.
if [ "${NMBAKE_CCACHE:-1}" = 1 ] && [ -z "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ] && command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
  export CCACHE_SLOPPINESS=${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}
  echo "test.sh: compiler cache: ccache in ${CCACHE_DIR:-$(ccache -k cache_dir 2>/dev/null || echo '~/.cache/ccache')}"
fi
summary=()
for part in $parts; do
  start=$(date +%s)
  echo "=== test.sh: $part"
  case "$part" in
    lint)
      code=0
      bash "$root/tests/check_format.sh" "$root" || code=$?
      [ "$code" = 0 ] || [ "$code" = 77 ] || exit "$code" ;;
    unit)
      # The bench programs too (compiled, not run), so a change that breaks them fails here.
      bash "$root/scripts/build.sh" -DNMBAKE_BENCH=ON
      (cd "$build" && ctest --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" --timeout 900) ;;
    threads) (cd "$build" && ctest --output-on-failure -R '^threads\.identical$') ;;
    asan) bash "$root/scripts/test-sanitize.sh" ;;
    fuzz) bash "$root/scripts/fuzz.sh" ;;
    *) echo "error: test.sh: unknown part '$part' in NMBAKE_TEST_PARTS (lint unit threads asan fuzz)" >&2; exit 1 ;;
  esac
  summary+=("$part $(($(date +%s) - start))s")
done
echo "=== test.sh: all passed ($(IFS=','; echo "${summary[*]}" | sed 's/,/, /g'))"
