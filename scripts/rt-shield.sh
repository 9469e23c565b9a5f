#!/usr/bin/env bash
# RT CPU shield: keeps every process that is not the cell's off the CPUs its loops run on.
#
#   scripts/rt-shield.sh on --cpus LIST [--keep PID]... [--poll] [--dry-run]
#   scripts/rt-shield.sh off
#   scripts/rt-shield.sh status
#   scripts/rt-shield.sh rest --cpus LIST     (prints the CPUs the rest of the machine gets)
#
# On a kernel without full preemption (Debian's default and this machine's: PREEMPT_NONE), a task
# in a long kernel section (a linker's munmap, a compiler's page faults) keeps a woken SCHED_FIFO
# thread off its CPU until the section ends: its priority does not help. docs/DECISIONS.md D59
# measured 2-32 ms of sim-robot's CPU held that way by a build running beside the cell. A shield
# moves all processes but the kept ones (and their descendants, now and later) into a cpuset
# without the shielded CPUs, as `isolcpus` does at boot. Per-CPU kernel threads cannot move and
# stay; unbound kernel work (the workqueues' cpumask) goes to the rest too. A process running a
# SCHED_FIFO/RR thread is left where it is (somebody's pinned loop). --poll keeps each shielded CPU
# from idling (a SCHED_IDLE spinner, the runtime's `idle=poll`): in a virtual machine a halted
# vCPU is woken by its host, which D59 saw take up to 25 ms. `off` moves them back, stops the
# spinners and restores the workqueues' mask; a process's own affinity is not restored (it gets
# every CPU). Needs root and a cgroup v1 cpuset hierarchy (mounted at
# $ARFLEX_CPUSET, default /sys/fs/cgroup/cpuset).
set -euo pipefail

CS=${ARFLEX_CPUSET:-/sys/fs/cgroup/cpuset}
SYS="$CS/arflex-system"
STATE=${ARFLEX_SHIELD_STATE:-/run/arflex-rt-shield}
WQ=/sys/devices/virtual/workqueue/cpumask

die() { echo "rt-shield: $*" >&2; exit 2; }

# expand "0,2-3" into "0 2 3"; refuses anything else, naming it
expand() {
  local out=() part a b
  IFS=, read -ra parts <<< "$1"
  for part in "${parts[@]}"; do
    if [[ "$part" =~ ^([0-9]+)$ ]]; then out+=("$part")
    elif [[ "$part" =~ ^([0-9]+)-([0-9]+)$ ]]; then
      a=${BASH_REMATCH[1]} b=${BASH_REMATCH[2]}
      (( a <= b )) || die "CPU range '$part' in '$1' runs backwards"
      for ((; a <= b; a++)); do out+=("$a"); done
    else die "'$part' in CPU list '$1' is not a CPU number or range (e.g. 0,2-3)"; fi
  done
  echo "${out[@]}"
}

join() { local IFS=,; echo "$*"; }

need_cpuset() {
  [ -w "$CS/cgroup.procs" ] || die "no writable cgroup v1 cpuset hierarchy at $CS (root is needed; set ARFLEX_CPUSET to its mount point)"
}

# the kept PIDs and all their descendants, one per line
kept_tree() {
  local -A parent=()
  local p pp
  for p in /proc/[0-9]*; do
    p=${p#/proc/}
    pp=$(awk '{ sub(/^.*\) /, ""); print $2 }' "/proc/$p/stat" 2>/dev/null) || continue
    parent[$p]=$pp
  done
  for p in "${!parent[@]}"; do
    local q=$p
    while [ -n "$q" ] && [ "$q" != 0 ]; do
      if [[ " $* " == *" $q "* ]]; then echo "$p"; break; fi
      q=${parent[$q]:-}
    done
  done
}

# true when a thread of process $1 runs under SCHED_FIFO (1) or SCHED_RR (2); field 41 of stat
has_rt_thread() {
  local t pol
  for t in /proc/"$1"/task/*/stat; do
    pol=$(awk '{ sub(/^.*\) /, ""); print $39 }' "$t" 2>/dev/null) || continue
    [ "$pol" = 1 ] || [ "$pol" = 2 ] && return 0
  done
  return 1
}

# sets SHIELD (the CPUs of $1, checked online) and REST (the other online CPUs, at least one)
split_cpus() {
  local online c
  [ -n "$1" ] || die "--cpus LIST is needed: the CPUs to keep for the cell"
  online=$(expand "$(cat /sys/devices/system/cpu/online)")
  SHIELD=$(expand "$1")
  for c in $SHIELD; do
    [[ " $online " == *" $c "* ]] || die "CPU $c in --cpus '$1' is not online (online: $(cat /sys/devices/system/cpu/online))"
  done
  REST=()
  for c in $online; do [[ " $SHIELD " == *" $c "* ]] || REST+=("$c"); done
  [ ${#REST[@]} -gt 0 ] || die "--cpus '$1' names every online CPU: the rest of the machine needs one"
}

# the hexadecimal mask of the CPUs given
mask() { local m=0 c; for c in "$@"; do m=$((m | (1 << c))); done; printf '%x\n' "$m"; }

cmd_rest() {
  [ "${1:-}" = --cpus ] && [ $# -eq 2 ] || die "usage: rt-shield.sh rest --cpus LIST"
  split_cpus "$2"
  join "${REST[@]}"
}

cmd_on() {
  local cpus="" dry=false poll=false keep=()
  while [ $# -gt 0 ]; do
    case "$1" in
      --cpus) cpus=${2:?--cpus needs a CPU list}; shift 2 ;;
      --keep) [[ "${2:-}" =~ ^[0-9]+$ ]] || die "--keep needs a process id, got '${2:-}'"; keep+=("$2"); shift 2 ;;
      --poll) poll=true; shift ;;
      --dry-run) dry=true; shift ;;
      *) die "unknown option '$1' for 'on' (--cpus LIST, --keep PID, --poll, --dry-run)" ;;
    esac
  done
  split_cpus "$cpus"
  local shield=$SHIELD rest=("${REST[@]}") c
  need_cpuset
  [ -d "$SYS" ] && die "a shield is already on (CPUs $(cat "$SYS/cpuset.cpus") for the rest); 'off' first"
  local kept
  kept=" $( [ ${#keep[@]} -gt 0 ] && kept_tree "${keep[@]}" | tr '\n' ' ') "
  if $dry; then
    echo "rt-shield: would move every process but $(echo "$kept" | wc -w | tr -d ' ') kept to CPUs $(join "${rest[@]}"), keeping CPUs $(join $shield) for the cell"
    return 0
  fi
  mkdir "$SYS"
  cat "$CS/cpuset.mems" > "$SYS/cpuset.mems"
  join "${rest[@]}" > "$SYS/cpuset.cpus"
  local moved=0 stayed=0 rt=0 p
  for p in $(cat "$CS/cgroup.procs"); do
    [[ "$kept" == *" $p "* ]] && continue
    # a process with a SCHED_FIFO/RR thread is somebody's real-time loop, pinned where it is: the
    # cpuset would take its CPU away, so it stays (counted)
    if has_rt_thread "$p"; then rt=$((rt + 1)); continue; fi
    if echo "$p" > "$SYS/cgroup.procs" 2>/dev/null; then moved=$((moved + 1)); else stayed=$((stayed + 1)); fi
  done
  mkdir -p "$STATE"
  if [ -w "$WQ" ]; then
    cat "$WQ" > "$STATE/workqueue.cpumask"
    mask "${rest[@]}" > "$WQ" || true
  fi
  : > "$STATE/spinners"
  if $poll; then
    for c in $shield; do
      # started after the moves, so it stays on every CPU's set; pinned to the one it keeps awake
      setsid taskset -c "$c" chrt -i 0 sh -c 'while :; do :; done' < /dev/null > /dev/null 2>&1 &
      echo $! >> "$STATE/spinners"
    done
  fi
  echo "rt-shield: on: CPUs $(join $shield) kept for the cell$($poll && echo ", polling when idle"); $moved processes moved to CPUs $(join "${rest[@]}"), $stayed could not move (per-CPU kernel threads), $rt left where they are (they run SCHED_FIFO/RR threads), $(echo "$kept" | wc -w | tr -d ' ') kept"
}

cmd_off() {
  need_cpuset
  [ -d "$SYS" ] || { echo "rt-shield: off: no shield was on"; return 0; }
  local n=0 p
  # a process forked while we move still lands in the shield's set: loop until it is empty
  local left tries=0
  while left=$(cat "$SYS/cgroup.procs") && [ -n "$left" ]; do
    tries=$((tries + 1))
    [ $tries -le 100 ] || die "off: processes $(echo $left) do not leave $SYS"
    for p in $left; do
      echo "$p" > "$CS/cgroup.procs" 2>/dev/null && n=$((n + 1)) || true
    done
  done
  rmdir "$SYS"
  if [ -f "$STATE/spinners" ]; then
    for p in $(cat "$STATE/spinners"); do kill "$p" 2>/dev/null || true; done
  fi
  if [ -f "$STATE/workqueue.cpumask" ] && [ -w "$WQ" ]; then cat "$STATE/workqueue.cpumask" > "$WQ" || true; fi
  rm -rf "$STATE"
  echo "rt-shield: off: $n processes back on every CPU"
}

cmd_status() {
  if [ -d "$SYS" ]; then
    echo "rt-shield: on: the rest of the machine runs on CPUs $(cat "$SYS/cpuset.cpus") ($(wc -l < "$SYS/cgroup.procs") processes); $(wc -l < "$CS/cgroup.procs") processes on every CPU"
  else
    echo "rt-shield: off"
  fi
}

case "${1:-}" in
  on) shift; cmd_on "$@" ;;
  off) shift; [ $# -eq 0 ] || die "'off' takes no arguments"; cmd_off ;;
  status) shift; [ $# -eq 0 ] || die "'status' takes no arguments"; cmd_status ;;
  rest) shift; cmd_rest "$@" ;;
  *) die "usage: rt-shield.sh on --cpus LIST [--keep PID]... [--poll] [--dry-run] | off | status | rest --cpus LIST" ;;
esac
