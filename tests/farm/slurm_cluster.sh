#!/usr/bin/env bash
# Starts or stops a real one-node Slurm cluster (munged + slurmctld + slurmd) on localhost for tests.
#   slurm_cluster.sh start BASE_DIR   prints SLURM_CONF=...; writes BASE_DIR/env to source
#   slurm_cluster.sh stop BASE_DIR    safe to repeat, and after a failed start
# Everything lives under BASE_DIR, with its own ports, so several clusters can run at once. It needs
# no systemd, cgroups or slurmdbd (Slurm 22.05 on Debian 12, as root or as one user).
# Exits 77 (skip) when Slurm or munge is not installed, 1 when the cluster does not come up.
set -euo pipefail

if [ $# -ne 2 ] || { [ "$1" != start ] && [ "$1" != stop ]; }; then
  echo "usage: $0 start|stop BASE_DIR" >&2
  exit 2
fi
action=$1
# Daemons and key tools live in sbin, which a non-root PATH often lacks.
PATH=$PATH:/usr/sbin:/sbin

need=(munged mungekey munge unmunge slurmctld slurmd sinfo sbatch squeue scancel scontrol)
missing=()
for c in "${need[@]}"; do command -v "$c" >/dev/null || missing+=("$c"); done
if [ "$action" = start ] && [ ${#missing[@]} -gt 0 ]; then
  echo "slurm_cluster: not installed: ${missing[*]}" >&2
  exit 77
fi

[ "$action" = stop ] && [ ! -d "$2" ] && exit 0
mkdir -p "$2"
B=$(cd "$2" && pwd)  # slurm.conf and munged need absolute paths
# munged refuses a socket under a folder others cannot traverse (mkdtemp makes 0700 folders).
[ "$action" = start ] && chmod a+x "$B"
conf=$B/etc/slurm.conf
sock=$B/munge/munge.sock
export SLURM_CONF=$conf

# A recorded PID counts only while it is ours (its command line names BASE_DIR, so a reused PID is
# never signalled) and not a zombie (they linger for seconds under this PID 1, and kill -0 sees them).
alive() {
  local stat
  tr '\0' ' ' 2>/dev/null <"/proc/$1/cmdline" | grep -qF "$B" || return 1
  stat=$(cut -d' ' -f3 "/proc/$1/stat" 2>/dev/null) && [ "$stat" != Z ]
}

# The live recorded PIDs of the daemons named $1 (a regex).
recorded() {
  local name pid
  [ -f "$B/pids" ] || return 0
  while read -r name pid; do
    if [[ $name =~ $1 ]] && alive "$pid"; then echo "$pid"; fi
  done <"$B/pids"
}

# TERMs the recorded daemons named $1, waits up to 10 s for them to exit, then KILLs what is left.
term_daemons() {
  local pids i
  mapfile -t pids < <(recorded "$1")
  [ ${#pids[@]} -gt 0 ] || return 0
  kill -TERM "${pids[@]}" 2>/dev/null || true
  for ((i = 0; i < 100; i++)); do
    [ -n "$(recorded "$1")" ] || return 0
    sleep 0.1
  done
  kill -KILL "${pids[@]}" 2>/dev/null || true
}

stop() {
  # Cancel and shut down through slurmctld while it (and munged) still run, then make sure by PID;
  # munged goes last, as the others need it to talk. Wait for cancelled jobs to leave the queue:
  # a slurmd still completing one when slurmctld goes retries it for 9 s before exiting.
  local i
  if [ -n "$(recorded slurmctld)" ]; then
    timeout 10 squeue -h -o %A 2>/dev/null | xargs -r timeout 10 scancel 2>/dev/null || true
    for ((i = 0; i < 50; i++)); do
      [ -z "$(timeout 5 squeue -h -o %A 2>/dev/null)" ] && break
      sleep 0.1
    done
    timeout 10 scontrol shutdown >/dev/null 2>&1 || true
  fi
  term_daemons 'slurm'
  term_daemons 'munged'
  rm -f "$B/pids" "$B/env"
}

fail() {
  local f
  trap - ERR
  echo "slurm_cluster: $1 (base $B)" >&2
  for f in "$B"/log/*; do
    [ -s "$f" ] && { echo "--- $f" >&2; tail -n 10 "$f" >&2; }
  done
  stop
  exit 1
}

# True when nothing listens on 127.0.0.1:$1 (the daemons bind all addresses, so this sees them).
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }

# Starts "$@" in the background, its own output in log/$1.out (so no caller's pipe is held open),
# and records its PID.
daemon() {
  "$@" </dev/null >>"$B/log/$1.out" 2>&1 &
  echo "$1 $!" >>"$B/pids"
}

# Polls "$@" every 0.1 s for up to $1 s; fails early when a recorded daemon has died.
wait_for() {
  local end=$((SECONDS + $1)) name pid
  shift
  until "$@"; do
    ((SECONDS < end)) || return 1
    while read -r name pid; do alive "$pid" || fail "$name (pid $pid) exited during start"; done <"$B/pids"
    sleep 0.1
  done
}

munge_ok() { munge -n -S "$sock" 2>/dev/null | unmunge -S "$sock" >/dev/null 2>&1; }
node_idle() { [ "$(timeout 5 sinfo -h -N -o %t 2>/dev/null)" = idle ]; }

if [ "$action" = stop ]; then
  stop
  exit 0
fi

stop  # a previous cluster in this BASE_DIR; its state is cleared below (slurmctld -c)
set -E
trap 'fail "unexpected error at line $LINENO"' ERR
[ ${#sock} -lt 108 ] || fail "BASE_DIR too long for a unix socket path"
rm -rf "$B/state" "$B/spool" "$B/run" "$B/log"
mkdir -p "$B/etc" "$B/munge" "$B/state" "$B/spool" "$B/run" "$B/log"
chmod 0755 "$B/munge"  # munged rejects a socket dir of 0700
[ -f "$B/munge/munge.key" ] || mungekey --create --keyfile="$B/munge/munge.key"
chmod 0600 "$B/munge/munge.key"

daemon munged --foreground --key-file="$B/munge/munge.key" --socket="$sock" \
  --pid-file="$B/run/munged.pid" --seed-file="$B/munge/munge.seed"  # foreground: logs to stderr only
wait_for 10 munge_ok || fail "munged not ready after 10 s"

# Ports: start at a point given by the BASE_DIR's hash (so concurrent clusters rarely even try the
# same ones), below the kernel's ephemeral range, and take the first free pair.
hash=$(printf %s "$B" | cksum | cut -d' ' -f1)
ctld_port=
for ((i = 0; i < 500; i++)); do
  p=$((20000 + (hash + i) % 5000 * 2))
  if port_free "$p" && port_free $((p + 1)); then ctld_port=$p; break; fi
done
[ -n "$ctld_port" ] || fail "no free port pair in 20000-29999"

# The node as slurmd finds it (CPUs, topology, RealMemory): it drains a node described bigger.
hw=$(slurmd -C | head -n 1)
hw=${hw#NodeName=* }
user=$(id -un)

# linuxproc/task none: no cgroups here (proctrack/cgroup drains the node). batch_sched_delay=0 and
# MinJobAge=4 make short jobs start promptly and `sbatch --wait` poll every 2 s. No slurmdbd, so
# finished jobs are read from the jobcomp file (or `scontrol show job` for MinJobAge seconds).
cat >"$conf" <<EOF
ClusterName=narvaltest
SlurmctldHost=localhost
SlurmctldPort=$ctld_port
SlurmdPort=$((ctld_port + 1))
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
AuthInfo=socket=$sock
CredType=cred/munge
MpiDefault=none
MailProg=/bin/true
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$B/log/jobcomp.txt
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=batch_sched_delay=0
MinJobAge=4
ReturnToService=2
StateSaveLocation=$B/state
SlurmdSpoolDir=$B/spool
SlurmctldPidFile=$B/run/slurmctld.pid
SlurmdPidFile=$B/run/slurmd.pid
SlurmctldLogFile=$B/log/slurmctld.log
SlurmdLogFile=$B/log/slurmd.log
NodeName=localhost NodeAddr=127.0.0.1 $hw State=UNKNOWN
PartitionName=main Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF

daemon slurmctld -D -c -f "$conf"
daemon slurmd -D -N localhost -f "$conf"
wait_for 60 node_idle || fail "node not idle after 60 s"
trap - ERR

echo "export SLURM_CONF=$conf" >"$B/env"
echo "SLURM_CONF=$conf"
