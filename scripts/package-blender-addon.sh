#!/usr/bin/env bash
# Makes the Blender add-on's zip: nmbake_blender/ and its .py files, what Blender's
# Edit > Preferences > Add-ons > Install... takes (docs/blender.md). Python's zipfile, no `zip`.
# The entries are sorted and dated 1980-01-01, so the zip of one source is the same bytes.
# Usage: scripts/package-blender-addon.sh [OUT.zip]   (default: build/nmbake_blender.zip)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/build/nmbake_blender.zip}
mkdir -p "$(dirname "$out")"
python3 - "$root/blender/nmbake_blender" "$out" <<'PY'
import os, sys, zipfile
src, out = sys.argv[1], sys.argv[2]
names = sorted(n for n in os.listdir(src) if n.endswith(".py"))
if "__init__.py" not in names:
    sys.exit("package-blender-addon.sh: %s has no __init__.py" % src)
tmp = out + ".tmp"
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
    for name in names:
        info = zipfile.ZipInfo("nmbake_blender/" + name, date_time=(1980, 1, 1, 0, 0, 0))
        info.external_attr = 0o644 << 16
        info.compress_type = zipfile.ZIP_DEFLATED
        with open(os.path.join(src, name), "rb") as f:
            z.writestr(info, f.read())
os.replace(tmp, out)
print(out)
PY
