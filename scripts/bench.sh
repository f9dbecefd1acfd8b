#!/usr/bin/env bash
# Builds the bench programs (NMBAKE_BENCH, off in the normal build) in build-bench/ and runs one of
# their targets: bench (default), bench-quick or accuracy. Needs ../shared/data.
#   scripts/bench.sh [TARGET]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_BENCH_BUILD_DIR:-$root/build-bench}
target=${1:-bench}
NMBAKE_BUILD_DIR=$build bash "$root/scripts/build.sh" -DNMBAKE_BENCH=ON -DNMBAKE_TESTS=OFF
cmake --build "$build" --target "$target"
