#!/usr/bin/env bash
# The C++ sources follow .clang-format: lists the files clang-format would change; exit 1 if any.
# Exit 77 (skipped) where clang-format is not installed. The files go to clang-format 40 at a time,
# one batch per core: one process a file cost ~13 s of process starts.
set -euo pipefail
root=${1:?source folder}
command -v clang-format >/dev/null || { echo "clang-format not installed: skipped"; exit 77; }
cd "$root"
list() { git ls-files '*.cpp' '*.h' 2>/dev/null || find baker raycast nmdiff viewer tests bench -name '*.cpp' -o -name '*.h'; }
# Each finding is "FILE:LINE:COL: error: code should be clang-formatted [-Wclang-format-violations]";
# anything else clang-format says (an unreadable file, a bad .clang-format) is shown as it is, and
# a non-zero exit without findings fails too.
code=0
report=$(list | tr '\n' '\0' | xargs -0 -r -n 40 -P "$(nproc 2>/dev/null || echo 2)" clang-format --dry-run -Werror 2>&1 >/dev/null) || code=$?
[ -z "$report" ] && [ "$code" = 0 ] && exit 0
bad=$(echo "$report" | grep -E ': error: code should be clang-formatted' | sed -E 's/^([^:]+):[0-9]+:[0-9]+: .*/\1/' | sort -u || true)
for f in $bad; do echo "not formatted: $f (clang-format -i $f)"; done
echo "$report" | grep -E ': (error|warning): ' | grep -v -E ': error: code should be clang-formatted' | sort -u || true
exit 1
