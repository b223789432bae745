#!/usr/bin/env bash
# A one-node Slurm cluster on localhost, from Debian's slurm-wlm and munge, for the sweep's
# Slurm test: every file (munge key and socket, slurm.conf, spool, state, logs) lives in one
# temporary folder, on ports free at the start, so nothing on the machine is touched and two of
# them can run at once.
#   slurm_localhost.sh start DIR   starts munged, slurmctld and slurmd in DIR (made if missing),
#                                  waits until the node is idle; prints the SLURM_CONF to use;
#                                  exit 77 (and why on stderr) where Slurm cannot start
#   slurm_localhost.sh stop DIR    stops the three daemons it started in DIR
set -uo pipefail
cmd=${1:-}; dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }

# The pid in DIR/NAME.pid if that process is still NAME (a pid file left by a run that was
# killed outright may name another process by now).
daemon_pid() {
  local pid
  pid=$(cat "$dir/$1.pid" 2>/dev/null) || return 1
  tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null | grep -q "$1" && echo "$pid"
}

stop() {
  local f pid
  for f in slurmd slurmctld munged; do
    pid=$(daemon_pid $f) && kill "$pid" 2>/dev/null
  done
  for f in slurmd slurmctld munged; do   # each gone within 5 s, or killed
    if pid=$(daemon_pid $f); then
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -9 "$pid" 2>/dev/null
    fi
    rm -f "$dir/$f.pid"
  done
  return 0
}
skip() { echo "slurm_localhost: Slurm cannot start here: $1" >&2; [ -f "$dir/$2" ] && tail -n 20 "$dir/$2" >&2; stop; exit 77; }

if [ "$cmd" = stop ]; then stop; exit 0; fi
[ "$cmd" = start ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }
for p in munged slurmctld slurmd sbatch sinfo; do
  command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] || skip "no $p (Debian packages munge, slurm-wlm)" none
done
[ "$(id -u)" -eq 0 ] || skip "the daemons run as root here, and this is uid $(id -u)" none
mkdir -p "$dir"/{spool,state,munge} && chmod 700 "$dir/munge"
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
ctld_port=$(free_port); d_port=$(free_port)
host=$(hostname -s)
# The node offers 32 CPUs whatever the machine has (config_overrides lets slurmd accept that),
# so that a test's array tasks, each one short run, start in one wave instead of one wave of
# nproc tasks per scheduling pass (a second each).
cpus=32
memory=$(awk '/MemTotal/ { print int($2 / 1024 / 2) }' /proc/meminfo)   # MB: half, so slurmd agrees

# munge: its own key and socket (a credential made with this key is valid only here).
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none && chmod 400 "$dir/munge/munge.key"
/usr/sbin/munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/socket" \
  --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munge/seed" \
  || skip "munged did not start" munged.log

cat >"$dir/slurm.conf" <<CONF
# A one-node cluster on localhost (tests/sweep/slurm_localhost.sh).
ClusterName=graspsim-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"
/usr/sbin/slurmctld -f "$SLURM_CONF" || skip "slurmctld did not start" slurmctld.log
/usr/sbin/slurmd -f "$SLURM_CONF" || skip "slurmd did not start" slurmd.log
for _ in $(seq 100); do   # up to 20 s for the node to register
  state=$(sinfo -h -N -o %t 2>/dev/null | head -n1)
  [ "$state" = idle ] && { echo "$SLURM_CONF"; exit 0; }
  sleep 0.2
done
skip "the node never became idle (sinfo: '${state:-nothing}')" slurmd.log
