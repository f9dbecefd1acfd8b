# Sourced by the under_ulimit.sh scripts. start_limit CMD [ARGS...] prints the lowest `ulimit -v`
# (MB, a multiple of 20, at most 4000) under which CMD ARGS exits 0 three times in a row, or
# nothing. Below it the command cannot start: the dynamic loader or a library's static constructor
# fails before main (exit 127, 134 or 139), which no check of nmbake's can catch (README, "Exit codes
# and errors").
starts_under() {  # starts_under MB CMD [ARGS...]
  local mb=$1
  shift
  timeout 60 bash -c "ulimit -v $((mb * 1024)); exec \"\$@\"" bash "$@" >/dev/null 2>&1
}
start_limit() {
  local low=0 high=4000 mid
  starts_under $high "$@" || return 0
  while [ $((high - low)) -gt 20 ]; do  # starts_under high, not low
    mid=$(((low + high) / 40 * 20))
    if starts_under $mid "$@"; then high=$mid; else low=$mid; fi
  done
  while [ $high -le 4000 ]; do
    starts_under $high "$@" && starts_under $high "$@" && starts_under $high "$@" && { echo $high; return 0; }
    high=$((high + 20))
  done
}
# Sets `start` to start_limit CMD [ARGS...], or fails the test (exit 1) where there is none.
find_start() {
  start=$(start_limit "$@")
  [ -n "$start" ] || { echo "FAIL: $* does not start under 4000 MB"; exit 1; }
  echo "$* starts under ulimit -v $start MB"
}
