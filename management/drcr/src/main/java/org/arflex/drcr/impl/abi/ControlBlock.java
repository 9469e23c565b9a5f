package org.arflex.drcr.impl.abi;

import java.io.IOException;
import java.util.List;

/**
 * The control block segment {@code /arflex.<rid>.<inst>.ctl}: Java side of
 * rt-core/include/arflex/control.h (struct arflex_ctl). The offsets below are that layout, taken
 * from {@link Layout}, which is generated from the header (DECISIONS.md D22); ControlBlockLayoutTest
 * checks that each name here is the C member it says.
 *
 * <p>Who writes what (control.h): the manager writes header, config and parameter descriptors
 * before the spawn, then only {@code runtime_hb_ns} and the parameter request words; everything
 * else belongs to the RT process.
 */
public final class ControlBlock implements AutoCloseable {

    public static final long MAGIC = Layout.CTL_MAGIC; // "ARFLXCTL"
    public static final int ABI_MAJOR = Layout.ABI_MAJOR;
    public static final int ABI_MINOR = Layout.ABI_MINOR;
    public static final int SIZE = Layout.CTL_SIZE;

    // header
    public static final int OFF_MAGIC = Layout.OFF_CTL_MAGIC;
    public static final int OFF_ABI_MAJOR = Layout.OFF_CTL_ABI_MAJOR;
    public static final int OFF_ABI_MINOR = Layout.OFF_CTL_ABI_MINOR;
    public static final int OFF_HEADER_SIZE = Layout.OFF_CTL_HEADER_SIZE;
    public static final int OFF_SIZE = Layout.OFF_CTL_SIZE;
    public static final int OFF_STATE = Layout.OFF_CTL_STATE;
    public static final int OFF_FLAGS = Layout.OFF_CTL_FLAGS;
    public static final int OFF_PID = Layout.OFF_CTL_PID;
    public static final int OFF_EXIT_STATUS = Layout.OFF_CTL_EXIT_STATUS;
    public static final int OFF_RUNTIME_HB = Layout.OFF_CTL_RUNTIME_HB_NS;
    public static final int OFF_RT_HB = Layout.OFF_CTL_RT_HB_NS;
    /** ctl.hold (uint32): why the component holds the arm by itself; cause | detail << 8 | input << 16. */
    public static final int OFF_HOLD = Layout.OFF_CTL_HOLD;
    public static final int HOLD_NONE = Layout.HOLD_NONE;
    public static final int HOLD_SAFETY_INPUT = Layout.HOLD_SAFETY_INPUT;
    public static final int HOLD_AWAIT_COMMAND = Layout.HOLD_AWAIT_COMMAND;
    public static final int HOLD_REFERENCE = Layout.HOLD_REFERENCE;
    /** Detail of HOLD_REFERENCE: the newest reference value was rejected (arflex_hold_reference_detail). */
    public static final int HOLD_REF_INVALID = Layout.HOLD_REF_INVALID;
    // config (struct arflex_ctl_config at 64)
    public static final int OFF_CONFIG = Layout.OFF_CTL_CONFIG;
    public static final int OFF_CFG_PERIOD = Layout.OFF_CTL_CONFIG_PERIOD_NS;
    public static final int OFF_CFG_DEADLINE = Layout.OFF_CTL_CONFIG_DEADLINE_NS;
    public static final int OFF_CFG_HB_TIMEOUT = Layout.OFF_CTL_CONFIG_HB_TIMEOUT_NS;
    public static final int OFF_CFG_CPU_MASK = Layout.OFF_CTL_CONFIG_CPU_MASK;
    public static final int OFF_CFG_PRIORITY = Layout.OFF_CTL_CONFIG_PRIORITY;
    public static final int OFF_CFG_TASK_TYPE = Layout.OFF_CTL_CONFIG_TASK_TYPE;
    public static final int OFF_CFG_SAFE_MODE = Layout.OFF_CTL_CONFIG_SAFE_MODE;
    public static final int OFF_CFG_FLAGS = Layout.OFF_CTL_CONFIG_CFG_FLAGS;
    public static final int OFF_CFG_PARAM_COUNT = Layout.OFF_CTL_CONFIG_PARAM_COUNT;
    /** config.orphan_hold_ns (ABI 1.1, ABI.md 6.2). */
    public static final int OFF_CFG_ORPHAN_HOLD = Layout.OFF_CTL_CONFIG_ORPHAN_HOLD_NS;
    public static final int OFF_WARNINGS = Layout.OFF_CTL_WARNINGS;
    public static final int WARN_KINDS = Layout.WARN_KINDS;
    /** enum arflex_warn_kind ARFLEX_WARN_FORGED: mailbox requests with a wrong token ignored. */
    public static final int WARN_FORGED = Layout.WARN_FORGED;
    // stats (struct arflex_stats at 256)
    public static final int OFF_STATS = Layout.OFF_CTL_STATS;
    public static final int OFF_STATS_SEQ = Layout.OFF_CTL_STATS_SEQ;
    public static final int OFF_STATS_CYCLES = Layout.OFF_CTL_STATS_CYCLES;
    public static final int OFF_STATS_OVERRUNS = Layout.OFF_CTL_STATS_OVERRUNS;
    public static final int OFF_STATS_MISSED = Layout.OFF_CTL_STATS_MISSED_PERIODS;
    public static final int OFF_STATS_DEADLINE_MISSES = Layout.OFF_CTL_STATS_DEADLINE_MISSES;
    public static final int OFF_STATS_UPDATE_ERRORS = Layout.OFF_CTL_STATS_UPDATE_ERRORS;
    public static final int OFF_STATS_SAFE_CYCLES = Layout.OFF_CTL_STATS_SAFE_CYCLES;
    public static final int OFF_STATS_LAST_RELEASE = Layout.OFF_CTL_STATS_LAST_RELEASE_NS;
    public static final int OFF_STATS_LATENCY = Layout.OFF_CTL_STATS_LATENCY;
    public static final int METRIC_SIZE = Layout.SIZEOF_METRIC;
    public static final int OFF_STATS_EXEC = Layout.OFF_CTL_STATS_EXEC;
    // within struct arflex_metric
    public static final int METRIC_COUNT = Layout.OFF_METRIC_COUNT;
    public static final int METRIC_MIN = Layout.OFF_METRIC_MIN_NS;
    public static final int METRIC_MAX = Layout.OFF_METRIC_MAX_NS;
    public static final int METRIC_SUM = Layout.OFF_METRIC_SUM_NS;
    public static final int METRIC_HIST = Layout.OFF_METRIC_HIST;
    public static final int HIST_BIN_NS = Layout.HIST_BIN_NS;
    public static final int HIST_BINS = Layout.HIST_BINS;
    // parameters
    public static final int OFF_PARAMS = Layout.OFF_CTL_PARAMS;
    /** ABI 1.2: rejected values per input, 16 slots of (uint32 name hash, uint32 count). */
    public static final int OFF_INPUTS = Layout.OFF_CTL_INPUTS;
    public static final int INPUT_SLOTS = Layout.CTL_INPUTS;
    public static final int PARAM_SLOTS = Layout.PARAM_SLOTS;
    public static final int SLOT_SIZE = Layout.SIZEOF_PARAM_SLOT;
    public static final int SLOT_NAME = Layout.OFF_PARAM_SLOT_NAME;
    public static final int NAME_SIZE = Layout.NAME_SIZE;
    public static final int SLOT_TYPE = Layout.OFF_PARAM_SLOT_TYPE;
    public static final int SLOT_FLAGS = Layout.OFF_PARAM_SLOT_FLAGS;
    public static final int SLOT_MIN = Layout.OFF_PARAM_SLOT_MIN_BITS;
    public static final int SLOT_MAX = Layout.OFF_PARAM_SLOT_MAX_BITS;
    public static final int SLOT_DEFAULT = Layout.OFF_PARAM_SLOT_DEFAULT_BITS;
    public static final int SLOT_REQ_SEQ = Layout.OFF_PARAM_SLOT_REQ_SEQ;
    public static final int SLOT_REQ_VALUE = Layout.OFF_PARAM_SLOT_REQ_VALUE;
    public static final int SLOT_APPLIED_SEQ = Layout.OFF_PARAM_SLOT_APPLIED_SEQ;
    public static final int SLOT_APPLIED_VALUE = Layout.OFF_PARAM_SLOT_APPLIED_VALUE;
    public static final int SLOT_APPLIED_STATUS = Layout.OFF_PARAM_SLOT_APPLIED_STATUS;

    // enum arflex_rt_state
    public static final int STATE_CREATED = Layout.STATE_CREATED;
    public static final int STATE_CONFIGURING = Layout.STATE_CONFIGURING;
    public static final int STATE_READY = Layout.STATE_READY;
    public static final int STATE_RUNNING = Layout.STATE_RUNNING;
    public static final int STATE_STOPPING = Layout.STATE_STOPPING;
    public static final int STATE_EXITED = Layout.STATE_EXITED;
    public static final int STATE_FAILED = Layout.STATE_FAILED;
    private static final String[] STATE_NAMES = {"CREATED", "CONFIGURING", "READY", "RUNNING", "STOPPING", "EXITED", "FAILED"};

    // flags / cfg flags / enums
    public static final int FLAG_SCHED_FIFO = Layout.FLAG_SCHED_FIFO;
    public static final int FLAG_MLOCKALL = Layout.FLAG_MLOCKALL;
    public static final int FLAG_SAFE_ACTIVE = Layout.FLAG_SAFE_ACTIVE;
    public static final int FLAG_RESET_REQUIRED = Layout.FLAG_RESET_REQUIRED;
    /** The RT half saw EOF on its supervisor pipe (fd 0): it is an orphan (ABI.md 6.2). */
    public static final int FLAG_SUPERVISOR_LOST = Layout.FLAG_SUPERVISOR_LOST;
    /** D70: the half registered a re-adopt hook: it can take a state block again while it runs (READOPT). */
    public static final int FLAG_READOPT = Layout.FLAG_READOPT;
    public static final int CFG_MOVES_HARDWARE = Layout.CFG_MOVES_HARDWARE;
    public static final int CFG_NO_MLOCK = Layout.CFG_NO_MLOCK;
    public static final int CFG_NO_DMA_LATENCY = Layout.CFG_NO_DMA_LATENCY;
    /** fd 0 of the RT half is a pipe the supervisor holds open for the half's life (ABI.md 6.2). */
    public static final int CFG_SUPERVISOR_PIPE = Layout.CFG_SUPERVISOR_PIPE;
    /** The contract's default {@code fault/@orphanHold}. */
    public static final long DEFAULT_ORPHAN_HOLD_NS = 2_000_000_000L;
    public static final int PARAM_BOOL = Layout.PARAM_BOOL;
    public static final int PARAM_INT64 = Layout.PARAM_INT64;
    public static final int PARAM_DOUBLE = Layout.PARAM_DOUBLE;
    public static final int PARAM_MUTABLE = Layout.PARAM_MUTABLE;

    /**
     * Configuration written before spawn. {@code orphanHoldNs}: how long an RT half that lost its
     * supervisor holds its safe outputs before it exits and removes its objects (ABI.md 6.2).
     */
    public record Config(long periodNs, long deadlineNs, long hbTimeoutNs, long cpuMask, int priority,
                         int taskType, int safeMode, int cfgFlags, long orphanHoldNs) {

        /** With the contract's default orphan hold (2 s). */
        public Config(long periodNs, long deadlineNs, long hbTimeoutNs, long cpuMask, int priority,
                      int taskType, int safeMode, int cfgFlags) {
            this(periodNs, deadlineNs, hbTimeoutNs, cpuMask, priority, taskType, safeMode, cfgFlags,
                    DEFAULT_ORPHAN_HOLD_NS);
        }

        /** This configuration with {@link #CFG_SUPERVISOR_PIPE} set. */
        public Config withSupervisorPipe() {
            return new Config(periodNs, deadlineNs, hbTimeoutNs, cpuMask, priority, taskType, safeMode,
                    cfgFlags | CFG_SUPERVISOR_PIPE, orphanHoldNs);
        }
    }

    /** A parameter descriptor written before spawn. */
    public record Param(String name, int type, boolean mutable, long minBits, long maxBits, long defaultBits) {
    }

    /** A consistent copy of the statistics counters. */
    public record Stats(long cycles, long overruns, long deadlineMisses, long safeCycles, long latencyMaxNs,
                        long execMaxNs, long execCount, long execSumNs, long execOverWcet, long updateErrors) {
    }

    /**
     * A consistent copy of one metric (struct arflex_metric): sample count, min (UINT64_MAX,
     * i.e. -1 here, while empty), max, sum, and the histogram: {@code bins[i]} counts samples in
     * [i*100 ns, (i+1)*100 ns) for i &lt; 2000, {@code bins[2000]} samples of 200 us or more.
     */
    public record Metric(long count, long minNs, long maxNs, long sumNs, long[] bins) {

        /**
         * Percentile {@code p} (0 &lt; p &lt; 100) in ns as arflex_metric_percentile() computes it:
         * upper edge of the bin holding the ceil(total*p/100)-th sample, capped at the max; the
         * max for the overflow bin; 0 when empty.
         */
        public long percentileNs(double p) {
            long total = 0;
            for (long b : bins) {
                total += b;
            }
            if (total == 0) {
                return 0;
            }
            long target = Math.max(1, (long) Math.ceil(total * p / 100.0));
            long acc = 0;
            for (int i = 0; i < HIST_BINS; i++) {
                acc += bins[i];
                if (acc >= target) {
                    long edge = (long) (i + 1) * HIST_BIN_NS;
                    return Long.compareUnsigned(edge, maxNs) < 0 ? edge : maxNs;
                }
            }
            return maxNs;
        }

        /** Samples of 200 us or more (the overflow bin). */
        public long overflow() {
            return bins[HIST_BINS];
        }
    }

    /** Counters and both metrics with their histograms, all from one seqlock read. */
    public record Detail(Stats stats, Metric latency, Metric exec) {
    }

    private final ShmSegment shm;

    private ControlBlock(ShmSegment shm) {
        this.shm = shm;
    }

    /**
     * Creates {@code name} (O_EXCL, 0600) and initialises it as arflex_ctl_format() does: header,
     * config, descriptors, applied values = defaults, metric minima = UINT64_MAX.
     */
    public static ControlBlock create(String name, Config cfg, List<Param> params) throws IOException {
        return create(name, cfg, params, false);
    }

    /**
     * As {@link #create(String, Config, List)}; {@code resetRequired} sets
     * ARFLEX_FLAG_RESET_REQUIRED before the spawn (a restarted component that moves hardware).
     */
    public static ControlBlock create(String name, Config cfg, List<Param> params, boolean resetRequired)
            throws IOException {
        if (params.size() > PARAM_SLOTS) {
            throw new IOException("control block " + name + ": " + params.size() + " parameters, at most " + PARAM_SLOTS);
        }
        ShmSegment s = ShmSegment.create(name, SIZE);
        try {
            s.buffer().putShort(OFF_ABI_MAJOR, (short) ABI_MAJOR);
            s.buffer().putShort(OFF_ABI_MINOR, (short) ABI_MINOR);
            s.putInt(OFF_HEADER_SIZE, OFF_STATS);
            s.putLong(OFF_SIZE, SIZE);
            s.putLong(OFF_CFG_PERIOD, cfg.periodNs());
            s.putLong(OFF_CFG_DEADLINE, cfg.deadlineNs());
            s.putLong(OFF_CFG_HB_TIMEOUT, cfg.hbTimeoutNs());
            s.putLong(OFF_CFG_CPU_MASK, cfg.cpuMask());
            s.putInt(OFF_CFG_PRIORITY, cfg.priority());
            s.putInt(OFF_CFG_TASK_TYPE, cfg.taskType());
            s.putInt(OFF_CFG_SAFE_MODE, cfg.safeMode());
            s.putInt(OFF_CFG_FLAGS, cfg.cfgFlags());
            s.putInt(OFF_CFG_PARAM_COUNT, params.size());
            s.putLong(OFF_CFG_ORPHAN_HOLD, cfg.orphanHoldNs());
            for (int m : new int[] {OFF_STATS_LATENCY, OFF_STATS_EXEC}) {
                s.putLong(m + METRIC_MIN, -1L);
            }
            for (int i = 0; i < params.size(); i++) {
                Param p = params.get(i);
                int o = OFF_PARAMS + i * SLOT_SIZE;
                s.putString(o + SLOT_NAME, NAME_SIZE, p.name());
                s.putInt(o + SLOT_TYPE, p.type());
                s.putInt(o + SLOT_FLAGS, p.mutable() ? PARAM_MUTABLE : 0);
                s.putLong(o + SLOT_MIN, p.minBits());
                s.putLong(o + SLOT_MAX, p.maxBits());
                s.putLong(o + SLOT_DEFAULT, p.defaultBits());
                s.putLong(o + SLOT_APPLIED_VALUE, p.defaultBits());
            }
            if (resetRequired) {
                // control.h: before the spawn the manager may set RESET_REQUIRED.
                s.putInt(OFF_FLAGS, FLAG_RESET_REQUIRED);
            }
            // ABI.md 6.1: magic last (release), then the runtime heartbeat.
            s.setLongRelease(OFF_MAGIC, MAGIC);
            s.setLongRelease(OFF_RUNTIME_HB, Posix.monotonicNs());
            // from now on the native writer (if running) keeps the runtime heartbeat fresh
            NativeHeartbeat.register(s.address());
            return new ControlBlock(s);
        } catch (RuntimeException e) {
            s.unlink();
            s.close();
            throw new IOException("control block " + name + ": " + e.getMessage(), e);
        }
    }

    public String name() {
        return shm.name();
    }

    /** The RT half's state word. */
    public int state() {
        return shm.getIntAcquire(OFF_STATE);
    }

    /** Name of a state value. */
    public static String stateName(int s) {
        return s >= 0 && s < STATE_NAMES.length ? STATE_NAMES[s] : "UNKNOWN(" + s + ")";
    }

    public int flags() {
        return shm.getIntAcquire(OFF_FLAGS);
    }

    /** The hold word (0: the component does not hold the arm by itself). */
    public int hold() {
        return shm.getIntAcquire(OFF_HOLD);
    }

    /**
     * Rejected values per input (ABI 1.2), as the RT half counted them in this run: input name
     * (the names the RT half declared; those of {@code names} whose hash matches a slot) to count.
     */
    public java.util.Map<String, Long> inputRejects(java.util.Collection<String> names) {
        java.util.Map<String, Long> out = new java.util.TreeMap<>();
        for (String n : names) {
            int hash = inputHash(n);
            for (int k = 0; k < INPUT_SLOTS; k++) {
                int at = OFF_INPUTS + Layout.SIZEOF_INPUT_COUNT * k;
                if (shm.getIntAcquire(at + Layout.OFF_INPUT_COUNT_NAME_HASH) == hash) {
                    out.put(n, Integer.toUnsignedLong(shm.getIntAcquire(at + Layout.OFF_INPUT_COUNT_REJECTS)));
                    break;
                }
            }
        }
        return out;
    }

    /** The name hash of an input's count slot: the low 32 bits of FNV-1a 64 of its name. */
    public static int inputHash(String name) {
        return (int) PortSegment.typeHash(name);
    }

    /** The configuration as written in the block (read-only after the spawn). */
    public Config config() {
        return new Config(shm.getLong(OFF_CFG_PERIOD), shm.getLong(OFF_CFG_DEADLINE), shm.getLong(OFF_CFG_HB_TIMEOUT),
                shm.getLong(OFF_CFG_CPU_MASK), shm.getInt(OFF_CFG_PRIORITY), shm.getInt(OFF_CFG_TASK_TYPE),
                shm.getInt(OFF_CFG_SAFE_MODE), shm.getInt(OFF_CFG_FLAGS), shm.getLong(OFF_CFG_ORPHAN_HOLD));
    }

    public int pid() {
        return shm.getIntAcquire(OFF_PID);
    }

    public int exitStatus() {
        return shm.getIntAcquire(OFF_EXIT_STATUS);
    }

    /** The RT thread's heartbeat (CLOCK_MONOTONIC ns), 0 before its first cycle. */
    public long rtHeartbeatNs() {
        return shm.getLongAcquire(OFF_RT_HB);
    }

    /** Writes the manager heartbeat. */
    public void runtimeHeartbeat(long nowNs) {
        shm.setLongRelease(OFF_RUNTIME_HB, nowNs);
    }

    public long warnings(int kind) {
        return shm.getLongAcquire(OFF_WARNINGS + 8 * kind);
    }

    /**
     * Reads the statistics under the seqlock; the WCET overrun count comes from the execution
     * time histogram (samples in bins whose lower edge is at or above {@code wcetNs}).
     */
    public Stats stats(long wcetNs) {
        for (int attempt = 0; attempt < 1000; attempt++) {
            long s1 = shm.getLongAcquire(OFF_STATS_SEQ);
            if ((s1 & 1) != 0) {
                Thread.onSpinWait();
                continue;
            }
            long cycles = shm.getLong(OFF_STATS_CYCLES);
            long overruns = shm.getLong(OFF_STATS_OVERRUNS);
            long dl = shm.getLong(OFF_STATS_DEADLINE_MISSES);
            long safe = shm.getLong(OFF_STATS_SAFE_CYCLES);
            long errors = shm.getLong(OFF_STATS_UPDATE_ERRORS);
            long latMax = shm.getLong(OFF_STATS_LATENCY + METRIC_MAX);
            long exMax = shm.getLong(OFF_STATS_EXEC + METRIC_MAX);
            long exCount = shm.getLong(OFF_STATS_EXEC + METRIC_COUNT);
            long exSum = shm.getLong(OFF_STATS_EXEC + METRIC_SUM);
            long over = 0;
            int firstBin = (int) Math.min(HIST_BINS, Math.max(0, (wcetNs + HIST_BIN_NS - 1) / HIST_BIN_NS));
            for (int b = firstBin; b <= HIST_BINS; b++) {
                over += shm.getLong(OFF_STATS_EXEC + METRIC_HIST + 8 * b);
            }
            VarHandleFence.acquire();
            long s2 = shm.getLongAcquire(OFF_STATS_SEQ);
            if (s1 == s2) {
                return new Stats(cycles, overruns, dl, safe, latMax, exMax, exCount, exSum, over, errors);
            }
        }
        return null;
    }

    /**
     * As {@link #stats(long)} plus copies of the latency and execution-time metrics with their
     * histograms, all under one seqlock read (ABI.md 3.1); null when no consistent copy was
     * obtained in 1000 attempts.
     */
    public Detail detail(long wcetNs) {
        long[] lat = new long[HIST_BINS + 1];
        long[] ex = new long[HIST_BINS + 1];
        int firstBin = (int) Math.min(HIST_BINS, Math.max(0, (wcetNs + HIST_BIN_NS - 1) / HIST_BIN_NS));
        for (int attempt = 0; attempt < 1000; attempt++) {
            long s1 = shm.getLongAcquire(OFF_STATS_SEQ);
            if ((s1 & 1) != 0) {
                Thread.onSpinWait();
                continue;
            }
            long cycles = shm.getLong(OFF_STATS_CYCLES);
            long overruns = shm.getLong(OFF_STATS_OVERRUNS);
            long dl = shm.getLong(OFF_STATS_DEADLINE_MISSES);
            long safe = shm.getLong(OFF_STATS_SAFE_CYCLES);
            long errors = shm.getLong(OFF_STATS_UPDATE_ERRORS);
            long[] lm = readMetricScalars(OFF_STATS_LATENCY);
            long[] em = readMetricScalars(OFF_STATS_EXEC);
            for (int b = 0; b <= HIST_BINS; b++) {
                lat[b] = shm.getLong(OFF_STATS_LATENCY + METRIC_HIST + 8 * b);
                ex[b] = shm.getLong(OFF_STATS_EXEC + METRIC_HIST + 8 * b);
            }
            VarHandleFence.acquire();
            long s2 = shm.getLongAcquire(OFF_STATS_SEQ);
            if (s1 == s2) {
                long over = 0;
                for (int b = firstBin; b <= HIST_BINS; b++) {
                    over += ex[b];
                }
                Stats st = new Stats(cycles, overruns, dl, safe, lm[2], em[2], em[0], em[3], over, errors);
                return new Detail(st, new Metric(lm[0], lm[1], lm[2], lm[3], lat), new Metric(em[0], em[1], em[2], em[3], ex));
            }
        }
        return null;
    }

    private long[] readMetricScalars(int off) {
        return new long[] {shm.getLong(off + METRIC_COUNT), shm.getLong(off + METRIC_MIN), shm.getLong(off + METRIC_MAX),
            shm.getLong(off + METRIC_SUM)};
    }

    /** Index of the named parameter, or -1. */
    public int paramIndex(String name) {
        int n = shm.getInt(OFF_CFG_PARAM_COUNT);
        for (int i = 0; i < n; i++) {
            if (shm.getString(OFF_PARAMS + i * SLOT_SIZE + SLOT_NAME, NAME_SIZE).equals(name)) {
                return i;
            }
        }
        return -1;
    }

    /** The value in force of slot {@code idx}. */
    public long paramValue(int idx) {
        return shm.getLongAcquire(OFF_PARAMS + idx * SLOT_SIZE + SLOT_APPLIED_VALUE);
    }

    public long paramAppliedSeq(int idx) {
        return shm.getLongAcquire(OFF_PARAMS + idx * SLOT_SIZE + SLOT_APPLIED_SEQ);
    }

    public int paramAppliedStatus(int idx) {
        return shm.getIntAcquire(OFF_PARAMS + idx * SLOT_SIZE + SLOT_APPLIED_STATUS);
    }

    /**
     * Posts a request for slot {@code idx} (the manager is the only requester of a slot):
     * req_seq+1 (odd), value, req_seq+2 (even, release).
     *
     * @return the even sequence the RT half echoes in applied_seq once handled
     */
    public long requestParam(int idx, long bits) {
        int o = OFF_PARAMS + idx * SLOT_SIZE;
        long seq = shm.getLongAcquire(o + SLOT_REQ_SEQ);
        shm.setLongRelease(o + SLOT_REQ_SEQ, seq + 1);
        shm.setLongRelease(o + SLOT_REQ_VALUE, bits);
        shm.setLongRelease(o + SLOT_REQ_SEQ, seq + 2);
        return seq + 2;
    }

    /**
     * Removes the object and unmaps it, once the native heartbeat writer no longer touches it
     * (if a round of the writer did not end within its deadline the mapping is left in place:
     * a few kilobytes kept is better than a write into unmapped memory).
     */
    @Override
    public void close() {
        shm.unlink();
        if (NativeHeartbeat.unregister(shm.address())) {
            shm.close();
        }
    }

    /** Exposes the segment to other ABI classes and tests. */
    public ShmSegment segment() {
        return shm;
    }

    private static final class VarHandleFence {
        static void acquire() {
            java.lang.invoke.VarHandle.acquireFence();
        }
    }
}
