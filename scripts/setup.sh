#!/usr/bin/env bash
# Command 1: install what is missing, build, and bake the bundled sample.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_BUILD_DIR:-$root/build}
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh"
"$build/baker/nmbake" "$root/data/sample/torus_low.obj" "$root/data/sample/torus_high.ply" \
  -o "$build/sample_normal.png" --size 1024 --report "$build/sample_report.json"
echo "sample map: $build/sample_normal.png (report: $build/sample_report.json)"
