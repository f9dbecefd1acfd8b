#!/usr/bin/env bash
# Installs the Debian packages nmbake needs that are not installed yet (needs root).
# Lists: scripts/packages.txt (baker, tests), viewer/packages.txt (unless NMBAKE_VIEWER=OFF) and
# tests/packages.txt (with NMBAKE_TEST_DEPS=1: the test command).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
lists=("$root/scripts/packages.txt")
if [ "${NMBAKE_VIEWER:-ON}" != "OFF" ] && [ -f "$root/viewer/packages.txt" ]; then lists+=("$root/viewer/packages.txt"); fi
# What only the test command needs (scripts/test.sh sets NMBAKE_TEST_DEPS=1): the peers the
# integration tests drive (tests/packages.txt).
if [ "${NMBAKE_TEST_DEPS:-0}" = 1 ] && [ -f "$root/tests/packages.txt" ]; then lists+=("$root/tests/packages.txt"); fi
missing=()
for pkg in $(grep -hv '^\s*#' "${lists[@]}" | tr -s ' \t' '\n' | sed '/^$/d' | sort -u); do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed'; then missing+=("$pkg"); fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "error: install-deps: root is needed to install: ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
