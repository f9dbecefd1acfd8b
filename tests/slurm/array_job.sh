#!/usr/bin/env bash
# The Slurm array job of docs/usage.md ("Batches on a farm") on a real single-node Slurm (issue 37,
# item 3): munged, slurmctld and slurmd started here in a temporary folder (their own slurm.conf
# through SLURM_CONF, munge key and socket, free ports, no cgroups, no accounting) and stopped at the
# end whatever happens. A 6-job batch (three jobs share the sample torus's high-poly, two a
# generated relief) baked by `sbatch -a 0-2 -W` as three `--shard I/3` tasks and merged with
# --merge-reports gives the maps of one process baking the whole file byte for byte (cmp) and its
# summary (every count; not the seconds) and its jobs' exit codes, errors and outputs.
# Exit 77 (skipped) when Slurm or munge is not installed (tests/packages.txt installs them) or not
# run as root; the daemons failing to start is a failure, with their logs printed. Every wait is
# bounded; the whole takes 6-10 s (sbatch -W polls every 2 s), 1.5 s of it CPU.
#   array_job.sh NMBAKE REPO WORK
set -euo pipefail
# Absolute: the batch runs in the jobs' folders and reads paths relative to them.
nmbake=$(realpath "$1") repo=$(realpath "$2") work=$(realpath -m "$3")
for tool in sbatch squeue sinfo scancel scontrol slurmctld slurmd munged mungekey; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool is not installed (Debian: slurmctld slurmd slurm-client munge; tests/packages.txt)"
    exit 77
  fi
done
if [ "$(id -u)" != 0 ]; then
  echo "SKIP: the test's Slurm runs as root (SlurmUser=root): run it as root"
  exit 77
fi
fail() {
  echo "FAIL: $*"
  exit 1
}

rm -rf "$work"
mkdir -p "$work/meshes" "$work/one" "$work/farm"
# The daemons' folder: short (munge's socket path has a limit of ~100 bytes), readable by all
# (munged refuses a socket in a folder others cannot enter).
daemons=$(mktemp -d "${TMPDIR:-/tmp}/nmbake-slurm.XXXXXX")
chmod 755 "$daemons"
pids=()
job_name=nmbake-shards submitted=0 waiter=
stop_all() {
  local code=$?
  set +e
  # sbatch -W still waiting (a signal), then the array's tasks still queued or running.
  [ -n "$waiter" ] && kill "$waiter" 2>/dev/null && wait "$waiter" 2>/dev/null
  if [ "$submitted" = 1 ]; then
    timeout 10 scancel -n "$job_name" 2>/dev/null
    for _ in $(seq 50); do
      [ -z "$(timeout 5 squeue -h -n "$job_name" 2>/dev/null)" ] && break
      sleep 0.2
    done
  fi
  # The daemons, the last started first: SIGTERM, then SIGKILL after 5 s.
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    kill "${pids[i]}" 2>/dev/null
  done
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    for _ in $(seq 50); do
      kill -0 "${pids[i]}" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "${pids[i]}" 2>/dev/null
    wait "${pids[i]}" 2>/dev/null
  done
  # Their logs kept beside the test's files, the folder removed.
  mkdir -p "$work/logs" && cp "$daemons"/*.log "$daemons"/*.err "$daemons/slurm.conf" "$work/logs/" 2>/dev/null
  rm -rf "$daemons"
  exit "$code"
}
trap stop_all EXIT
trap 'exit 143' TERM INT HUP
show_logs() {
  # A daemon's log, or what it printed before it could open it (stderr: -D and -F print there).
  for log in "$daemons"/*.log "$daemons"/*.err; do
    [ -s "$log" ] || continue
    echo "--- $(basename "$log")"
    tail -n 40 "$log"
  done
}

# The meshes: the sample torus (data/sample), and a square low-poly with two reliefs over it.
torus_low=$repo/data/sample/torus_low.obj torus_high=$repo/data/sample/torus_high.ply
[ -r "$torus_low" ] && [ -r "$torus_high" ] || fail "the sample torus is missing in $repo/data/sample"
cat >"$work/meshes/square_low.obj" <<'OBJ'
v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
OBJ
relief() {  # AMPLITUDE FREQUENCY: a 33 x 33 grid over the square, z = A sin(F x) cos(F y)
  awk -v a="$1" -v f="$2" 'BEGIN {
    n = 32
    for (j = 0; j <= n; j++) for (i = 0; i <= n; i++) {
      x = -1 + 2 * i / n; y = -1 + 2 * j / n
      printf "v %.6f %.6f %.6f\n", x, y, a * sin(f * x) * cos(f * y)
    }
    for (j = 0; j < n; j++) for (i = 0; i < n; i++) {
      k = j * (n + 1) + i + 1
      printf "f %d %d %d\nf %d %d %d\n", k, k + 1, k + n + 2, k, k + n + 2, k + n + 1
    }
  }'
}
relief 0.05 6 >"$work/meshes/relief_a.obj"
relief 0.08 3 >"$work/meshes/relief_b.obj"
# Six jobs, three groups of a high-poly: the torus (jobs 1, 3, 5), relief A (2, 6), relief B (4).
cat >"$work/jobs.json" <<JSON
{"defaults": {"size": 64, "padding": 2},
 "jobs": [{"low": "$torus_low", "highs": ["$torus_high"], "output": "out/torus.png"},
          {"low": "../meshes/square_low.obj", "highs": ["../meshes/relief_a.obj"], "output": "out/a.png"},
          {"low": "$torus_low", "highs": ["$torus_high"], "output": "out/torus_dx.tga", "options": {"green": "down"}},
          {"low": "../meshes/square_low.obj", "highs": ["../meshes/relief_b.obj"], "output": "out/b.png", "options": {"size": 128}},
          {"low": "$torus_low", "highs": ["$torus_high"], "output": "out/torus_<MAP>.png", "options": {"maps": "normal,ao", "ao-rays": 8}},
          {"low": "../meshes/square_low.obj", "highs": ["../meshes/relief_a.obj"], "output": "out/a4.png", "options": {"samples": 4}}]}
JSON
maps="torus.png a.png torus_dx.tga b.png torus_normal.png torus_ao.png a4.png"
for where in one farm; do
  mkdir -p "$work/$where/out"
  cp "$work/jobs.json" "$work/$where/jobs.json"
done

# One process, the whole file.
(cd "$work/one" && "$nmbake" --batch jobs.json --report batch.json --quiet) ||
  fail "the one-process batch failed (exit $?)"

# Two free TCP ports (nothing answers on them), from a range apart from the usual services'.
free_port() {
  local port
  for _ in $(seq 100); do
    port=$((20000 + RANDOM % 30000))
    [ "$port" != "${1:-}" ] || continue
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
      echo "$port"
      return
    fi
  done
  return 1
}
ctld_port=$(free_port) && slurmd_port=$(free_port "$ctld_port") || fail "no free TCP port found"
host=$(hostname -s)

# munge: its own key, socket, pid, seed and log.
mungekey --create --keyfile="$daemons/munge.key" >/dev/null
munged -F --socket="$daemons/munge.socket" --key-file="$daemons/munge.key" --pid-file="$daemons/munged.pid" \
  --seed-file="$daemons/munged.seed" --log-file="$daemons/munged.log" >"$daemons/munged.err" 2>&1 &
pids+=($!)

# Slurm: one node (this host), one partition, root runs everything; no cgroups (proctrack/linuxproc,
# task/none), no accounting. Quick: MinJobAge=4 makes sbatch -W poll every 2 s (it waits 2 s, 8 s,
# 32 s while a finished job's record outlives half the wait), batch_sched_delay=0 starts the tasks
# at once (default: up to 3 s later). CPUs=3 (config_overrides: whatever the host has) so that the three
# tasks may run at once.
export SLURM_CONF=$daemons/slurm.conf
cat >"$SLURM_CONF" <<CONF
ClusterName=nmbake-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$daemons/munge.socket
StateSaveLocation=$daemons/state
SlurmdSpoolDir=$daemons/spool
SlurmctldPidFile=$daemons/slurmctld.pid
SlurmdPidFile=$daemons/slurmd.pid
SlurmctldLogFile=$daemons/slurmctld.log
SlurmdLogFile=$daemons/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=4
SchedulerParameters=batch_sched_delay=0
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=3 State=UNKNOWN
PartitionName=nmbake Nodes=$host Default=YES MaxTime=10 State=UP
CONF
mkdir -p "$daemons/state" "$daemons/spool"

# Waits up to $1 seconds for the command after it to succeed, while the last daemon started runs.
wait_for() {
  local seconds=$1
  shift
  local end=$((SECONDS + seconds))
  until "$@"; do
    [ "$SECONDS" -lt "$end" ] && kill -0 "${pids[-1]}" 2>/dev/null || return 1
    sleep 0.2
  done
}
wait_for 10 test -S "$daemons/munge.socket" || { show_logs; fail "munged did not start"; }
slurmctld -D -f "$SLURM_CONF" >"$daemons/slurmctld.err" 2>&1 &
pids+=($!)
ctld_up() { timeout 5 scontrol ping 2>/dev/null | grep -q 'is UP'; }
wait_for 20 ctld_up || { show_logs; fail "slurmctld did not start"; }
slurmd -D -N "$host" -f "$SLURM_CONF" >"$daemons/slurmd.err" 2>&1 &
pids+=($!)
node_idle() { [ "$(timeout 5 sinfo -h -n "$host" -o %t 2>/dev/null)" = idle ]; }
wait_for 30 node_idle || { show_logs; timeout 5 sinfo -N -l; fail "the node did not come up idle"; }
echo "slurm: slurmctld on port $ctld_port, slurmd on $slurmd_port, node $host idle after ${SECONDS}s"

# The array job of docs/usage.md: three tasks, each its part of the jobs and its part's report.
cat >"$work/farm/bake.sbatch" <<SBATCH
#!/bin/bash
#SBATCH -a 0-2 -c 1
"$nmbake" --batch jobs.json --shard \$SLURM_ARRAY_TASK_ID/3 --report part\$SLURM_ARRAY_TASK_ID.json
SBATCH
start=$SECONDS
code=0 submitted=1
# In the background and waited for, so that a signal to this script stops it at once (the trap).
(cd "$work/farm" && exec timeout 120 sbatch -W -J "$job_name" -o 'task%a.out' bake.sbatch) >"$work/sbatch.out" 2>&1 &
waiter=$!
wait "$waiter" || code=$?
waiter=
cat "$work/sbatch.out"
if [ "$code" != 0 ]; then
  for out in "$work"/farm/task*.out; do
    [ -f "$out" ] && { echo "--- $(basename "$out")"; cat "$out"; }
  done
  show_logs
  [ "$code" = 124 ] && fail "the array job did not finish in 120 s"
  fail "sbatch -W exited $code"
fi
echo "slurm: the array job ran in $((SECONDS - start))s"
# Each task its part, a group of a high-poly whole in it (the costliest first, by texels): part 0
# relief B's job 4 (128 x 128), part 1 the torus's jobs 1, 3 and 5, part 2 relief A's jobs 2 and 6.
part_jobs=(1 3 2)
for i in 0 1 2; do
  [ -s "$work/farm/part$i.json" ] || fail "task $i wrote no part$i.json: $(cat "$work/farm/task$i.out" 2>/dev/null)"
  grep -q "batch jobs.json part $i/3: ${part_jobs[i]} jobs, ${part_jobs[i]} baked, 0 failed" "$work/farm/task$i.out" ||
    fail "task $i did not bake the ${part_jobs[i]} jobs of part $i/3: $(cat "$work/farm/task$i.out")"
done
(cd "$work/farm" && "$nmbake" --merge-reports part*.json -o batch.json) || fail "the merge failed (exit $?)"

# The maps, byte for byte, and no other file.
for map in $maps; do
  [ -s "$work/one/out/$map" ] || fail "one process wrote no $map"
  cmp "$work/one/out/$map" "$work/farm/out/$map" || fail "$map differs between one process and the array job"
done
one_files=$(ls "$work/one/out" | tr '\n' ' ') farm_files=$(ls "$work/farm/out" | tr '\n' ' ')
[ "$one_files" = "$farm_files" ] || fail "other files: one process wrote $one_files, the array job $farm_files"
# The summary's counts (its seconds are the time's) and each job's number, exit code, error and
# output: the reports are printed a key a line, sorted, so these are lines at known depths.
report_facts() {
  awk '/^  "summary": \{/ { s = 1; next } s && /^  \}/ { s = 0 } s && !/"seconds"/ { print "summary" $0 }
       /^      "(job|exit_code|error|output)": / { print "job" $0 }' "$1"
}
one=$(report_facts "$work/one/batch.json") farm=$(report_facts "$work/farm/batch.json")
# Here-strings, not `echo | grep -q`: under pipefail, grep leaving at its match could end echo by
# SIGPIPE before the lines after it, and the check failed on a report that held the line.
grep -q '"jobs": 6' <<<"$one" || fail "the one-process report has not 6 jobs: $one"
grep -q '"high_loads_saved": 3' <<<"$one" || fail "the one-process report has not 3 loads saved: $one"
[ "$one" = "$farm" ] || fail "the merged report differs from one process's: $(diff <(echo "$one") <(echo "$farm"))"
echo "PASS: 3 Slurm array tasks bake the 6 jobs as one process does (maps byte for byte, the merged summary)"
