#!/usr/bin/env bash
# A single-node Slurm on this machine, for the tests: munged, slurmctld and slurmd from Debian's
# munge and slurm-wlm, this host as controller and node (all its CPUs, one partition), state in
# a folder of its own. Needs root.
#
#   tests/slurm/local_slurm.sh start DIR   # writes DIR/slurm.conf, starts the daemons, waits for the node
#   tests/slurm/local_slurm.sh stop DIR    # stops the daemons it started, by the pids they wrote
#
# Slurm's commands find the configuration through SLURM_CONF=DIR/slurm.conf (printed by start).
# The daemons run as root (SlurmUser=root), so that DIR may be private to root.
set -euo pipefail
action=${1:?start or stop}
dir=$(realpath -m "${2:?a state folder}")

stop() {
    for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munged.pid"; do
        [[ -s $pidfile ]] || continue
        pid=$(cat "$pidfile")
        kill "$pid" 2> /dev/null || true
        for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2> /dev/null || true
        rm -f "$pidfile"
    done
}

if [[ $action == stop ]]; then
    stop
    exit 0
fi
[[ $action == start ]] || { echo "local_slurm.sh: start or stop, not '$action'" >&2; exit 2; }
[[ $(id -u) -eq 0 ]] || { echo "local_slurm.sh: starting Slurm's daemons needs root" >&2; exit 2; }
for program in munged slurmctld slurmd sbatch squeue sinfo; do
    command -v "$program" > /dev/null || { echo "local_slurm.sh: $program is missing (apt-get install slurm-wlm munge)" >&2; exit 2; }
done
mkdir -p "$dir"/{state,spool}
host=$(hostname -s)
cpus=$(nproc)

# munge runs as its own user, which may not enter the state folder (a test's temporary folder
# is private to root): its socket and pid file live in /run/munge.
mkdir -p /run/munge /var/log/munge /etc/munge
chown munge: /run/munge /var/log/munge
if [[ ! -s /etc/munge/munge.key ]]; then
    dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2> /dev/null
    chown munge: /etc/munge/munge.key
    chmod 400 /etc/munge/munge.key
fi
socket=/run/munge/munge.socket.2
if ! [[ -S $socket ]] || ! munge -n > /dev/null 2>&1; then
    su -s /bin/sh munge -c "munged --pid-file=/run/munge/zcheck-test-munged.pid --socket=$socket --force"
    cp /run/munge/zcheck-test-munged.pid "$dir/munged.pid"
fi

cat > "$dir/slurm.conf" <<EOF
ClusterName=zcheck-test
SlurmctldHost=$host
SlurmUser=root
SlurmctldPort=6917
SlurmdPort=6918
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$dir/slurm.conf
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 100); do
    if sinfo -h -o %T 2> /dev/null | grep -qx idle; then
        echo "SLURM_CONF=$SLURM_CONF"
        exit 0
    fi
    sleep 0.2
done
echo "local_slurm.sh: the node did not become idle in 20 s; see $dir/slurmctld.log and $dir/slurmd.log" >&2
sinfo >&2 || true
stop
exit 1
