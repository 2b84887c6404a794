#!/usr/bin/env bash
# Throwaway one-node Slurm cluster on localhost, for automated tests.
#
#   local_cluster.sh start DIR   start munged, slurmctld and slurmd with all
#                                state in DIR; on success print
#                                "export SLURM_CONF=DIR/slurm.conf" on stdout
#   local_cluster.sh stop DIR    cancel all jobs and stop the daemons that
#                                "start DIR" launched (idempotent)
#
# Only processes proven to belong to DIR are ever signalled: daemons from
# DIR's pid files whose command line names DIR, and slurmstepd processes
# holding DIR/slurmd.log open (plus their children). A real Slurm/MUNGE
# installation on the same machine is left alone. Everything except the
# export line goes to stderr.
#
# No accounting storage is configured, so sacct does not work on this cluster;
# use squeue / scontrol show job (finished jobs stay visible for MinJobAge s).
#
# Environment knobs (optional):
#   LOCAL_SLURM_PORT_BASE  first port tried for SlurmctldPort (default 16817;
#                          SlurmdPort is the next one)
#   LOCAL_SLURM_TIMEOUT    seconds to wait for the node to become idle (60)
set -euo pipefail

PROG=${0##*/}
PATH=$PATH:/usr/sbin:/sbin  # daemons live in sbin, often absent for non-root

msg() { echo "$PROG: $*" >&2; }
die() { msg "error: $*"; exit 1; }

usage() {
  echo "usage: $PROG start|stop DIR" >&2
  exit 2
}

# need CMD PACKAGE: exit 2 if CMD is missing.
need() {
  command -v "$1" >/dev/null 2>&1 ||
    { msg "error: required command '$1' not found (Debian package: $2)"; exit 2; }
}

# ---------------------------------------------------------------- processes

# These helpers use bash builtins only: forks are slow on some VMs and the
# stop path polls /proc repeatedly.

# alive PID: true if PID exists and is not a zombie.
alive() {
  local line
  { read -r line <"/proc/$1/stat"; } 2>/dev/null || return 1
  line=${line##*) }  # skip "pid (comm) ", comm may contain spaces
  [[ -n $line && ${line%% *} != Z ]]
}

# ours PID: true if PID is alive and its command line names a file in DIR or
# it holds DIR's slurmd log open (slurmstepd); guards against pid reuse and
# against daemons of a real installation.
ours() {
  local pid=$1 f
  local -a argv=()
  alive "$pid" || return 1
  { mapfile -d '' -t argv <"/proc/$pid/cmdline"; } 2>/dev/null || true
  [[ " ${argv[*]-} " == *"$DIR/"* ]] && return 0
  for f in /proc/"$pid"/fd/*; do
    [[ $f -ef $DIR/slurmd.log ]] && return 0
  done
  return 1
}

# daemon_pid NAME: print the pid of our running NAME daemon, if any.
daemon_pid() {
  local file=$DIR/$1.pid pid
  [[ -r $file ]] || return 1
  read -r pid <"$file" || true
  [[ $pid =~ ^[0-9]+$ ]] && ours "$pid" && echo "$pid"
}

# terminate NAME PID: SIGTERM, wait up to 15 s, then SIGKILL.
terminate() {
  local name=$1 pid=$2 i
  kill -TERM "$pid" 2>/dev/null || true
  for ((i = 0; i < 150; i++)); do
    alive "$pid" || return 0
    sleep 0.1
  done
  msg "warning: $name (pid $pid) ignored SIGTERM for 15 s, sending SIGKILL"
  kill -KILL "$pid" 2>/dev/null || true
  for ((i = 0; i < 50; i++)); do
    alive "$pid" || return 0
    sleep 0.1
  done
  msg "error: $name (pid $pid) still alive after SIGKILL"
  return 1
}

# stepd_pids: slurmstepd processes of this cluster (they keep DIR/slurmd.log
# open), found via /proc, not by name alone.
stepd_pids() {
  local p arg0
  for p in /proc/[0-9]*; do
    arg0=  # builtins only: forking per process is slow on big machines
    { IFS= read -r -d '' arg0 <"$p/cmdline"; } 2>/dev/null || true
    [[ $arg0 == slurmstepd* ]] || continue
    p=${p#/proc/}
    ours "$p" && echo "$p"
  done
  return 0
}

# tree PID...: the PIDs and all their descendants (ppid field in /proc).
tree() {
  local line p pp out=" $* " grew=1
  local -a pairs=()
  for p in /proc/[0-9]*/stat; do
    { read -r line <"$p"; } 2>/dev/null || continue
    pp=${line##*) }  # skip "pid (comm) " even if comm has spaces
    pp=${pp#* }
    pairs+=("${line%% *} ${pp%% *}")
  done
  while ((grew)); do
    grew=0
    for line in "${pairs[@]}"; do
      p=${line% *} pp=${line#* }
      if [[ $out == *" $pp "* && $out != *" $p "* ]]; then
        out+="$p " grew=1
      fi
    done
  done
  echo "$out"
}

# kill_tree PID...: SIGTERM the PIDs and their descendants, SIGKILL them
# after 5 s.
kill_tree() {
  local pids p i left
  pids=$(tree "$@")
  # shellcheck disable=SC2086
  kill -TERM $pids 2>/dev/null || true
  for ((i = 0; i < 50; i++)); do
    left=
    for p in $pids; do alive "$p" && left+="$p "; done
    [[ -z $left ]] && return 0
    sleep 0.1
  done
  # shellcheck disable=SC2086
  kill -KILL $left 2>/dev/null || true
  sleep 0.5
  for p in $left; do
    alive "$p" && { msg "error: pid $p still alive after SIGKILL"; return 1; }
  done
  return 0
}

# ---------------------------------------------------------------- helpers

# port_busy PORT: true if something listens on TCP PORT.
port_busy() {
  if command -v ss >/dev/null 2>&1; then
    [[ -n $(ss -Hltn "sport = :$1" 2>/dev/null) ]]
  else  # fall back to /proc (state 0A = LISTEN)
    local hex
    hex=$(printf '%04X' "$1")
    cat /proc/net/tcp /proc/net/tcp6 2>/dev/null |
      awk -v h=":$hex" '$2 ~ h"$" && $4 == "0A" { f = 1 } END { exit !f }'
  fi
}

slurm() { SLURM_CONF=$DIR/slurm.conf timeout 20 "$@"; }

# dump_logs: last lines of every log in DIR, to stderr.
dump_logs() {
  local f
  for f in "$DIR"/munged.log "$DIR"/slurmctld.log "$DIR"/slurmd.log "$DIR"/*.stderr; do
    [[ -s $f ]] || continue
    echo "----- last lines of $f -----" >&2
    tail -n 25 "$f" >&2
  done
}

# ---------------------------------------------------------------- stop

do_stop() {
  local pid name ids i rc=0

  # Cancel every job while the controller is still up.
  if daemon_pid slurmctld >/dev/null; then
    ids=$(slurm squeue -h -o %F 2>/dev/null | sort -u) || ids=
    if [[ -n $ids ]]; then
      # shellcheck disable=SC2086
      slurm scancel $ids 2>/dev/null || msg "warning: scancel $ids failed"
      for ((i = 0; i < 200; i++)); do  # up to 20 s (KillWait is 5 s)
        [[ -z $(slurm squeue -h -o %i 2>/dev/null) ]] && break
        sleep 0.1
      done
    fi
    # Give the cancelled jobs' steps up to 10 s to clean up on their own.
    for ((i = 0; i < 50; i++)); do
      [[ -z $(stepd_pids) ]] && break
      sleep 0.2
    done
  fi

  for name in slurmd slurmctld; do
    if pid=$(daemon_pid "$name"); then
      terminate "$name" "$pid" || rc=1
    fi
  done

  # Job steps outlive slurmd by design; kill any left over from this cluster
  # (e.g. after a daemon crashed), together with the job's processes.
  pid=$(stepd_pids)
  if [[ -n $pid ]]; then
    msg "warning: killing leftover slurmstepd processes and their children: ${pid//$'\n'/ }"
    # shellcheck disable=SC2086
    kill_tree $pid || rc=1
  fi

  if pid=$(daemon_pid munged); then
    terminate munged "$pid" || rc=1
  fi
  rm -f "$DIR"/slurmd.pid "$DIR"/slurmctld.pid "$DIR"/munged.pid
  return "$rc"
}

# ---------------------------------------------------------------- start

write_conf() {
  local host=$1 ctld_port=$2 slurmd_port=$3 user node mem cpus
  user=$(id -un)
  cpus=$(nproc)

  # Reuse slurmd's own view of the hardware, with RealMemory 10% lower so the
  # node is never rejected for having less memory than configured.
  node=$(slurmd -C 2>"$DIR/slurmd-C.stderr" | grep -m1 '^NodeName=') ||
    die "'slurmd -C' did not print a NodeName line"
  mem=$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$node")
  mem=$(( ${mem:-1000} * 9 / 10 )); ((mem > 0)) || mem=1
  node=$(sed -e "s/^NodeName=[^ ]*/NodeName=$host NodeAddr=127.0.0.1/" \
             -e "s/RealMemory=[0-9]*/RealMemory=$mem/" <<<"$node")
  if [[ $node != *" CPUs=$cpus "* ]]; then
    # nproc disagrees with the hardware (e.g. a cpuset): trust nproc.
    msg "note: slurmd -C and nproc disagree; using CPUs=$cpus"
    node="NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem"
  fi

  : >"$DIR/plugstack.conf"  # keep the system's SPANK plugins out
  # No cgroup.conf: with proctrack/linuxproc and task/none no cgroup plugin is
  # loaded (other config files would be looked up next to slurm.conf anyway).
  rm -f "$DIR/cgroup.conf"

  cat >"$DIR/slurm.conf" <<EOF
# Generated by $PROG for a throwaway test cluster; do not edit.
ClusterName=gilabtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$user
SlurmdUser=$user
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/slurmctld.log
SlurmdLogFile=$DIR/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=$DIR/plugstack.conf
AuthType=auth/munge
AuthInfo=socket=$DIR/munge.sock
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
# No accounting: sacct is unavailable on this cluster.
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
KillWait=5
MailProg=/bin/true
$node State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
}

# wait_pidfile NAME: wait up to 10 s for NAME's pid file to name a live
# process of ours.
wait_pidfile() {
  local i
  for ((i = 0; i < 100; i++)); do
    daemon_pid "$1" >/dev/null && return 0
    sleep 0.1
  done
  die "$1 did not start (no live pid in $DIR/$1.pid)"
}

on_start_failure() {
  local rc=$?
  trap - EXIT
  ((rc == 0)) && rc=1
  dump_logs
  msg "start failed; stopping what was started in $DIR"
  do_stop || true
  exit "$rc"
}

do_start() {
  local host base port name pid state timeout i t0
  host=$(hostname -s) || die "'hostname -s' failed"
  timeout=${LOCAL_SLURM_TIMEOUT:-60}

  for name in munged slurmctld slurmd; do
    if pid=$(daemon_pid "$name"); then
      die "$name from an earlier start is still running in $DIR (pid $pid); run '$PROG stop $DIR' first"
    fi
  done
  t0=$SECONDS
  trap on_start_failure EXIT

  mkdir -p "$DIR/state" "$DIR/spool"
  rm -f "$DIR"/*.stderr

  # Two free adjacent ports for slurmctld and slurmd.
  base=${LOCAL_SLURM_PORT_BASE:-16817}
  port=
  for ((i = 0; i < 100; i++)); do
    if ! port_busy $((base + 2 * i)) && ! port_busy $((base + 2 * i + 1)); then
      port=$((base + 2 * i))
      break
    fi
  done
  [[ -n $port ]] || die "no two free TCP ports found from $base up"

  # MUNGE: private key, socket, pid, log and seed in DIR. --force lets it
  # start although DIR (e.g. from mktemp -d) is not searchable by others.
  if [[ ! -s $DIR/munge.key ]]; then
    mungekey --create --keyfile="$DIR/munge.key" 2>"$DIR/mungekey.stderr" ||
      die "mungekey could not create $DIR/munge.key"
  fi
  chmod 0400 "$DIR/munge.key"
  rm -f "$DIR/munge.sock" "$DIR/munge.sock.lock"
  munged --force --key-file="$DIR/munge.key" --socket="$DIR/munge.sock" \
    --pid-file="$DIR/munged.pid" --log-file="$DIR/munged.log" \
    --seed-file="$DIR/munged.seed" </dev/null >"$DIR/munged.stderr" 2>&1 ||
    die "munged failed to start (see $DIR/munged.log and munged.stderr)"
  wait_pidfile munged

  write_conf "$host" "$port" $((port + 1))

  # Both daemonize themselves and write their pid files; their output must not
  # reach our stdout, which callers typically capture with $(...).
  # slurmctld -c: start with an empty job queue even if DIR was used before
  # (a crashed run would otherwise have its jobs requeued).
  slurmctld -c -f "$DIR/slurm.conf" </dev/null >"$DIR/slurmctld.stderr" 2>&1 ||
    die "slurmctld -f $DIR/slurm.conf failed"
  wait_pidfile slurmctld
  slurmd -f "$DIR/slurm.conf" </dev/null >"$DIR/slurmd.stderr" 2>&1 ||
    die "slurmd -f $DIR/slurm.conf failed"
  wait_pidfile slurmd

  # Wait for the node to register and become idle.
  state=
  while ((SECONDS - t0 < timeout)); do
    for name in munged slurmctld slurmd; do
      daemon_pid "$name" >/dev/null || die "$name exited during start-up"
    done
    state=$(slurm sinfo -h -n "$host" -o %T 2>/dev/null) || state=
    [[ $state == idle ]] && break
    sleep 0.5
  done
  [[ $state == idle ]] ||
    die "node $host not idle after ${timeout} s (sinfo state: '${state:-none}')"

  trap - EXIT
  msg "cluster gilabtest up in $((SECONDS - t0)) s (ports $port/$((port + 1)), node $host, dir $DIR)"
  echo "export SLURM_CONF=$DIR/slurm.conf"
}

# ---------------------------------------------------------------- main

[[ $# -eq 2 ]] || usage
cmd=$1
[[ -n $2 ]] || usage
# slurm.conf cannot quote paths: reject such DIRs before creating anything.
bad_chars='*[[:space:],=\(\)]*'
# shellcheck disable=SC2053
[[ $2 != $bad_chars ]] || die "DIR must not contain spaces, commas, '=' or parentheses: $2"

case $cmd in
  start)
    need munged munge
    need mungekey munge
    need slurmctld slurm-wlm  # package slurmctld, pulled in by slurm-wlm
    need slurmd slurm-wlm     # package slurmd
    need sinfo slurm-wlm      # package slurm-client
    need squeue slurm-wlm
    need scancel slurm-wlm
    need timeout coreutils
    mkdir -p -- "$2" || die "cannot create directory $2"
    ;;
  stop)
    if [[ ! -d $2 ]]; then
      msg "$2 does not exist; nothing to stop"
      exit 0
    fi
    ;;
  *) usage ;;
esac

DIR=$(cd -- "$2" && pwd -P) || die "cannot enter directory $2"
# shellcheck disable=SC2053
[[ $DIR != $bad_chars ]] || die "DIR must not contain spaces, commas, '=' or parentheses: $DIR"
# Unix socket paths (munge.sock, slurmd's spool sockets) are limited to 108 bytes.
((${#DIR} <= 70)) || die "DIR path is too long for unix sockets (max 70 chars): $DIR"

if [[ $cmd == start ]]; then
  do_start
else
  do_stop || die "could not stop every daemon in $DIR"
  msg "stopped cluster in $DIR"
fi
