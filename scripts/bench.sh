#!/usr/bin/env bash
# Builds the bench programs (NMBAKE_BENCH, off in the normal build) in build-bench/ and runs one of
# their targets: bench (default), bench-quick or accuracy. Needs ../shared/data.
#   scripts/bench.sh [TARGET]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_BENCH_BUILD_DIR:-$root/build-bench}
target=${1:-bench}
NMBAKE_BUILD_DIR=$build bash "$root/scripts/build.sh" -DNMBAKE_BENCH=ON -DNMBAKE_TESTS=OFF
# Blender is installed by the bench only, to time the peer side by side (section 10), never by the
# tests. NMBAKE_BENCH_BLENDER=0 skips it; without root or apt-get, section 10 prints nmbake alone.
if [[ $target == bench* ]] && ! command -v blender >/dev/null && [[ ${NMBAKE_BENCH_BLENDER:-1} != 0 ]] &&
  [[ $(id -u) == 0 ]] && command -v apt-get >/dev/null; then
  echo "bench.sh: installing Blender (apt-get) to time it side by side with nmbake"
  if ! DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends blender >/dev/null; then
    echo "bench.sh: could not install Blender; the bench runs without it"
  fi
fi
cmake --build "$build" --target "$target"
