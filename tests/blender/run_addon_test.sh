#!/usr/bin/env bash
# blender.addon (tests/blender/CMakeLists.txt): packages the add-on with
# scripts/package-blender-addon.sh and runs tests/blender/test_addon.py in one headless Blender,
# with a user scripts folder, a user config folder and TMPDIR of its own under WORK.
# Exit 77 (skipped) when there is no Blender (tests/packages.txt lists Debian's `blender`);
# NMBAKE_BLENDER names another Blender executable.
# Usage: run_addon_test.sh NMBAKE NMDIFF SOURCE_ROOT WORK
set -euo pipefail
nmbake=$1 nmdiff=$2 root=$3 work=$4
blender=${NMBAKE_BLENDER:-blender}
if ! command -v "$blender" >/dev/null; then
  echo "blender.addon: skipped: no '$blender' on PATH (Debian: apt-get install blender; scripts/test.sh installs tests/packages.txt)"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work/user-scripts" "$work/user-config" "$work/tmp"
bash "$root/scripts/package-blender-addon.sh" "$work/nmbake_blender.zip" >/dev/null
export BLENDER_USER_SCRIPTS=$work/user-scripts BLENDER_USER_CONFIG=$work/user-config TMPDIR=$work/tmp
"$blender" -b --factory-startup --python-exit-code 1 --python "$root/tests/blender/test_addon.py" -- \
  --zip "$work/nmbake_blender.zip" --nmbake "$nmbake" --nmdiff "$nmdiff" --work "$work"
