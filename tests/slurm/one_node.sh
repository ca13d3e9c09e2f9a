#!/usr/bin/env bash
# A one-node Slurm cluster in a folder of its own, for tests and for trying `rths sweep --executor
# slurm` on one machine (docs/cluster.md): Debian's munged, slurmctld and slurmd, run as root, with
# every state, spool, log and pid file and a munge key made here, under DIR; no cgroups.
#
#   tests/slurm/one_node.sh start DIR   # prints `export SLURM_CONF=DIR/slurm.conf`; exit 0 once sinfo sees the node idle
#   tests/slurm/one_node.sh stop DIR    # stops the three daemons started for DIR
#
# Needs: slurmctld slurmd slurm-client munge (Debian packages), root (slurmd starts jobs as their user).
set -euo pipefail
cmd=${1:-}; dir=${2:-}
[[ ( $cmd == start || $cmd == stop ) && -n $dir ]] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }
mkdir -p "$dir"; dir=$(cd "$dir" && pwd)

stop() {
  for p in slurmd slurmctld munged; do
    [[ -f $dir/$p.pid ]] || continue
    pid=$(cat "$dir/$p.pid" 2>/dev/null || true)
    [[ -n $pid ]] && kill "$pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
    rm -f "$dir/$p.pid"
  done
}
if [[ $cmd == stop ]]; then stop; exit 0; fi

for tool in munged mungekey slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null || PATH=$PATH:/usr/sbin command -v "$tool" >/dev/null || {
    echo "one_node.sh: $tool not found (apt-get install slurmctld slurmd slurm-client munge)" >&2; exit 3; }
done
export PATH=$PATH:/usr/sbin
[[ $(id -u) -eq 0 ]] || { echo "one_node.sh: needs root (slurmd runs jobs as their owner)" >&2; exit 3; }

# Two free TCP ports for slurmctld and slurmd.
read -r ctld_port d_port < <(python3 - <<'PY'
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])
PY
)
host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/munge"
chmod 700 "$dir/munge"
rm -f "$dir/munge/munge.key"
mungekey --create --keyfile="$dir/munge/munge.key" --bits=1024 2>/dev/null || \
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=128 count=1 status=none
chmod 400 "$dir/munge/munge.key"
munged --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
  --pid-file="$dir/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed" --force

cat > "$dir/slurm.conf" <<CONF
# One-node Slurm made by tests/slurm/one_node.sh for $dir
ClusterName=rthstest
SlurmctldHost=$host
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
SchedulerParameters=sched_interval=1
MessageTimeout=10
InactiveLimit=0
KillWait=5
MinJobAge=300
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$dir/slurm.conf
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 150); do
  if sinfo -h -o '%t' 2>/dev/null | grep -qx idle; then echo "export SLURM_CONF=$SLURM_CONF"; exit 0; fi
  sleep 0.2
done
echo "one_node.sh: the node did not become idle in 30 s; logs in $dir/log" >&2
sinfo >&2 || true; tail -5 "$dir/log/"*.log >&2 || true
stop; exit 1
