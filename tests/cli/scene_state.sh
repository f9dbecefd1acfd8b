# Sourced by the output tests (output_contract.sh, nmbake/outputs.sh) with $work set: makes
# $work/scene the current folder, $log ($work) the place for the command's output outside it, and
# defines bad (a FAIL line; the script exits with $fail) and state (contents and links of every
# file in the folder, to compare before and after a run).
rm -rf "$work" && mkdir -p "$work/scene" && cd "$work/scene" || exit 1
log=$work
fail=0
bad() { echo "FAIL: $*"; fail=1; }
state() { for f in $(ls -A | sort); do
  if [ -L "$f" ]; then echo "$f -> $(readlink "$f")"; elif [ -f "$f" ]; then echo "$f $(md5sum <"$f")"; else echo "$f other"; fi
done; }
