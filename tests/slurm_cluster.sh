# A real one-node Slurm cluster (munged, slurmctld, slurmd from Debian) in a folder, for the
# study tests and measurements (not a test itself): source it, then
#   slurm_start     makes $slurm_dir (a new folder in /tmp the munge user can reach), writes
#                   its slurm.conf, starts the three daemons and waits for the node
#   slurm_stop      stops them by the pids in their pid files and removes $slurm_dir
# Exports SLURM_CONF. Needs root (munged runs as munge, the daemons as root) and the packages
# slurm-wlm and munge (scripts/setup.sh installs them). Facts: ../shared/SCALE.md.
slurm_start() {
  local dir cpus mem
  slurm_dir=$(mktemp -d /tmp/vfslurm-XXXXXX) && chmod 755 "$slurm_dir" || return 1
  dir=$slurm_dir
  mkdir -p "$dir/state" "$dir/spool" "$dir/munge" /run/munge
  chown munge:munge /run/munge "$dir/munge"
  cpus=$(nproc)
  mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))
  cat >"$dir/slurm.conf" <<CONF
ClusterName=vftest
SlurmctldHost=localhost
SlurmUser=root
AuthType=auth/munge
MailProg=/bin/true
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
SlurmctldPort=16817
SlurmdPort=16818
NodeName=localhost CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"
  runuser -u munge -- /usr/sbin/munged --socket=/run/munge/munge.socket.2 \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" || return 1
  /usr/sbin/slurmctld -f "$SLURM_CONF" || return 1
  /usr/sbin/slurmd -f "$SLURM_CONF" -N localhost || return 1
  for _ in $(seq 100); do
    [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && return 0
    sleep 0.2
  done
  echo "slurm: the node did not come up: $(tail -3 "$dir/slurmctld.log" "$dir/slurmd.log")" >&2
  return 1
}

slurm_stop() {
  local dir=$slurm_dir pidfile
  for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -s "$pidfile" ] && kill "$(cat "$pidfile")" 2>/dev/null
  done
  sleep 0.5
  rm -rf "$dir"
}
