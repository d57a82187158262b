#!/usr/bin/env bash
# A private single-node Slurm cluster for tests: one slurmctld, one slurmd and
# one munged, all on loopback, all state, logs, sockets and pid files inside
# one directory, so that a test can submit `sbatch --array` jobs to it without
# touching (or needing) any Slurm or munge installed system-wide.
#
#   tools/slurm_private.sh start DIR   start it; prints `export SLURM_CONF=...`
#   tools/slurm_private.sh stop DIR    stop what `start DIR` started (idempotent)
#   tools/slurm_private.sh check       are the binaries there? (exit 1 if not)
#
# Typical use in a test:
#   dir="$(mktemp -d)"
#   trap 'tools/slurm_private.sh stop "$dir"; rm -rf "$dir"' EXIT
#   eval "$(tools/slurm_private.sh start "$dir")"
#   sbatch --wait --array=0-3 --wrap '...'
#
# Needs the Debian packages slurm-wlm and munge (Slurm 22.05 on Debian 12).
# Runs as root (SlurmUser=root), without systemd and without cgroups.
# SLURM_PRIVATE_EXTRA_CONF, if set, is appended verbatim to slurm.conf
# (e.g. "MinJobAge=5" for a faster `sbatch --wait`, see below).
# Only progress and errors go to stderr; stdout carries just the export line.
set -euo pipefail

# Every daemon we start carries this variable in its environment (and so do the
# slurmstepd processes slurmd forks): `stop` kills only processes that have it
# with the value of their DIR, never any other Slurm or munge on the machine.
marker=PADDOCK_SLURM_PRIVATE

say() { echo "slurm_private: $*" >&2; }
die() { say "error: $*"; exit 1; }

usage() {
  sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

# ---------------------------------------------------------------- check
binaries=(slurmctld slurmd sbatch squeue sinfo scancel munged)

# exit 0 if every binary is on PATH (sbin included), else name the missing ones
cmd_check() {
  local missing=() b
  for b in "${binaries[@]}"; do
    command -v "$b" >/dev/null 2>&1 || missing+=("$b")
  done
  if [ "${#missing[@]}" -gt 0 ]; then
    echo "slurm_private: missing: ${missing[*]} (Debian packages: slurm-wlm munge)" >&2
    return 1
  fi
  return 0
}

# ---------------------------------------------------------------- processes
# is PID alive and one of ours for DIR (its environment holds the marker)?
ours() {
  local pid="$1" dir="$2"
  [ -n "$pid" ] && [ -r "/proc/$pid/environ" ] &&
    grep -Fqxz "$marker=$dir" "/proc/$pid/environ" 2>/dev/null
}

# PIDs of every live process of ours for DIR (the daemons and slurmstepds)
our_pids() {
  local dir="$1" p pid
  for p in /proc/[0-9]*; do
    pid="${p#/proc/}"
    [ "$pid" = "$$" ] && continue
    if ours "$pid" "$dir"; then echo "$pid"; fi
  done
}

# signal PID (if ours), wait up to SECONDS for it to go, then SIGKILL it
stop_pid() {
  local pid="$1" dir="$2" name="$3" wait_s="${4:-10}" i
  ours "$pid" "$dir" || return 0
  kill -TERM "$pid" 2>/dev/null || return 0
  for ((i = 0; i < wait_s * 10; i++)); do
    ours "$pid" "$dir" || return 0
    sleep 0.1
  done
  say "$name (pid $pid) did not stop in ${wait_s}s: SIGKILL"
  kill -KILL "$pid" 2>/dev/null || true
  for ((i = 0; i < 50; i++)); do ours "$pid" "$dir" || return 0; sleep 0.1; done
  say "warning: $name (pid $pid) still there after SIGKILL"
}

# ---------------------------------------------------------------- ports
# TCP ports in use in any state (listening, connected, TIME_WAIT...), decimal
used_ports() {
  cat /proc/net/tcp /proc/net/tcp6 2>/dev/null |
    awk 'NR > 0 && $2 ~ /:/ { split($2, a, ":"); print a[2] }' |
    while read -r hex; do echo $((16#$hex)); done | sort -un
}

# a free TCP port below the kernel's ephemeral range (so no outgoing
# connection takes it meanwhile), not in the list of $1 (space separated)
free_port() {
  local avoid=" $1 " used lo=15000 hi=32000 eph p i
  eph="$(awk '{print $1}' /proc/sys/net/ipv4/ip_local_port_range 2>/dev/null || echo 32768)"
  [ "$eph" -gt $((lo + 2000)) ] && [ "$eph" -le 65535 ] && hi="$eph"
  used=" $(used_ports | tr '\n' ' ') "
  for ((i = 0; i < 200; i++)); do
    p=$((lo + (RANDOM * 32768 + RANDOM) % (hi - lo)))
    case "$used$avoid" in *" $p "*) continue ;; esac
    echo "$p"
    return 0
  done
  die "found no free TCP port in $lo-$((hi - 1))"
}

# ---------------------------------------------------------------- config
write_conf() {
  local dir="$1" node="$2" ctld_port="$3" slurmd_port="$4" comm=""
  # Bind the daemons to loopback only (not 0.0.0.0). Slurm binds to what
  # gethostname() resolves to, so this is only right when that is 127.x;
  # otherwise bind to any address (still only ever contacted on 127.0.0.1).
  if getent ahostsv4 "$(hostname)" 2>/dev/null | awk '$1 ~ /^127\./ { f = 1 } END { exit !f }'; then
    comm="CommunicationParameters=NoInAddrAny,NoCtldInAddrAny"
  else
    say "note: $(hostname) does not resolve to 127.x; daemons listen on all addresses"
  fi
  cat >"$dir/etc/slurm.conf" <<EOF
# written by tools/slurm_private.sh for a private single-node test cluster
ClusterName=paddock
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
$comm
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/run/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.daemon.pid
SlurmdPidFile=$dir/run/slurmd.daemon.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
# no cgroups, no accounting, no MPI, no mail
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
NodeName=$node NodeHostname=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
  if [ -n "${SLURM_PRIVATE_EXTRA_CONF:-}" ]; then
    printf '%s\n' "# SLURM_PRIVATE_EXTRA_CONF" "$SLURM_PRIVATE_EXTRA_CONF" >>"$dir/etc/slurm.conf"
  fi
}

# ---------------------------------------------------------------- start
# print the last lines of every log in DIR/log to stderr
show_logs() {
  local f
  for f in "$1"/log/*; do
    [ -s "$f" ] || continue
    echo "----- tail of $f" >&2
    tail -n 15 "$f" >&2
  done
}

# start a daemon in the foreground mode in the background, stdio to a log,
# with the marker in its environment; record its PID in DIR/run/NAME.pid
launch() {
  local dir="$1" name="$2"
  shift 2
  env "$marker=$dir" SLURM_CONF="$dir/etc/slurm.conf" "$@" \
    </dev/null >>"$dir/log/$name.out" 2>&1 &
  echo $! >"$dir/run/$name.pid"
}

# DIR/run/NAME.pid is alive and ours?
alive() { ours "$(cat "$1/run/$2.pid" 2>/dev/null || true)" "$1"; }

# the process `launch` just started is still there? (during start: until
# `env` has exec'd the daemon, its environment does not show the marker yet,
# so `alive` would call a daemon that is starting dead)
running() {
  local pid
  pid="$(cat "$1/run/$2.pid" 2>/dev/null || true)"
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null && [ "$(cut -d' ' -f3 "/proc/$pid/stat" 2>/dev/null)" != Z ]
}

# one attempt: configure, launch the three daemons, wait for the node to be
# idle. Returns 0 when up, 2 when a port was taken meanwhile, 1 otherwise.
start_once() {
  local dir="$1" timeout_s="$2" node ctld_port slurmd_port i state=""
  node="$(hostname -s)"
  ctld_port="$(free_port "")"
  slurmd_port="$(free_port "$ctld_port")"
  write_conf "$dir" "$node" "$ctld_port" "$slurmd_port"
  export SLURM_CONF="$dir/etc/slurm.conf"

  # munged: private key, socket, pid, log and seed, in the foreground (-F)
  if [ ! -s "$dir/etc/munge.key" ]; then
    if command -v mungekey >/dev/null 2>&1; then
      mungekey --create --keyfile="$dir/etc/munge.key" 2>/dev/null
    else
      dd if=/dev/urandom of="$dir/etc/munge.key" bs=1024 count=1 status=none
    fi
    chmod 0400 "$dir/etc/munge.key"
  fi
  rm -f "$dir/run/munge.socket" "$dir/run/munge.socket.lock"
  launch "$dir" munged munged --foreground \
    --socket="$dir/run/munge.socket" --key-file="$dir/etc/munge.key" \
    --pid-file="$dir/run/munged.daemon.pid" --log-file="$dir/log/munged.log" \
    --seed-file="$dir/state/munged.seed"
  for ((i = 0; i < 100; i++)); do
    [ -S "$dir/run/munge.socket" ] && break
    running "$dir" munged || { say "munged exited at start"; return 1; }
    sleep 0.1
  done
  [ -S "$dir/run/munge.socket" ] || { say "munged made no socket in 10 s"; return 1; }

  # slurmctld, then slurmd for our node name, both in the foreground (-D)
  launch "$dir" slurmctld slurmctld -D -f "$SLURM_CONF"
  launch "$dir" slurmd slurmd -D -N "$node" -f "$SLURM_CONF"

  # wait for the node to be idle, watching that every daemon is still alive
  for ((i = 0; i < timeout_s * 4; i++)); do
    for d in munged slurmctld slurmd; do
      if ! running "$dir" "$d"; then
        say "$d exited during start"
        if grep -qs "Address already in use" "$dir/log/$d.out" "$dir/log/$d.log"; then
          return 2
        fi
        return 1
      fi
    done
    state="$(timeout 5 sinfo -h -n "$node" -o %T 2>/dev/null || true)"
    case "$state" in idle | idle\~) return 0 ;; esac
    sleep 0.25
  done
  say "node $node not idle after ${timeout_s}s (state: '${state:-no answer}')"
  return 1
}

cmd_start() {
  local dir="$1" rc=1 attempt t0
  t0="$(date +%s.%N)"
  cmd_check || die "Slurm or munge is not installed"
  [ "$(id -u)" = 0 ] || die "must run as root (SlurmUser=root)"
  case "$dir" in *[[:space:]#=\"\']*) die "DIR must not contain blanks, #, =, or quotes: '$dir'" ;; esac
  mkdir -p "$dir"
  dir="$(cd "$dir" && pwd -P)"
  # a unix socket path has at most 107 bytes
  [ "${#dir}" -le 80 ] || die "DIR path too long for a unix socket: $dir"
  for d in munged slurmctld slurmd; do
    alive "$dir" "$d" && die "a private cluster is already running in $dir (stop it first)"
  done
  mkdir -p "$dir"/{etc,state,spool,log,run}
  # munged refuses a socket in a directory others cannot traverse (mktemp -d
  # makes 0700): open DIR and DIR/run for traversal, keep the rest private
  chmod 0755 "$dir" "$dir/run"
  chmod 0700 "$dir/etc" "$dir/state"

  for attempt in 1 2 3; do
    rc=0
    start_once "$dir" "${SLURM_PRIVATE_TIMEOUT:-60}" || rc=$?
    [ "$rc" = 0 ] && break
    if [ "$rc" = 2 ] && [ "$attempt" -lt 3 ]; then
      say "a port was taken meanwhile; retrying with other ports"
      cmd_stop "$dir" >/dev/null 2>&1 || true
      continue
    fi
    break
  done
  if [ "$rc" != 0 ]; then
    show_logs "$dir"
    cmd_stop "$dir" || true
    die "the private Slurm cluster in $dir did not come up (logs above)"
  fi
  say "up in $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s: node $(hostname -s), $(grep -E '^Slurm(ctld|d)Port=' "$dir/etc/slurm.conf" | tr '\n' ' ')"
  echo "export SLURM_CONF=$dir/etc/slurm.conf"
}

# ---------------------------------------------------------------- stop
cmd_stop() {
  local dir="$1" d pid i left
  [ -d "$dir" ] || return 0
  dir="$(cd "$dir" && pwd -P)"
  export SLURM_CONF="$dir/etc/slurm.conf"

  # cancel whatever jobs are left, so that no slurmstepd or job lingers
  if alive "$dir" slurmctld && command -v squeue >/dev/null 2>&1; then
    local jobs_left
    jobs_left="$(timeout 10 squeue -h -o %A 2>/dev/null | sort -u | tr '\n' ' ' || true)"
    if [ -n "${jobs_left// /}" ]; then
      # shellcheck disable=SC2086
      timeout 10 scancel $jobs_left 2>/dev/null || true
      for ((i = 0; i < 100; i++)); do
        [ -z "$(timeout 5 squeue -h -o %A 2>/dev/null || true)" ] && break
        sleep 0.1
      done
    fi
  fi

  # the daemons, by the PIDs recorded at start (checked to be ours)
  for d in slurmd slurmctld munged; do
    pid="$(cat "$dir/run/$d.pid" 2>/dev/null || true)"
    [ -n "$pid" ] && stop_pid "$pid" "$dir" "$d" 10
    rm -f "$dir/run/$d.pid"
  done

  # anything else of ours still there (slurmstepd, a daemon whose pid file
  # was lost): TERM, then KILL
  left="$(our_pids "$dir" | tr '\n' ' ')"
  if [ -n "${left// /}" ]; then
    # shellcheck disable=SC2086
    kill -TERM $left 2>/dev/null || true
    for ((i = 0; i < 50; i++)); do
      left="$(our_pids "$dir" | tr '\n' ' ')"
      [ -z "${left// /}" ] && break
      sleep 0.1
    done
    if [ -n "${left// /}" ]; then
      say "SIGKILL to leftover processes: $left"
      # shellcheck disable=SC2086
      kill -KILL $left 2>/dev/null || true
    fi
  fi
  rm -f "$dir/run/munge.socket" "$dir/run/munge.socket.lock" "$dir"/run/*.daemon.pid
  return 0
}

# ---------------------------------------------------------------- main
[ $# -ge 1 ] || usage
case "$1" in
  check) cmd_check ;;
  start) [ $# -eq 2 ] || usage; cmd_start "$2" ;;
  stop) [ $# -eq 2 ] || usage; cmd_stop "$2" ;;
  *) usage ;;
esac

# Notes (Slurm 22.05, Debian 12):
# - `sbatch --wait` polls the controller after 2 s, 10 s, then every 32 s;
#   it keeps polling every 2 s only when MinJobAge <= 5 (so as not to miss a
#   finished job being purged: a job it misses counts as exit code 0). With
#   the default MinJobAge=300 a 4-task array of `echo` returns after ~10 s;
#   SLURM_PRIVATE_EXTRA_CONF=$'MinJobAge=5\nSchedulerParameters=sched_interval=1'
#   makes it ~4 s, at the cost of finished jobs vanishing from squeue sooner.
# - the mpi/pmix "can not load PMIx library" errors in the logs are harmless
#   (Slurm loads every MPI plugin it finds; MpiDefault=none).
