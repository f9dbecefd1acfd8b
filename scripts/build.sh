#!/usr/bin/env bash
# Configures and builds nmbake in build/ (Release). Extra arguments go to cmake's configure step.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_BUILD_DIR:-$root/build}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DNMBAKE_VIEWER="${NMBAKE_VIEWER:-ON}" "$@" >/dev/null
cmake --build "$build" -j "$jobs"
