#!/usr/bin/env python3
"""ARFLEX latency benchmark (issue 5): the paper's Table 1 and beyond, beside cyclictest.

Three contenders on the same CPU at the same SCHED_FIFO priority, one after the other in
every mode (interleaved, never concurrent: see docs/latency.md):
  probe     the latency-probe component installed as a bundle into the running DRCR
  pure C    rt-core's arflex-baseline-task (no management at all)
  cyclictest  from Debian's rt-tests (raw per-cycle values with -v -N)
Modes: light (idle), stress (stress-ng), reconfiguration (bundle churn + DTO polling).
The measured CPU is kept apart unless --shared-cpu: the probe holds it exclusively (contract),
the runtime reserves it (arflex.cpus.reserved) and the JVM runs on the other CPUs.
Writes <out>/latency.json and <out>/latency-<mode>.svg; prints Table 1 and the targets.
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import stats  # noqa: E402
import svg  # noqa: E402
from runtime import Runtime, RuntimeError_  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
PERIOD_NS = 1_000_000
CONTENDERS = ["probe", "pure C", "cyclictest"]
MODES = ["light", "stress", "reconfiguration"]
HIST_BIN_NS = 500
HIST_NBINS = 200  # 0..100 us, then overflow

children = []  # Popen objects in their own sessions, killed by group on exit
WORK = []  # the work directory once made (removed on success and on interruption)


class BenchError(Exception):
    pass


def log(msg):
    print(f"[latency {datetime.datetime.now():%H:%M:%S}] {msg}", file=sys.stderr, flush=True)


def spawn(args, **kw):
    p = subprocess.Popen(args, start_new_session=True, **kw)
    children.append(p)
    return p


def reap(p, timeout):
    """Waits for p; kills its group past the deadline. Returns the exit code."""
    try:
        return p.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        kill_group(p)
        raise BenchError(f"{p.args[0]} did not finish within {timeout:.0f} s (killed)")
    finally:
        if p in children and p.poll() is not None:
            children.remove(p)


def kill_group(p):
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(p.pid, sig)
        except (ProcessLookupError, PermissionError):
            break
        try:
            p.wait(timeout=3)
            break
        except subprocess.TimeoutExpired:
            continue


# ---- machine ----------------------------------------------------------------------------------

def machine_info(cpu):
    model = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    preempt = "unknown"
    try:
        with open("/sys/kernel/realtime") as f:
            preempt = "PREEMPT_RT" if f.read().strip() == "1" else preempt
    except OSError:
        v = platform.version()
        preempt = "PREEMPT_RT" if "PREEMPT_RT" in v else ("PREEMPT_DYNAMIC" if "PREEMPT_DYNAMIC" in v
                                                           else ("PREEMPT" if "PREEMPT" in v else "none"))
    # The preemption model in force: PREEMPT_DYNAMIC kernels choose it at boot (preempt=) or
    # through debugfs; "none" means a task in a long kernel section on the measured CPU delays
    # the wake-up of any real-time task there until it returns or reschedules.
    dynamic = None
    try:
        with open("/sys/kernel/debug/sched/preempt") as f:
            m = re.search(r"\(([a-z]+)\)", f.read())
            dynamic = m.group(1) if m else None
    except OSError:
        try:
            out = subprocess.run(["dmesg"], capture_output=True, text=True, timeout=10).stdout
            m = re.search(r"Dynamic Preempt: ([a-z]+)", out)
            dynamic = m.group(1) if m else None
        except (OSError, subprocess.SubprocessError):
            pass
    if preempt == "PREEMPT_DYNAMIC" and dynamic:
        preempt = f"PREEMPT_DYNAMIC, mode {dynamic}"
    # only the boot options that bear on latency (the full line may carry unrelated settings)
    keys = ("isolcpus", "nohz", "nohz_full", "rcu_nocbs", "preempt", "threadirqs", "idle", "processor.max_cstate",
            "intel_idle.max_cstate", "cpuidle", "haltpoll", "mitigations", "irqaffinity", "skew_tick", "nosmt")
    try:
        with open("/proc/cmdline") as f:
            cmdline = " ".join(t for t in f.read().split() if t.split("=", 1)[0] in keys or
                               any(t.startswith(k + ".") for k in keys))
    except OSError:
        cmdline = ""
    try:
        cyclictest_v = subprocess.run(["cyclictest", "--help"], capture_output=True, text=True).stdout.split("\n")[0]
    except OSError:
        cyclictest_v = "missing"
    try:
        stress_v = subprocess.run(["stress-ng", "--version"], capture_output=True, text=True).stdout.strip()
    except OSError:
        stress_v = "missing"
    return {"kernel": f"{platform.system()} {platform.release()} {platform.version()}",
            "preemption": preempt, "cpu_model": model, "cpus_online": os.cpu_count(),
            "bench_cpu": cpu, "kernel_cmdline_latency_options": cmdline, "isolated": "isolcpus" in cmdline,
            "load_average_at_start": os.getloadavg(), "root": os.geteuid() == 0,
            "cyclictest": cyclictest_v, "stress_ng": stress_v, "python": platform.python_version(),
            "hostname": platform.node()}


# ---- contenders ---------------------------------------------------------------------------------

def patched_probe_jar(src, dst, cpu, priority, exclusive):
    """Copy of the probe bundle with the contract's timing set to the benchmark's CPU, priority
    and CPU exclusivity (timing/@exclusive, contracts SPEC 8.6)."""
    name = "OSGI-INF/arflex/latency-probe.xml"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        names = zin.namelist()
        if name not in names or "native/linux-x86_64/latency-probe" not in names:
            raise BenchError(f"{src} lacks {name} or the RT executable (build natively first)")
        for info in zin.infolist():
            data = zin.read(info.filename)
            if info.filename == name:
                text = data.decode()
                text, n1 = re.subn(r'priority="\d+"', f'priority="{priority}"', text)
                text, n2 = re.subn(r'cpus="[^"]*"', f'cpus="{cpu}"', text)
                text = re.sub(r'\s+exclusive="[^"]*"', "", text)
                text, n3 = re.subn(r'(<timing\b[^>]*?)\s*/>', r'\1 exclusive="%s"/>' % str(exclusive).lower(), text)
                if n1 != 1 or n2 != 1 or n3 != 1:
                    raise BenchError(f"{src}: cannot set priority/cpus/exclusive in {name}")
                data = text.encode()
            zout.writestr(info, data)


def cpu_times(cpu):
    """(steal, irq+softirq, total, busy = user+nice+system) jiffies of one CPU from /proc/stat."""
    try:
        with open("/proc/stat") as f:
            for line in f:
                if line.startswith(f"cpu{cpu} "):
                    v = [int(x) for x in line.split()[1:]]
                    return v[7] if len(v) > 7 else 0, v[5] + v[6], sum(v), v[0] + v[1] + v[2]
    except OSError:
        pass
    return 0, 0, 0, 0


# Inter-processor interrupts that other CPUs send to the measured one: a TLB shootdown when a
# process with a thread on it changes its page tables elsewhere, a function call, a reschedule.
IPI_KINDS = ("TLB", "CAL", "RES", "IWI")


def cpu_interrupts(cpu):
    """{kind: count} of the inter-processor interrupts received by one CPU (/proc/interrupts)."""
    out = {}
    try:
        with open("/proc/interrupts") as f:
            cols = f.readline().split()
            if f"CPU{cpu}" not in cols:
                return out
            i = cols.index(f"CPU{cpu}")
            for line in f:
                name, _, rest = line.partition(":")
                name = name.strip()
                if name in IPI_KINDS:
                    out[name] = int(rest.split()[i])
    except (OSError, ValueError, IndexError):
        pass
    return out


def block(fn, cpu, *args):
    """Runs one contender's block and records the bench CPU's steal and interrupt time in it
    (hypervisor steal explains the multi-millisecond outliers on a VM) and the inter-processor
    interrupts it received (what the rest of the machine made it do)."""
    s0, i0, t0, b0 = cpu_times(cpu)
    q0 = cpu_interrupts(cpu)
    w0 = time.monotonic()
    r = fn(*args)
    s1, i1, t1, b1 = cpu_times(cpu)
    q1 = cpu_interrupts(cpu)
    r["cpu_time"] = {"seconds": round(time.monotonic() - w0, 2), "steal_jiffies": s1 - s0,
                     "irq_jiffies": i1 - i0, "total_jiffies": t1 - t0, "busy_jiffies": b1 - b0}
    r["cpu_time"].update({f"ipi_{k.lower()}": q1[k] - q0[k] for k in IPI_KINDS if k in q0 and k in q1})
    return r


def merge_cpu_time(parts):
    parts = [p for p in parts if p]
    if not parts:
        return None
    return {k: round(sum(p[k] for p in parts), 2) for k in parts[0]}


def merge_raw(rounds):
    """Concatenates the rounds of a raw-sample contender (probe, cyclictest)."""
    m = {"lat": [], "dev": [], "overruns": 0, "rounds": len(rounds)}
    for r in rounds:
        m["lat"] += r["lat"]
        m["dev"] += r["dev"]  # within a round only: no deviation across a restart
        m["overruns"] += r["overruns"]
    m["cpu_time"] = merge_cpu_time([r.get("cpu_time") for r in rounds])
    if "reader" in rounds[0]:
        m["overruns_control_block"] = sum(r["overruns_control_block"] or 0 for r in rounds)
        m["reader"] = [r["reader"] for r in rounds]
    return m


def merge_baseline(runs, key, bin_ns_key="histogram_bin_ns"):
    """Long-run columns of the pure C task over several runs, from its JSON files (it keeps no
    raw samples for us). count/average/min/max/overruns are exact. A percentile is exact to
    the 100 ns bin from the merged histogram while it lies below the histogram's range
    (200 us); beyond it, the largest of the runs' exact percentiles is given as an upper
    bound (a percentile of a union never exceeds the largest per-run one) and flagged."""
    ms = [r[key] for r in runs]
    n = sum(m["count"] for m in ms)
    out = {"count": n, "average": sum(m["avg"] * m["count"] for m in ms) / n,
           "avedev": None, "min": min(m["min"] for m in ms), "max": max(m["max"] for m in ms),
           "percentile_method": {}}
    if len(runs) == 1:
        m = ms[0]
        out["avedev"] = m["avedev"]
        for k in ("p50", "p99", "p99_9"):
            out[k] = m.get(k + "_exact", m[k])
            out["percentile_method"][k] = "exact"
        return out
    hist = None
    if key == "wakeup_latency_ns":
        hist = [sum(col) for col in zip(*[r["latency_histogram"] for r in runs])]
        bin_ns = runs[0][bin_ns_key]
    for k, p in (("p50", 50.0), ("p99", 99.0), ("p99_9", 99.9)):
        v = None
        if hist:
            target = max(1, -(-p * n // 100))
            acc = 0
            for i, c in enumerate(hist):
                acc += c
                if acc >= target:
                    v = None if i == len(hist) - 1 else (i + 1) * bin_ns
                    break
        if v is not None:
            out[k] = v
            out["percentile_method"][k] = f"merged {bin_ns} ns histogram (upper bin edge)"
        else:
            out[k] = max(m.get(k + "_exact", m[k]) for m in ms)
            out["percentile_method"][k] = "upper bound: largest per-run exact percentile"
    return out


def run_probe(rt, jar, reader, n, cpu, cpu_other, work, tag):
    """Installs the probe bundle, reads n samples through the reader, uninstalls it."""
    samples = os.path.join(work, f"{tag}-probe.txt")
    summary = os.path.join(work, f"{tag}-probe.json")
    bid = rt.install(jar)
    done = False
    try:
        inst = rt.wait_instance("latency-probe", "ACTIVE", timeout=60)
        if inst.get("cpu") != cpu:
            raise BenchError(f"admission placed the probe on CPU {inst.get('cpu')}, not the measured CPU {cpu}")
        args = ([ "taskset", "-c", str(cpu_other)] if cpu_other is not None else []) + [
            reader, "--runtime", rt.rid, "--instance", inst["name"], "--count", str(n),
            "--out", samples, "--summary", summary, "--idle-timeout-ms", "5000"]
        p = spawn(args)
        rc = reap(p, n / 1000.0 + 60)
        if rc != 0:
            raise BenchError(f"latency-probe-reader exited {rc} (summary {summary})")
        done = True
    finally:
        try:
            rt.uninstall(bid)
            rt.wait_gone("latency-probe", timeout=60)
        except RuntimeError_:
            if done:
                raise  # otherwise the first error (already propagating) is the one to report
    with open(summary) as f:
        summ = json.load(f)
    seqs, rel, lat = [], [], []
    with open(samples) as f:
        for line in f:
            a, b, c = line.split()
            seqs.append(int(a))
            rel.append(int(b))
            lat.append(int(c))
    if len(lat) != n:
        raise BenchError(f"probe: {len(lat)} samples read, {n} wanted")
    if summ["seq_gaps"] or seqs[0] != 1:
        raise BenchError(f"probe: samples missing (first seq {seqs[0]}, gaps {summ['seq_gaps']}): ring too small?")
    dev = [(rel[i] + lat[i]) - (rel[i - 1] + lat[i - 1]) - PERIOD_NS for i in range(1, n)]
    ctl = summ.get("ctl") or {}
    # Overruns over exactly these n cycles: a release more than one period after the previous
    # one is a catch-up after an overrun (the control block's count, a few cycles later, is
    # the cross-check).
    return {"lat": lat, "dev": dev, "overruns": sum(1 for i in range(1, n) if rel[i] - rel[i - 1] > PERIOD_NS),
            "overruns_control_block": ctl.get("overruns"),
            "reader": summ, "sched_fifo": ctl.get("sched_fifo"), "instance": inst}


def run_baseline(exe, n, cpu, prio, work, tag):
    out = os.path.join(work, f"{tag}-baseline-{n}.json")
    p = spawn([exe, "--period-us", "1000", "--priority", str(prio), "--cpu", str(cpu),
               "--loops", str(n), "--json", out, "--quiet"])
    rc = reap(p, n / 1000.0 + 60)
    if rc != 0:
        raise BenchError(f"arflex-baseline-task exited {rc}")
    with open(out) as f:
        return json.load(f)


CYC_LINE = re.compile(r"^\s*0:\s*(\d+):\s*(-?\d+)\s*$")


def run_cyclictest(n, cpu, prio, cpu_other, work, tag):
    out = os.path.join(work, f"{tag}-cyclictest.txt")
    js = os.path.join(work, f"{tag}-cyclictest.json")
    args = ["cyclictest", "-m", "-p", str(prio), "-a", str(cpu), "-t", "1", "-d", "0", "-i", "1000",
            "-l", str(n), "-v", "-N", f"--json={js}"]
    if cpu_other is not None:
        args.append(f"--mainaffinity={cpu_other}")
    with open(out, "w") as f:
        p = spawn(args, stdout=f, stderr=subprocess.STDOUT)
        rc = reap(p, n / 1000.0 + 60)
    if rc != 0:
        raise BenchError(f"cyclictest exited {rc} (output {out})")
    lat = []
    with open(out) as f:
        for line in f:
            m = CYC_LINE.match(line)
            if m:
                lat.append(int(m.group(2)))
    if len(lat) != n:
        raise BenchError(f"cyclictest: {len(lat)} values in {out}, {n} wanted")
    # cyclictest skips whole periods after a late wake-up (next += interval while now > next):
    # the planned step after sample i-1 is (1 + lat[i-1] // interval) intervals.
    dev = [lat[i] - lat[i - 1] + (lat[i - 1] // PERIOD_NS) * PERIOD_NS for i in range(1, n)]
    own = None
    try:
        with open(js) as f:
            own = json.load(f)
    except (OSError, ValueError):
        pass
    return {"lat": lat, "dev": dev, "overruns": sum(1 for x in lat if x >= PERIOD_NS), "own_json": own}


# ---- load -----------------------------------------------------------------------------------------

def expand_cpus(spec):
    """'0,2-3' -> [0, 2, 3]."""
    out = []
    for part in spec.split(","):
        lo, _, hi = part.partition("-")
        out += range(int(lo), int(hi or lo) + 1)
    return out


def stress_args(seconds, seed, work):
    # every CPU, the measured one included, whatever the benchmark's own affinity
    return ["taskset", "-c", f"0-{os.cpu_count() - 1}", "stress-ng", "--cpu", "2", "--vm", "1", "--vm-bytes", "256M", "--hdd", "1", "--hdd-bytes", "64M",
            "--temp-path", work, "--seed", str(seed), "--timeout", f"{seconds}s", "--quiet"]


class Reconfiguration(threading.Thread):
    """Every 100 ms: poll the DTO (10 Hz) and install or uninstall a dummy component (so one
    reconfiguration every 100 ms); every second: Felix update of another installed bundle."""

    def __init__(self, rt, dummy_jar, update_jar, cpu):
        super().__init__(daemon=True, name="reconfiguration")
        self.rt, self.dummy_jar, self.update_jar, self.cpu = rt, dummy_jar, update_jar, cpu
        self.halt = threading.Event()
        self.counts = {"ticks": 0, "late_ticks": 0, "dto_polls": 0, "installs": 0, "uninstalls": 0,
                       "updates": 0, "errors": 0, "polls_with_other_on_measured_cpu": 0}
        self.first_error = None
        self.placements = {}
        self.dummy_id = None
        self.update_id = None

    def run(self):
        try:
            self.update_id = self.rt.install(self.update_jar)
        except RuntimeError_ as e:
            self._err(e)
        next_t = time.monotonic()
        while not self.halt.is_set():
            self.counts["ticks"] += 1
            try:
                d = self.rt.dto()
                self.counts["dto_polls"] += 1
                shared = False
                for i in d.get("instances", []):  # where the admission put the churned components
                    if i.get("name") != "latency-probe" and i.get("cpu") is not None:
                        key = f"{i.get('name')}@cpu{i.get('cpu')}"
                        self.placements[key] = self.placements.get(key, 0) + 1
                        shared |= i.get("cpu") == self.cpu
                self.counts["polls_with_other_on_measured_cpu"] += shared
                if self.dummy_id is None:
                    self.dummy_id = self.rt.install(self.dummy_jar)
                    self.counts["installs"] += 1
                else:
                    bid, self.dummy_id = self.dummy_id, None
                    self.rt.uninstall(bid)
                    self.counts["uninstalls"] += 1
                if self.counts["ticks"] % 10 == 0 and self.update_id is not None:
                    self.rt.felix_update(self.update_id)
                    self.counts["updates"] += 1
            except RuntimeError_ as e:
                self._err(e)
            next_t += 0.1
            now = time.monotonic()
            if now > next_t:
                self.counts["late_ticks"] += 1
                next_t = now
            self.halt.wait(max(0.0, next_t - now))

    def _err(self, e):
        self.counts["errors"] += 1
        if self.first_error is None:
            self.first_error = str(e)

    def finish(self):
        self.halt.set()
        self.join(timeout=120)
        for bid in (self.dummy_id, self.update_id):
            if bid is not None:
                try:
                    self.rt.uninstall(bid)
                except RuntimeError_ as e:
                    self._err(e)
        self.dummy_id = self.update_id = None


# ---- report -----------------------------------------------------------------------------------------

def summarise(res, obs):
    """Table-1 columns over the first obs samples and the long-run columns, both definitions."""
    out = {}
    for c, r in res.items():
        if c == "pure C":
            short, runs = r["short"], r["long"]
            w4, d4 = short["wakeup_latency_ns"], short["period_deviation_ns"]
            out[c] = {
                "wakeup": {"table1": {"count": w4["count"], "average": w4["avg"], "avedev": w4["avedev"],
                                      "min": w4["min"], "max": w4["max"]},
                           "long": merge_baseline(runs, "wakeup_latency_ns")},
                "deviation": {"table1": {"count": d4["count"], "average": d4["avg"], "avedev": d4["avedev"],
                                         "min": d4["min"], "max": d4["max"]},
                              "long": merge_baseline(runs, "period_deviation_ns")},
                "overruns": sum(x["overruns"] for x in runs),
                "note": "Table 1 from a separate run of exactly the observations; long run from the tool's JSON",
                "cpu_time": {"table1": short.get("cpu_time"),
                             "long": merge_cpu_time([x.get("cpu_time") for x in runs])},
            }
        else:
            out[c] = {"wakeup": {"table1": stats.table1(r["lat"][:obs]), "long": stats.long_run(r["lat"])},
                      "deviation": {"table1": stats.table1(r["dev"][:obs - 1]), "long": stats.long_run(r["dev"])},
                      "overruns": r["overruns"], "cpu_time": r.get("cpu_time")}
            if c == "probe":
                out[c]["overruns_control_block"] = r["overruns_control_block"]
                out[c]["reader_per_round"] = r["reader"]
    return out


def fmt(v):
    if v is None:
        return "-"
    return f"{v:,.0f}".replace(",", " ") if isinstance(v, (int, float)) else str(v)


def print_table(summary, modes, obs, dur):
    for defn, title in (("wakeup", "wake-up lateness (actual wake - planned release), ns"),
                        ("deviation", "signed period deviation (wake - previous wake - period), ns")):
        print()
        print(f"Table 1 ({title})")
        print(f"{'':<28}{'AVERAGE':>10}{'AVEDEV':>10}{'MIN':>10}{'MAX':>11}  |{'p50':>9}{'p99':>10}"
              f"{'p99.9':>10}{'MAX':>11}{'overruns':>9}")
        print(f"{'':<28}{f'first {obs} observations':>41}  |{f'long run ({dur} s per contender)':>49}")
        for mode in modes:
            for c in CONTENDERS:
                s = summary[mode].get(c)
                if not s:
                    continue
                t, lg = s[defn]["table1"], s[defn]["long"]
                label = f"{mode} / {c}"
                print(f"{label:<28}{fmt(t['average']):>10}{fmt(t['avedev']):>10}{fmt(t['min']):>10}"
                      f"{fmt(t['max']):>11}  |{fmt(lg['p50']):>9}{fmt(lg['p99']):>10}{fmt(lg['p99_9']):>10}"
                      f"{fmt(lg['max']):>11}{fmt(s['overruns']):>9}")


def long_cpu_time(summary, mode, c):
    """The cpu_time record of a contender's long blocks in one mode (None if absent)."""
    ct = (summary[mode].get(c) or {}).get("cpu_time")
    if isinstance(ct, dict) and "long" in ct:
        ct = ct["long"]
    return ct


def print_cpu_time(summary, modes, cpu):
    hz = os.sysconf("SC_CLK_TCK") or 100
    print()
    print(f"CPU {cpu} during each contender's long blocks: time stolen by the hypervisor / in interrupts / "
          f"busy running tasks (user+system, ms; the contender's own share is ~2 %)")
    for mode in modes:
        parts = []
        for c in CONTENDERS:
            ct = long_cpu_time(summary, mode, c)
            if ct:
                busy = f" / {ct['busy_jiffies'] * 1000 // hz}" if "busy_jiffies" in ct else ""
                parts.append(f"{c}: {ct['steal_jiffies'] * 1000 // hz} / {ct['irq_jiffies'] * 1000 // hz}{busy}"
                             f" in {ct['seconds']:.0f} s")
        la = summary[mode].get("load_average_at_end")
        print(f"  {mode:<16}" + ";  ".join(parts) + (f"  (load average {la[0]:.1f})" if la else ""))
    print(f"CPU {cpu}: inter-processor interrupts received during each contender's long blocks "
          f"({' / '.join(k for k in IPI_KINDS)}: TLB shootdowns, function calls, reschedules, IRQ work)")
    for mode in modes:
        parts = [f"{c}: " + " / ".join(str(ct.get(f"ipi_{k.lower()}", "-")) for k in IPI_KINDS)
                 for c in CONTENDERS if (ct := long_cpu_time(summary, mode, c)) and "ipi_tlb" in ct]
        if parts:
            print(f"  {mode:<16}" + ";  ".join(parts))


def targets(summary, modes):
    rows = []

    def w(mode, c, k):
        try:
            return summary[mode][c]["wakeup"]["long"][k]
        except (KeyError, TypeError):
            return None

    for mode in modes:
        p50p, p50c = w(mode, "probe", "p50"), w(mode, "cyclictest", "p50")
        if p50p is not None and p50c is not None:
            d = p50p - p50c
            rows.append((mode, "p50 probe - cyclictest", f"{d / 1000:+.2f} us", "|d| <= 2 us", abs(d) <= 2000))
        for k, lim in (("p99", 1.05), ("p99_9", 1.2)):
            a, b = w(mode, "probe", k), w(mode, "cyclictest", k)
            if a is not None and b:
                rows.append((mode, f"{k.replace('_', '.')} probe / cyclictest", f"{a / b:.3f}", f"<= {lim}", a / b <= lim))
        for k in ("p50", "p99"):
            a, b = w(mode, "pure C", k), w(mode, "cyclictest", k)
            if a is not None and b:
                r = a / b
                rows.append((mode, f"{k} pure C / cyclictest (sanity)", f"{r:.3f}", "~ 1.0 (0.9..1.1)", 0.9 <= r <= 1.1))
    if "reconfiguration" in modes and "light" in modes:
        a, b = w("reconfiguration", "probe", "p99"), w("light", "probe", "p99")
        if a is not None and b:
            rows.append(("reconfiguration", "probe p99 reconf / light", f"{a / b:.3f}", "<= 1.05", a / b <= 1.05))
        c_rc, c_lt = w("reconfiguration", "cyclictest", "p99"), w("light", "cyclictest", "p99")
        if a is not None and b and c_rc and c_lt:
            # not a target: the same ratio for cyclictest shows how much of it the machine did
            rows.append(("reconfiguration", "  cyclictest p99 reconf / light", f"{c_rc / c_lt:.3f}", "(machine, info)",
                         None))
            rows.append(("reconfiguration", "  probe's ratio / cyclictest's ratio", f"{(a / b) / (c_rc / c_lt):.3f}",
                         "(info)", None))
        try:
            orc = summary["reconfiguration"]["probe"]["overruns"]
            olt = summary["light"]["probe"]["overruns"]
            extra = max(0, orc - olt)
            rows.append(("reconfiguration", "probe extra overruns (reconf - light)", str(extra), "0", extra == 0))
        except (KeyError, TypeError):
            pass
    return rows


def print_targets(rows):
    print()
    print("Targets (issue 5; ratios within this run)")
    for mode, what, val, target, ok in rows:
        verdict = "" if ok is None else ("PASS" if ok else "MISS")
        print(f"  {mode:<16}{what:<40}{val:>12}  target {target:<18}{verdict}")


# ---- main -------------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(prog="arflex bench latency", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cpu", type=int, default=1, help="CPU of all three contenders (default 1)")
    ap.add_argument("--priority", type=int, default=90,
                    help="SCHED_FIFO priority of all three (default 90; the paper's RTAI priority 1)")
    ap.add_argument("--duration", type=int, default=30,
                    help="long run per contender and mode, seconds (default 30)")
    ap.add_argument("--observations", type=int, default=4000, help="Table 1 observations (default 4000)")
    ap.add_argument("--rounds", type=int, default=3,
                    help="split each contender's long run into this many blocks, the order rotating "
                         "every round (default 3; fewer when a block would hold fewer than --observations)")
    ap.add_argument("--modes", default=",".join(MODES), help="comma list of light,stress,reconfiguration")
    ap.add_argument("--quick", action="store_true", help="fast check: --duration 5")
    ap.add_argument("--seed", type=int, default=20240601, help="seed of stress-ng (default 20240601)")
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "bench"), help="output directory")
    ap.add_argument("--native-dir", default=os.path.join(ROOT, "target", "native"))
    ap.add_argument("--runtime-dir", default=os.path.join(ROOT, "management", "runtime", "target", "arflex-runtime"))
    ap.add_argument("--probe-jar", default=os.path.join(ROOT, "bundles", "latency-probe", "target",
                                                        "org.arflex.bench.latencyprobe-0.1.0-SNAPSHOT.jar"))
    ap.add_argument("--dummy-jar", default=os.path.join(ROOT, "bundles", "sample-counter", "target",
                                                        "org.arflex.samples.counter-0.1.0-SNAPSHOT.jar"))
    ap.add_argument("--update-jar", default=os.path.join(ROOT, "bundles", "sample-scaler", "target",
                                                         "org.arflex.samples.scaler-0.1.0-SNAPSHOT.jar"))
    ap.add_argument("--rid", default=f"latb{os.getpid()}", help="runtime id (shm/mq names)")
    ap.add_argument("--shared-cpu", action="store_true",
                    help="do not keep the measured CPU apart (the configuration before CPU reservation): "
                         "the probe's contract is not exclusive, the runtime reserves no CPU and the JVM "
                         "is not pinned to the other CPU")
    ap.add_argument("--keep-work", action="store_true",
                    help="keep the work directory (raw samples, runtime log) after a successful run")
    ap.add_argument("--runtime-cpus", default="others",
                    help="CPU list the runtime's JVM (and the non-RT threads of the RT halves it spawns) "
                         "may run on: 'others' (default: every CPU but --cpu), 'all', or a list for "
                         "taskset -c; ignored with --shared-cpu")
    a = ap.parse_args()
    if a.quick:
        a.duration = 5
    modes = [m.strip() for m in a.modes.split(",") if m.strip()]
    for m in modes:
        if m not in MODES:
            ap.error(f"unknown mode '{m}' (light, stress, reconfiguration)")
    n_long = a.duration * 1000
    if n_long < a.observations:
        ap.error(f"--duration {a.duration} s gives {n_long} cycles, fewer than --observations {a.observations}")
    rounds = max(1, min(a.rounds, n_long // a.observations))
    if rounds != a.rounds:
        log(f"--rounds {a.rounds} -> {rounds}: a block must hold at least {a.observations} cycles")
    if not 1 <= a.priority <= 98:
        ap.error("--priority must be 1..98")
    ncpu = os.cpu_count() or 1
    if not 0 <= a.cpu < ncpu:
        ap.error(f"--cpu {a.cpu}: this machine has CPUs 0..{ncpu - 1}")
    cpu_other = next((c for c in range(ncpu) if c != a.cpu), None)
    bindir = os.path.join(a.native_dir, "bin")
    reader = os.path.join(bindir, "latency-probe-reader")
    baseline = os.path.join(bindir, "arflex-baseline-task")
    for f in (reader, baseline, a.probe_jar, a.dummy_jar, a.update_jar):
        if not os.path.exists(f):
            raise BenchError(f"missing {f} (build first: ./arflex bench latency builds everything)")
    if shutil.which("cyclictest") is None:
        raise BenchError("cyclictest not found (Debian package rt-tests)")
    if "stress" in modes and shutil.which("stress-ng") is None:
        raise BenchError("stress-ng not found (Debian package stress-ng)")

    os.makedirs(a.out, exist_ok=True)
    work = os.path.join(a.out, f"latency-work-{a.rid}")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    WORK.append(work)
    info = machine_info(a.cpu)
    if not info["root"]:
        log("not root: SCHED_FIFO and mlockall will be refused; the figures are SCHED_OTHER figures")
    jars = os.path.join(work, "jars")
    os.makedirs(jars)
    probe_jar = os.path.join(jars, "latency-probe.jar")
    isolate = not a.shared_cpu and cpu_other is not None
    if not isolate or a.runtime_cpus == "all":
        jvm_cpus = None
    elif a.runtime_cpus == "others":
        jvm_cpus = ",".join(str(c) for c in range(ncpu) if c != a.cpu)
    elif re.fullmatch(r"[0-9]+(-[0-9]+)?(,[0-9]+(-[0-9]+)?)*", a.runtime_cpus):
        jvm_cpus = a.runtime_cpus
    else:
        ap.error(f"--runtime-cpus '{a.runtime_cpus}': others, all or a CPU list such as 0 or 0,2-3")
    if jvm_cpus:
        # The benchmark itself (reconfiguration thread, DTO polls, sample parsing) stays off the
        # measured CPU too: unpinned, it ran there 2-3 % of the time in slices of 20 us and more,
        # system calls that delay a wake-up on a kernel without preemption. Its children inherit
        # this; the contenders set their own affinity, stress-ng is given every CPU back.
        os.sched_setaffinity(0, {int(c) for c in expand_cpus(jvm_cpus)})
    patched_probe_jar(a.probe_jar, probe_jar, a.cpu, a.priority, isolate)
    dummy_jar = shutil.copy(a.dummy_jar, os.path.join(jars, "dummy.jar"))
    update_jar = shutil.copy(a.update_jar, os.path.join(jars, "update.jar"))

    t0 = time.time()
    rt = None
    results, reconf_counts = {}, {}
    try:
        log(f"starting the runtime (id {a.rid}) from {a.runtime_dir}")
        # Kept apart (default): admission gives the measured CPU only to contracts naming it
        # (arflex.cpus.reserved) and the probe holds it exclusively; the JVM, and with it the
        # non-RT threads of every RT half it spawns, runs on the other CPU.
        rt = Runtime(a.runtime_dir, work, a.rid, os.path.join(work, "runtime.log"),
                     # arflex.cpus given: the DRCR's default is the JVM's own affinity
                     props={"arflex.cpus": ",".join(str(c) for c in range(ncpu)),
                            "arflex.cpus.reserved": str(a.cpu)} if isolate else None,
                     cpus=jvm_cpus)
        for mode in modes:
            log(f"mode {mode}: {a.duration} s per contender, CPU {a.cpu}, SCHED_FIFO {a.priority}")
            load = reconf = None
            if mode == "stress":
                secs = 3 * a.duration + a.observations // 1000 + 120
                # its "finished prematurely" warnings when we end it go to the work dir's log
                stress_log = open(os.path.join(work, "stress-ng.log"), "w")
                load = spawn(stress_args(secs, a.seed, work), stdout=stress_log, stderr=subprocess.STDOUT)
                stress_log.close()
                time.sleep(2)
            elif mode == "reconfiguration":
                reconf = Reconfiguration(rt, dummy_jar, update_jar, a.cpu)
                reconf_t0 = time.monotonic()
                reconf.start()
                time.sleep(2)
            try:
                raw = {c: [] for c in CONTENDERS}
                short = None
                n_round = n_long // rounds
                for r in range(rounds):
                    order = CONTENDERS[r % 3:] + CONTENDERS[:r % 3]
                    for c in order:
                        log(f"  round {r + 1}/{rounds}: {c} ({n_round} cycles)")
                        if c == "probe":
                            raw[c].append(block(run_probe, a.cpu, rt, probe_jar, reader, n_round, a.cpu, cpu_other,
                                                work, f"{mode}-{r}"))
                        elif c == "pure C":
                            if short is None:
                                short = block(run_baseline, a.cpu, baseline, a.observations, a.cpu, a.priority,
                                              work, f"{mode}-t1")
                            raw[c].append(block(run_baseline, a.cpu, baseline, n_round, a.cpu, a.priority,
                                                work, f"{mode}-{r}"))
                        else:
                            raw[c].append(block(run_cyclictest, a.cpu, n_round, a.cpu, a.priority, cpu_other,
                                                work, f"{mode}-{r}"))
                res = {"probe": merge_raw(raw["probe"]), "cyclictest": merge_raw(raw["cyclictest"]),
                       "pure C": {"short": short, "long": raw["pure C"]}}
                res["load_average"] = os.getloadavg()
                results[mode] = res
            finally:
                if load is not None:
                    kill_group(load)
                    children.remove(load)
                if reconf is not None:
                    reconf.finish()
                    reconf_counts = dict(reconf.counts, first_error=reconf.first_error, placements=reconf.placements,
                                         seconds=round(time.monotonic() - reconf_t0, 1))
    finally:
        if rt is not None:
            rt.close()

    summary = {}
    for m in modes:
        la = results[m].pop("load_average")
        summary[m] = summarise(results[m], a.observations)
        summary[m]["load_average_at_end"] = la
    print_table(summary, modes, a.observations, a.duration)
    print_cpu_time(summary, modes, a.cpu)
    rows = targets(summary, modes)
    print_targets(rows)
    if reconf_counts:
        print(f"\nreconfiguration load: {reconf_counts}")
    for m in MODES:  # a plot of a mode not run this time would be stale
        if m not in modes and os.path.exists(os.path.join(a.out, f"latency-{m}.svg")):
            os.remove(os.path.join(a.out, f"latency-{m}.svg"))
    for m in modes:
        series = []
        for c in CONTENDERS:
            r = results[m][c]
            if c == "pure C":
                lh = [sum(col) for col in zip(*[x["latency_histogram"] for x in r["long"]])]
                series.append((c, stats.rebin(lh, r["long"][0]["histogram_bin_ns"], HIST_BIN_NS, HIST_NBINS)))
            else:
                series.append((c, stats.histogram(r["lat"], HIST_BIN_NS, HIST_NBINS)))
        path = os.path.join(a.out, f"latency-{m}.svg")
        svg.histogram_svg(f"ARFLEX latency, {m} mode: {a.duration} s per contender, CPU {a.cpu}, "
                          f"SCHED_FIFO {a.priority}, 1 kHz", series, HIST_BIN_NS, HIST_NBINS, path)
    doc = {"benchmark": "latency", "issue": 5, "date": datetime.datetime.now(datetime.timezone.utc).isoformat(),
           "machine": info, "seed": a.seed,
           "options": {"cpu": a.cpu, "priority": a.priority, "period_ns": PERIOD_NS, "duration_s": a.duration,
                       "observations": a.observations, "rounds": rounds, "modes": modes, "quick": a.quick, "runtime_id": a.rid,
                       "measured_cpu_kept_apart": isolate,
                       "isolation": ({"probe_contract": f'timing cpus="{a.cpu}" exclusive="true"',
                                      "runtime": f"arflex.cpus.reserved={a.cpu}",
                                      "jvm_affinity": f"taskset -c {jvm_cpus}" if jvm_cpus else "all cpus"}
                                     if isolate else None),
                       "native_dir": a.native_dir, "runtime_dir": a.runtime_dir,
                       "stress_ng": stress_args("T", a.seed, "<work>") if "stress" in modes else None,
                       "schedule": "interleaved per mode in rounds; round r runs the contenders in the order "
                                   "probe, pure C, cyclictest rotated by r; pure C's Table-1 run of exactly "
                                   "the observations comes before its first long block",
                       "cyclictest": f"cyclictest -m -p {a.priority} -a {a.cpu} -t 1 -d 0 -i 1000 -l N -v -N"},
           "elapsed_s": round(time.time() - t0, 1),
           "definitions": {"wakeup": "actual wake - planned release (ns, >= 0), as cyclictest",
                           "deviation": "actual wake - previous actual wake - period (ns, signed)",
                           "percentiles": "nearest rank over all samples of the long run",
                           "avedev": "mean absolute deviation around the mean (spreadsheet AVEDEV)"},
           "results": summary, "targets": [{"mode": m, "what": w_, "value": v, "target": t, "pass": ok}
                                           for m, w_, v, t, ok in rows],
           "reconfiguration_load": reconf_counts,
           "histograms": {m: {"bin_ns": HIST_BIN_NS, "nbins": HIST_NBINS} for m in modes}}
    with open(os.path.join(a.out, "latency.json"), "w") as f:
        json.dump(doc, f, indent=1)
    if a.keep_work:
        log(f"work files kept in {work} (--keep-work: runtime.log, raw samples)")
    else:
        shutil.rmtree(work, ignore_errors=True)
    print(f"\nwrote {os.path.join(a.out, 'latency.json')} and latency-<mode>.svg ({doc['elapsed_s']} s); "
          f"kernel {info['kernel']} ({info['preemption']}), {info['cpu_model']}")


def cleanup_children():
    for p in list(children):
        kill_group(p)


if __name__ == "__main__":
    def on_signal(sig, frame):
        # once: a second Ctrl-C (or the wrapper's TERM) must not interrupt the cleanup
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        raise KeyboardInterrupt
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    try:
        main()
    except KeyboardInterrupt:
        log("interrupted: cleaning up")
        cleanup_children()
        for w in WORK:
            shutil.rmtree(w, ignore_errors=True)
        sys.exit(130)
    except (BenchError, RuntimeError_) as e:
        cleanup_children()
        log(f"error: {e}")
        if WORK:
            log(f"work files kept for diagnosis in {WORK[0]} (runtime.log, raw samples)")
        sys.exit(1)
    finally:
        cleanup_children()
