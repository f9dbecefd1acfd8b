#!/usr/bin/env bash
# --version, --help and a command line in error never load the image module (loading it took
# 0.24-0.37 s of `nmbake --version`); a bake does. LD_DEBUG=files lists every library the dynamic
# loader opens.
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
n=$(opened "$low" "$high" -o "$work/v.png" --size 8 --quiet)
echo "a bake: the image module opened $n times"
[ "$n" -gt 0 ] || fail=1
exit $fail
