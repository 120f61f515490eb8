# A throw-away single-node Slurm cluster for tests, to be sourced by bash.
#   slurm_cluster_scratch NAME
#                             sets $dir to a new temporary folder and stops the cluster and removes
#                             the folder when the script exits (EXIT, HUP, INT, TERM traps).
#   slurm_cluster_start DIR   generates a munge key, starts munged, slurmctld and slurmd with all
#                             their files under DIR (which must be an empty private directory, e.g.
#                             from mktemp -d), exports SLURM_CONF and waits until the node is idle.
#                             On failure it sets SLURM_CLUSTER_ERROR to the reason, prints the
#                             daemons' logs, stops what it started and returns 1.
#   slurm_cluster_stop        cancels the cluster's jobs, kills every daemon it started and every
#                             process holding files under DIR (slurmstepd, job steps) by pid, waits
#                             for them to exit and removes DIR.
#   slurm_cluster_logs        prints the daemons' logs.
#   slurm_cluster_wait_jobs SECONDS JOBID...
#                             waits until none of the jobs is pending, running or completing.
#   slurm_cluster_job_states JOBID
#                             prints the state of the job (one line per array task).
# After start, SLURM_CLUSTER_PIDS holds the daemons' pids and SLURM_CLUSTER_NODE the node name.

SLURM_CLUSTER_DIR=""
SLURM_CLUSTER_PIDS=""
SLURM_CLUSTER_NODE=""
SLURM_CLUSTER_ERROR=""

# Prints a TCP port in 20000-59999 that no socket uses (/proc/net/tcp*), with the next port free too.
slurm_cluster_free_port() {
  local port tries
  for tries in $(seq 1 200); do
    port=$((20000 + (RANDOM * 32768 + RANDOM) % 40000))
    if ! cat /proc/net/tcp /proc/net/tcp6 2>/dev/null | awk '{print $2}' |
      grep -Eiq "$(printf ':(%04X|%04X)$' "$port" $((port + 1)))"; then
      echo "$port"
      return 0
    fi
  done
  return 1
}

# Prints the pids of processes (other than this shell) whose cwd or open files are under DIR.
slurm_cluster_holders() {
  local dir="$1" p pid link
  for p in /proc/[0-9]*; do
    pid="${p#/proc/}"
    [ "$pid" = "$$" ] || [ "$pid" = "${BASHPID:-$$}" ] && continue
    for link in "$p/cwd" "$p"/fd/*; do
      case "$(readlink "$link" 2>/dev/null)" in
        "$dir" | "$dir"/*) echo "$pid"; break ;;
      esac
    done
  done
}

# Waits up to SECONDS for the pids to exit; returns 1 if one is still running.
slurm_cluster_wait_exit() {
  local seconds="$1" pid i alive
  shift
  for i in $(seq 1 $((seconds * 10))); do
    alive=0
    for pid in "$@"; do
      if kill -0 "$pid" 2>/dev/null; then alive=1; fi
    done
    [ "$alive" -eq 0 ] && return 0
    sleep 0.1
  done
  return 1
}

slurm_cluster_logs() {
  local name f
  [ -n "$SLURM_CLUSTER_DIR" ] || return 0
  for name in munged slurmctld slurmd; do
    # A daemon that failed before opening its log file wrote only to stderr (NAME.out).
    f="$SLURM_CLUSTER_DIR/$name.log"
    [ -s "$f" ] || f="$SLURM_CLUSTER_DIR/$name.out"
    if [ -s "$f" ]; then
      echo "---- $f (last 40 lines)"
      tail -n 40 "$f"
    fi
  done
}

slurm_cluster_fail() {
  SLURM_CLUSTER_ERROR="$1"
  slurm_cluster_logs
  slurm_cluster_stop
  return 1
}

slurm_cluster_scratch() {
  dir="$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX")" || return 1
  trap 'slurm_cluster_stop; rm -rf "$dir"' EXIT
  # A signal ends the script through exit, which runs the EXIT trap.
  trap 'exit 1' HUP INT TERM
}

slurm_cluster_start() {
  local dir="$1" tool port node cpus mem i state
  if [ "$(id -u)" -ne 0 ]; then
    SLURM_CLUSTER_ERROR="a throw-away Slurm cluster needs root (slurmd runs jobs as their user)"
    return 1
  fi
  for tool in munged slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
    if ! command -v "$tool" >/dev/null; then
      SLURM_CLUSTER_ERROR="$tool is not installed (scripts/install-deps.sh installs slurm-wlm and munge)"
      return 1
    fi
  done
  SLURM_CLUSTER_DIR="$(cd "$dir" && pwd -P)" || { SLURM_CLUSTER_ERROR="no directory $dir"; return 1; }
  dir="$SLURM_CLUSTER_DIR"
  SLURM_CLUSTER_PIDS=""
  mkdir -p "$dir/state" "$dir/spool" "$dir/jobs"
  # munged needs the socket's directory to be searchable by everyone.
  chmod 0711 "$dir"

  dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 status=none
  chmod 0400 "$dir/munge.key"
  chown "$(id -u):$(id -g)" "$dir/munge.key"
  munged --foreground --socket="$dir/munge.socket" --key-file="$dir/munge.key" \
    --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munged.seed" \
    </dev/null >"$dir/munged.out" 2>&1 &
  SLURM_CLUSTER_PIDS="$!"
  for i in $(seq 1 100); do
    [ -S "$dir/munge.socket" ] && break
    kill -0 "$SLURM_CLUSTER_PIDS" 2>/dev/null || break
    sleep 0.1
  done
  [ -S "$dir/munge.socket" ] || { slurm_cluster_fail "munged did not start"; return 1; }

  node="$(hostname -s)"
  SLURM_CLUSTER_NODE="$node"
  port="$(slurm_cluster_free_port)" || { slurm_cluster_fail "found no free TCP port"; return 1; }
  cpus="$(nproc)"
  mem=$(($(awk '/^MemTotal:/ {print $2}' /proc/meminfo) / 1024 * 9 / 10))
  cat >"$dir/slurm.conf" <<EOF
ClusterName=penumbra-test
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.socket
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
ReturnToService=2
SlurmdParameters=config_overrides
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
MinJobAge=600
KillWait=5
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF="$dir/slurm.conf"

  slurmctld -D -i -f "$dir/slurm.conf" </dev/null >"$dir/slurmctld.out" 2>&1 &
  SLURM_CLUSTER_PIDS="$SLURM_CLUSTER_PIDS $!"
  slurmd -D -f "$dir/slurm.conf" </dev/null >"$dir/slurmd.out" 2>&1 &
  SLURM_CLUSTER_PIDS="$SLURM_CLUSTER_PIDS $!"

  for i in $(seq 1 300); do
    for tool in $SLURM_CLUSTER_PIDS; do
      kill -0 "$tool" 2>/dev/null || { slurm_cluster_fail "a Slurm daemon (pid $tool) exited"; return 1; }
    done
    state="$(sinfo -h -n "$node" -o %t 2>/dev/null)"
    [ "$state" = "idle" ] && return 0
    sleep 0.1
  done
  slurm_cluster_fail "node $node is not idle after 30 s (state '${state:-unknown}')"
  return 1
}

slurm_cluster_stop() {
  local dir="$SLURM_CLUSTER_DIR" pid holders
  [ -n "$dir" ] || return 0
  if [ -n "${SLURM_CONF:-}" ] && [ -S "$dir/munge.socket" ]; then
    timeout 10 scancel --quiet --user="$(id -un)" 2>/dev/null
  fi
  for pid in $SLURM_CLUSTER_PIDS; do kill -TERM "$pid" 2>/dev/null; done
  holders="$(slurm_cluster_holders "$dir")"
  for pid in $holders; do kill -TERM "$pid" 2>/dev/null; done
  if ! slurm_cluster_wait_exit 2 $SLURM_CLUSTER_PIDS $holders; then
    for pid in $SLURM_CLUSTER_PIDS $holders; do kill -KILL "$pid" 2>/dev/null; done
    slurm_cluster_wait_exit 5 $SLURM_CLUSTER_PIDS $holders
  fi
  holders="$(slurm_cluster_holders "$dir")"
  for pid in $holders; do kill -KILL "$pid" 2>/dev/null; done
  [ -z "$holders" ] || slurm_cluster_wait_exit 5 $holders
  # Reaps the daemons started by this shell.
  for pid in $SLURM_CLUSTER_PIDS; do wait "$pid" 2>/dev/null; done
  rm -rf "$dir"
  unset SLURM_CONF
  SLURM_CLUSTER_DIR=""
}

slurm_cluster_wait_jobs() {
  local seconds="$1" i ids out
  shift
  ids="$(IFS=,; echo "$*")"
  for i in $(seq 1 $((seconds * 5))); do
    out="$(squeue -h -j "$ids" -t PD,CF,R,CG,S -o %i 2>/dev/null)" && [ -z "$out" ] && return 0
    sleep 0.2
  done
  return 1
}

slurm_cluster_job_states() {
  scontrol -o show job "$1" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p'
}
