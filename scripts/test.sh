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
