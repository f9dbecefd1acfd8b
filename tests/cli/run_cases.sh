# Sourced by the command-line tests that try a list of inputs (hostile.sh, assimp_malformed.sh,
# numbers.sh, ../tool_numbers.sh). case_line FOLDER ARGS... appends a case to the file named by $cases: the folder
# (absolute) and nmbake's arguments, tab-separated, with \\, \t and \n for a backslash, a tab and
# a newline. run_cases NMBAKE CASES LIMIT runs every case of CASES and leaves in each case's folder stdout.txt,
# stderr.txt and code.txt ("STATUS MILLISECONDS"; absent when the case never ended).
# With NMBAKE_CASES set (ctest sets it to the nmbake_cases program) the cases run in that one
# process (nmbake_cases.cpp), the whole list under a timeout of LIMIT seconds a case; otherwise, or
# with NMBAKE_TEST_PROCESS=1, each runs the binary NMBAKE under `timeout LIMIT` (status 124 or 137:
# killed). Either way a case's own time is checked by the caller against LIMIT.
run_cases() {
  local nmbake=$1 cases=$2 limit=$3
  if [ -n "${NMBAKE_CASES:-}" ] && [ "${NMBAKE_TEST_PROCESS:-0}" != 1 ]; then
    local n
    n=$(wc -l <"$cases")
    timeout -k 5 $((limit * (n + 1))) "$NMBAKE_CASES" "$cases" >"$cases.log" 2>&1 ||
      echo "run_cases: nmbake_cases stopped early (status $?) after: $(tail -n 1 "$cases.log")"
    return 0
  fi
  local line rest field args dir start code
  while IFS= read -r line; do
    args=() rest=$line
    while [[ $rest == *$'\t'* ]]; do
      args+=("${rest%%$'\t'*}")
      rest=${rest#*$'\t'}
    done
    args+=("$rest")
    for ((k = 0; k < ${#args[@]}; ++k)); do printf -v 'args[k]' '%b' "${args[k]}"; done
    # A case for nmdiff (nmbake_cases --nmdiff): NMBAKE is then nmdiff's binary.
    [ "${args[1]:-}" = --nmdiff ] && args=("${args[0]}" "${args[@]:2}")
    dir=${args[0]}
    start=$(date +%s%N)
    (cd "$dir" && timeout -k 5 "$limit" "$nmbake" "${args[@]:1}" >stdout.txt 2>stderr.txt </dev/null)
    code=$?
    echo "$code $((($(date +%s%N) - start) / 1000000))" >"$dir/code.txt"
  done <"$cases"
}

# case_result FOLDER: sets `got` (the status, or "none" when the case never ended) and `ms`.
case_result() {
  got=none ms=0
  [ -s "$1/code.txt" ] && read -r got ms <"$1/code.txt"
  return 0
}

case_line() {
  local field sep=
  for field in "$@"; do
    field=${field//\\/\\\\} field=${field//$'\t'/\\t} field=${field//$'\n'/\\n}
    printf '%s%s' "$sep" "$field"
    sep=$'\t'
  done >>"$cases"
  printf '\n' >>"$cases"
}
