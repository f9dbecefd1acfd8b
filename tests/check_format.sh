#!/usr/bin/env bash
# The C++ sources follow .clang-format: lists the files clang-format would change; exit 1 if any.
# Exit 77 (skipped) where clang-format is not installed.
set -euo pipefail
root=${1:?source folder}
command -v clang-format >/dev/null || { echo "clang-format not installed: skipped"; exit 77; }
cd "$root"
status=0
while IFS= read -r f; do
  if ! clang-format --dry-run -Werror "$f" >/dev/null 2>&1; then
    echo "not formatted: $f (clang-format -i $f)"
    status=1
  fi
done < <(git ls-files '*.cpp' '*.h' 2>/dev/null || find baker raycast nmdiff viewer tests bench -name '*.cpp' -o -name '*.h')
exit $status
