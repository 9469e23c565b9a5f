package org.arflex.drcr.impl.abi;

import java.io.IOException;
import java.util.List;

/**
 * The control block segment {@code /arflex.<rid>.<inst>.ctl}: Java side of
 * rt-core/include/arflex/control.h (struct arflex_ctl). The offsets below are that layout;
 * ControlBlockLayoutTest compiles a C program against the header and compares them.
 *
 * <p>Who writes what (control.h): the manager writes header, config and parameter descriptors
 * before the spawn, then only {@code runtime_hb_ns} and the parameter request words; everything
 * else belongs to the RT process.
 */
public final class ControlBlock implements AutoCloseable {

    public static final long MAGIC = 0x4C5443584C465241L; // "ARFLXCTL"
    public static final int ABI_MAJOR = 1;
    public static final int ABI_MINOR = 2;
    public static final int SIZE = 40960;

    // header
    public static final int OFF_MAGIC = 0;
    public static final int OFF_ABI_MAJOR = 8;
    public static final int OFF_ABI_MINOR = 10;
    public static final int OFF_HEADER_SIZE = 12;
    public static final int OFF_SIZE = 16;
    public static final int OFF_STATE = 24;
    public static final int OFF_FLAGS = 28;
    public static final int OFF_PID = 32;
    public static final int OFF_EXIT_STATUS = 36;
    public static final int OFF_RUNTIME_HB = 40;
    public static final int OFF_RT_HB = 48;
    /** ctl.hold (uint32): why the component holds the arm by itself; cause | detail << 8 | input << 16. */
    public static final int OFF_HOLD = 56;
    public static final int HOLD_NONE = 0;
    public static final int HOLD_SAFETY_INPUT = 1;
    public static final int HOLD_AWAIT_COMMAND = 2;
    public static final int HOLD_REFERENCE = 3;
    /** Detail of HOLD_REFERENCE: the newest reference value was rejected (arflex_hold_reference_detail). */
    public static final int HOLD_REF_INVALID = 1;
    // config (struct arflex_ctl_config at 64)
    public static final int OFF_CONFIG = 64;
    public static final int OFF_CFG_PERIOD = 64;
    public static final int OFF_CFG_DEADLINE = 72;
    public static final int OFF_CFG_HB_TIMEOUT = 80;
    public static final int OFF_CFG_CPU_MASK = 88;
    public static final int OFF_CFG_PRIORITY = 96;
    public static final int OFF_CFG_TASK_TYPE = 100;
    public static final int OFF_CFG_SAFE_MODE = 104;
    public static final int OFF_CFG_FLAGS = 108;
    public static final int OFF_CFG_PARAM_COUNT = 112;
    /** config.orphan_hold_ns (ABI 1.1, ABI.md 6.2). */
    public static final int OFF_CFG_ORPHAN_HOLD = 120;
    public static final int OFF_WARNINGS = 128;
    public static final int WARN_KINDS = 16;
    /** enum arflex_warn_kind ARFLEX_WARN_FORGED: mailbox requests with a wrong token ignored. */
    public static final int WARN_FORGED = 11;
    // stats (struct arflex_stats at 256)
    public static final int OFF_STATS = 256;
    public static final int OFF_STATS_SEQ = 256;
    public static final int OFF_STATS_CYCLES = 264;
    public static final int OFF_STATS_OVERRUNS = 272;
    public static final int OFF_STATS_MISSED = 280;
    public static final int OFF_STATS_DEADLINE_MISSES = 288;
    public static final int OFF_STATS_UPDATE_ERRORS = 296;
    public static final int OFF_STATS_SAFE_CYCLES = 304;
    public static final int OFF_STATS_LAST_RELEASE = 312;
    public static final int OFF_STATS_LATENCY = 320;
    public static final int METRIC_SIZE = 16128;
    public static final int OFF_STATS_EXEC = OFF_STATS_LATENCY + METRIC_SIZE;
    // within struct arflex_metric
    public static final int METRIC_COUNT = 0;
    public static final int METRIC_MIN = 8;
    public static final int METRIC_MAX = 16;
    public static final int METRIC_SUM = 24;
    public static final int METRIC_HIST = 64;
    public static final int HIST_BIN_NS = 100;
    public static final int HIST_BINS = 2000;
    // parameters
    public static final int OFF_PARAMS = 32576;
    /** ABI 1.2: rejected values per input, 16 slots of (uint32 name hash, uint32 count). */
    public static final int OFF_INPUTS = 40768;
    public static final int INPUT_SLOTS = 16;
    public static final int PARAM_SLOTS = 64;
    public static final int SLOT_SIZE = 128;
    public static final int SLOT_NAME = 0;
    public static final int NAME_SIZE = 32;
    public static final int SLOT_TYPE = 32;
    public static final int SLOT_FLAGS = 36;
    public static final int SLOT_MIN = 40;
    public static final int SLOT_MAX = 48;
    public static final int SLOT_DEFAULT = 56;
    public static final int SLOT_REQ_SEQ = 64;
    public static final int SLOT_REQ_VALUE = 72;
    public static final int SLOT_APPLIED_SEQ = 80;
    public static final int SLOT_APPLIED_VALUE = 88;
    public static final int SLOT_APPLIED_STATUS = 96;

    // enum arflex_rt_state
    public static final int STATE_CREATED = 0;
    public static final int STATE_CONFIGURING = 1;
    public static final int STATE_READY = 2;
    public static final int STATE_RUNNING = 3;
    public static final int STATE_STOPPING = 4;
    public static final int STATE_EXITED = 5;
    public static final int STATE_FAILED = 6;
    private static final String[] STATE_NAMES = {"CREATED", "CONFIGURING", "READY", "RUNNING", "STOPPING", "EXITED", "FAILED"};

    // flags / cfg flags / enums
    public static final int FLAG_SCHED_FIFO = 1;
    public static final int FLAG_MLOCKALL = 2;
    public static final int FLAG_SAFE_ACTIVE = 4;
    public static final int FLAG_RESET_REQUIRED = 8;
    /** The RT half saw EOF on its supervisor pipe (fd 0): it is an orphan (ABI.md 6.2). */
    public static final int FLAG_SUPERVISOR_LOST = 64;
    public static final int CFG_MOVES_HARDWARE = 1;
    public static final int CFG_NO_MLOCK = 2;
    public static final int CFG_NO_DMA_LATENCY = 4;
    /** fd 0 of the RT half is a pipe the supervisor holds open for the half's life (ABI.md 6.2). */
    public static final int CFG_SUPERVISOR_PIPE = 8;
    /** The contract's default {@code fault/@orphanHold}. */
    public static final long DEFAULT_ORPHAN_HOLD_NS = 2_000_000_000L;
    public static final int PARAM_BOOL = 1;
    public static final int PARAM_INT64 = 2;
    public static final int PARAM_DOUBLE = 3;
    public static final int PARAM_MUTABLE = 1;

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
                if (shm.getIntAcquire(OFF_INPUTS + 8 * k) == hash) {
                    out.put(n, Integer.toUnsignedLong(shm.getIntAcquire(OFF_INPUTS + 8 * k + 4)));
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
