#!/usr/bin/env bash
# The README check (issue 36, item 6): the documentation and the commands' --help name the same
# options. docs/usage.md is the full option list, linked from README.md:
# - every long option listed by `nmbake --help`, `nmbake --batch --help`, `nmdiff --help` and
#   `nmview --help` (when given) appears in docs/usage.md;
# - every long option that README.md or docs/usage.md names is an option of one of them, except the
#   options of other programs they quote (kOthers below).
# Prints each mismatch, exits 1 on any.
#   readme_options.sh REPO NMBAKE NMDIFF [NMVIEW]   (without NMVIEW: nmview's options read from its source)
set -u
repo=$1 nmbake=$2
shift 2
readme=$repo/README.md usage=$repo/docs/usage.md
# Options of other programs the documents quote: cmake's, the accuracy bench's (nmbake_accuracy).
kOthers="--install --prefix --build --target --scenes"
fail=0
for f in "$readme" "$usage"; do
  [ -r "$f" ] || { echo "FAIL: $f is missing"; exit 1; }
done
grep -qF '](docs/usage.md)' "$readme" || { echo "FAIL: README.md does not link docs/usage.md, the full option list"; fail=1; }

# A help text's options: the long names at the start of its option lines ("  -o,--output TEXT ...").
help_options() { sed -nE 's/^ +(-[A-Za-z],)?(--[a-z0-9][a-z0-9-]*).*/\2/p' | sort -u; }
# A document's options: every --word in it.
doc_options() { grep -oE -- '--[a-z][a-z0-9]*(-[a-z0-9]+)*' "$@" | sed 's/^[^:]*://' | sort -u; }

declare -A known
check_help() {  # NAME, then the help text on stdin
  local name=$1 options
  options=$(help_options)
  if [ -z "$options" ]; then
    echo "FAIL: $name: no options found in its help"
    fail=1
    return
  fi
  for o in $options; do
    known[$o]=1
    grep -qE -- "${o}([^a-z0-9-]|$)" "$usage" || { echo "FAIL: $name: $o is not in docs/usage.md"; fail=1; }
  done
}
check_help "nmbake --help" < <("$nmbake" --help)
check_help "nmbake --batch --help" < <("$nmbake" --batch --help)
for exe in "$@"; do
  check_help "$(basename "$exe") --help" < <("$exe" --help)
done
# Without the viewer built (NMBAKE_VIEWER=OFF), nmview's options as its source declares them, so that
# the documents may still name them.
case " $* " in
  *nmview*) ;;
  *) for o in $(grep -oE 'add_(option|flag)\("(-[A-Za-z],)?--[a-z0-9-]+' "$repo/viewer/main.cpp" | grep -oE -- '--[a-z0-9-]+'); do
       known[$o]=1
     done ;;
esac
[ "${#known[@]}" -gt 40 ] || { echo "FAIL: only ${#known[@]} options found in the helps"; fail=1; }

for o in $kOthers; do known[$o]=1; done
for f in "$readme" "$usage"; do
  for o in $(doc_options "$f"); do
    [ -n "${known[$o]:-}" ] || { echo "FAIL: $(basename "$f") names $o, which no --help lists"; fail=1; }
  done
done
[ "$fail" = 0 ] && echo "ok: ${#known[@]} options, README.md and docs/usage.md agree with the helps"
exit "$fail"
