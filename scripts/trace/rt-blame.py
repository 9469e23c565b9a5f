#!/usr/bin/env python3
"""Why a SCHED_FIFO loop ran late, from a text ftrace of scripts/trace/rt-trace.sh.

    rt-blame.py TRACE COMM [--gap MS]

For every SCHED_FIFO thread whose name starts with COMM, each pair of its consecutive runs that
lie more than --gap ms apart (default 1.9: a 1 ms loop that lost a release) is put in one of:

  held       it was woken on time but its CPU went to it only later: the task shown was in a
             section the kernel does not preempt (PREEMPT_NONE: any system call or fault), or
             a SCHED_FIFO task of its priority or above ran;
  late-wake  its timer's wake-up itself came late and its CPU shows no event meanwhile: the
             CPU did not take the interrupt (in a virtual machine: the vCPU was not running, or
             a halted vCPU was woken late by its host);
  long-run   it ran more than 1 ms in one go: its own cycle overran, or its CPU stopped under it.

Prints one line per late run and a count by kind and holder. docs/DECISIONS.md D59.
"""
import argparse
import collections
import re
import sys

LINE = re.compile(r'^\s*(.{1,16}?)-(\d+)\s+(?:\(\s*(\S+)\)\s+)?\[(\d+)\]\s+\S+\s+([\d.]+): (\w+): (.*)$')
SWITCH = re.compile(r'prev_comm=(.*?) prev_pid=(\d+) prev_prio=(\d+) prev_state=(\S+) ==> '
                    r'next_comm=(.*?) next_pid=(\d+) next_prio=(\d+)')
WAKE = re.compile(r'comm=(.*?) pid=(\d+) prio=(\d+)')


def read(path):
    events = []
    with open(path, errors='replace') as f:
        for ln in f:
            m = LINE.match(ln)
            if m:
                comm, pid, tgid, cpu, ts, ev, rest = m.groups()
                events.append((float(ts), int(cpu), comm.strip(), int(pid), tgid, ev, rest))
    return events


def rt_threads(events, comm):
    """Thread ids named comm... that ran at a real-time priority (kernel prio below 100)."""
    tids = set()
    for e in events:
        if e[5] == 'sched_switch':
            s = SWITCH.search(e[6])
            if s and s.group(5).startswith(comm) and int(s.group(7)) < 100:
                tids.add(int(s.group(6)))
    return sorted(tids)


def blame(events, tid, gap_s):
    outs = [i for i, e in enumerate(events) if e[5] == 'sched_switch' and f' prev_pid={tid} ' in e[6]]
    rows = []
    for a, b in zip(outs, outs[1:]):
        ta, tb = events[a][0], events[b][0]
        if tb - ta <= gap_s:
            continue
        cpu = events[b][1]
        wake = next((i for i in range(a, b) if events[i][5] == 'sched_wakeup'
                     and f' pid={tid} ' in ' ' + events[i][6]), None)
        run = next((i for i in range(wake if wake is not None else a, b) if events[i][5] == 'sched_switch'
                    and f' next_pid={tid} ' in events[i][6] + ' '), None)
        holder = '?'
        if run is not None:
            s = SWITCH.search(events[run][6])
            holder = f'{s.group(1)}-{s.group(2)}'
            if events[run][4]:
                holder += f' (process {events[run][4].strip()})'
        tw = events[wake][0] if wake is not None else None
        wait = events[run][0] - tw if (run is not None and tw is not None) else None
        quiet = [e[0] for e in events[a:(wake + 1 if wake is not None else b)] if e[1] == cpu]
        silence = max((y - x for x, y in zip(quiet, quiet[1:])), default=0.0)
        ran_for = tb - events[run][0] if run is not None else 0.0
        kind = ('long-run' if ran_for > 1e-3 else
                'held' if wait is not None and wait > 0.5e-3 else 'late-wake')
        rows.append((ta, tb - ta, tw - ta if tw is not None else None, wait, holder, cpu, silence, kind))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('trace')
    ap.add_argument('comm')
    ap.add_argument('--gap', type=float, default=1.9, help='ms between two runs that counts as late (1.9)')
    a = ap.parse_args()
    events = read(a.trace)
    tids = rt_threads(events, a.comm)
    if not tids:
        sys.exit(f"rt-blame: no SCHED_FIFO thread named '{a.comm}...' ran in {a.trace}")
    counts = collections.Counter()
    for tid in tids:
        rows = blame(events, tid, a.gap / 1e3)
        print(f'{a.comm} thread {tid}: {len(rows)} runs more than {a.gap} ms after the one before')
        for ta, g, w, wait, holder, cpu, sil, kind in rows:
            ws = f'{1e3 * w:6.2f}' if w is not None else '     ?'
            rs = f'{1e3 * wait:6.2f}' if wait is not None else '     ?'
            print(f'  {ta:.6f} +{1e3 * g:6.2f} ms  woken +{ws} ms  ran +{rs} ms after  cpu{cpu}  '
                  f'silent {1e3 * sil:5.2f} ms  {kind:9s} {holder if kind == "held" else ""}')
            counts[kind if kind != 'held' else f'held by {re.sub(r"-[0-9]+ .*$|-[0-9]+$", "", holder)}'] += 1
    print('rt-blame: ' + (', '.join(f'{k} {v}' for k, v in counts.most_common()) or 'no late runs'))


if __name__ == '__main__':
    main()
