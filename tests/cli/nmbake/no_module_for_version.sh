#!/usr/bin/env bash
# --version, --help and a command line in error never load the image module (loading it took
# 0.24-0.37 s of `nmbake --version`), nor does a bake to PNG (written with libpng directly); a bake
# to EXR or TGA does. LD_DEBUG=files lists every library the dynamic loader opens.
#   no_module_for_version.sh NMBAKE LOW HIGH WORK
set -u
nmbake=$1 low=$2 high=$3 work=$4
mkdir -p "$work"
opened() { LD_DEBUG=files "$nmbake" "$@" 2>&1 | grep -c libnmbake_oiio; }
fail=0
for args in --version --help --size; do
  n=$(opened $args)
  echo "nmbake $args: the image module opened $n times"
  [ "$n" = 0 ] || fail=1
done
n=$(opened "$low" "$high" -o "$work/v.png" --miss-mask "$work/m.png" --size 8 --quiet)
echo "a bake to PNG: the image module opened $n times"
[ "$n" = 0 ] || fail=1
[ -s "$work/v.png" ] && [ -s "$work/m.png" ] || { echo "the PNG bake wrote no map or mask"; fail=1; }
for out in v.exr v.tga; do
  n=$(opened "$low" "$high" -o "$work/$out" --size 8 --quiet)
  echo "a bake to $out: the image module opened $n times"
  [ "$n" -gt 0 ] || fail=1
done
n=$(opened "$low" "$high" -o "$work/w.png" --miss-mask "$work/w.tif" --size 8 --quiet)
echo "a bake to PNG with a TIFF mask: the image module opened $n times"
[ "$n" -gt 0 ] || fail=1
exit $fail
