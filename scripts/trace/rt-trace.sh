#!/usr/bin/env bash
# Records the kernel's scheduling (ftrace) to tell why a real-time loop lost a release.
#
#   scripts/trace/rt-trace.sh start [MB_PER_CPU]   (default 400)
#   scripts/trace/rt-trace.sh stop FILE            writes the text trace to FILE, tracing off
#   scripts/trace/rt-blame.py FILE COMM [--gap MS] who held a SCHED_FIFO thread named COMM
#
# Records sched_switch, sched_wakeup, the process events and the mmap_lock events, with the
# thread group of each task and the monotonic clock (CLOCK_MONOTONIC, as rt-core's timestamps).
# Needs root and tracefs (mounted at /sys/kernel/tracing when it is not). A 1 kHz cell of 12
# halves writes ~100 MB per CPU and minute. docs/DECISIONS.md D59.
set -euo pipefail
T=/sys/kernel/tracing
die() { echo "rt-trace: $*" >&2; exit 2; }
if [ ! -e "$T/tracing_on" ]; then
  mount -t tracefs nodev "$T" 2>/dev/null || die "no tracefs at $T and it cannot be mounted (root is needed)"
fi
case "${1:-}" in
  start)
    mb=${2:-400}
    [[ "$mb" =~ ^[1-9][0-9]*$ ]] || die "'$mb' is not a size in MB per CPU"
    echo 0 > "$T/tracing_on"
    echo > "$T/trace"
    echo mono > "$T/trace_clock"
    echo $((mb * 1024)) > "$T/buffer_size_kb"
    echo 1 > "$T/options/record-tgid"
    echo 0 > "$T/events/enable"
    for e in sched/sched_switch sched/sched_wakeup sched/sched_process_exec sched/sched_process_fork \
             sched/sched_process_exit mmap_lock/mmap_lock_start_locking mmap_lock/mmap_lock_acquire_returned \
             mmap_lock/mmap_lock_released; do
      [ -e "$T/events/$e/enable" ] && echo 1 > "$T/events/$e/enable"
    done
    echo 1 > "$T/tracing_on"
    echo "rt-trace: recording ($mb MB per CPU); 'stop FILE' ends it" ;;
  stop)
    out=${2:?stop needs the file to write}
    echo 0 > "$T/tracing_on"
    cat "$T/trace" > "$out"
    lost=$(awk '/^overrun:/ { s += $2 } END { print s + 0 }' "$T"/per_cpu/cpu*/stats)
    echo 0 > "$T/events/enable"
    echo > "$T/trace"
    echo 1408 > "$T/buffer_size_kb"
    echo "rt-trace: $(wc -l < "$out") lines in $out; $lost events lost to a full buffer" ;;
  *) die "usage: rt-trace.sh start [MB_PER_CPU] | stop FILE" ;;
esac
