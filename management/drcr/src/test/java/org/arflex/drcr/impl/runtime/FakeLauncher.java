package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.concurrent.CompletableFuture;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/** An RT launcher without processes: records every command; tests end processes at will. */
final class FakeLauncher implements RtLauncher {

    /** Thread-safe: stops may run on a stop thread. */
    final List<String> events = java.util.Collections.synchronizedList(new ArrayList<>());
    final Map<String, FakeHalf> running = new java.util.concurrent.ConcurrentHashMap<>();
    /** Thread-safe too: launches may run on launch threads. */
    final List<Spec> specs = java.util.Collections.synchronizedList(new ArrayList<>());
    final Map<String, Integer> openOutputs = new HashMap<>();
    /** Segment name -> what damage() of its output reports (tests set it). */
    final Map<String, String> damaged = new HashMap<>();
    /** Segment name -> the newest value's payload its output reports (tests set it; none: never written). */
    final Map<String, byte[]> values = new java.util.concurrent.ConcurrentHashMap<>();
    /** Instance id -> why its ADOPT is refused (tests set it). */
    final Map<String, String> refuseAdopt = new java.util.concurrent.ConcurrentHashMap<>();
    /** Instance id -> why its READOPT is refused (D61; tests set it). */
    final Map<String, String> refuseReadopt = new java.util.concurrent.ConcurrentHashMap<>();
    /** Instances whose half registers no re-adopt hook (D70: no ControlBlock.FLAG_READOPT); tests set it. */
    final Set<String> noReadoptHook = java.util.concurrent.ConcurrentHashMap.newKeySet();
    /** Instances whose START is refused (the half died before it, say); tests set it. */
    final Set<String> refuseStart = java.util.concurrent.ConcurrentHashMap.newKeySet();
    /** Instances whose next launches fail. */
    final Map<String, Integer> failLaunches = new java.util.concurrent.ConcurrentHashMap<>();
    private final java.util.concurrent.atomic.AtomicLong nextPid = new java.util.concurrent.atomic.AtomicLong(1000);

    final class FakeHalf implements RtHalf {
        final String inst;
        final long pid = nextPid.getAndIncrement();
        final CompletableFuture<Exit> exit = new CompletableFuture<>();
        final long[] params;
        long rtHb;
        long runtimeHb;
        boolean started;
        /** Runs while the cell waits for this half's cycles (what happens meanwhile). */
        Runnable duringAwait = () -> { };
        /** Whether it answers STOP/SHUTDOWN; tests make it a frozen process. */
        boolean answers = true;
        /** Runs in a shutdown that went unanswered, before the kill ends it (a test blocks it). */
        Runnable untilKilled = () -> { };
        boolean cleaned;
        /** What flags() reports (control block flags); tests set it. */
        int flags;
        /** What hold() reports (the control block's hold word); tests set it. */
        int hold;
        /** What stats() reports; tests set it. */
        ControlBlock.Stats stats = new ControlBlock.Stats(0, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        /** The execution-time metric detail() reports with {@link #stats}, or null (no histogram). */
        ControlBlock.Metric exec;

        FakeHalf(Spec s) {
            inst = s.instance();
            params = s.params().stream().mapToLong(ControlBlock.Param::defaultBits).toArray();
        }

        @Override
        public long pid() {
            return pid;
        }

        @Override
        public CompletableFuture<Exit> exit() {
            return exit;
        }

        @Override
        public void bind(String port, String segment) {
            events.add(inst + " BIND " + port + " " + segment);
        }

        @Override
        public void unbind(String port) {
            events.add(inst + " UNBIND " + port);
        }

        @Override
        public void adopt(String stateSegment) throws IOException {
            String why = refuseAdopt.get(inst);
            events.add(inst + " ADOPT " + stateSegment + (why != null ? " (refused)" : ""));
            if (why != null) {
                throw new IOException(why);
            }
        }

        @Override
        public void readopt(String stateSegment) throws IOException {
            String why = refuseReadopt.get(inst);
            events.add(inst + " READOPT " + stateSegment + (why != null ? " (refused)" : ""));
            if (why != null) {
                throw new IOException(why);
            }
        }

        /** When set, a running rebind is answered by what this returns (a test holds it open). */
        java.util.function.Function<String, CompletableFuture<Void>> rebinds;

        @Override
        public CompletableFuture<Void> rebind(String port, String segment, long waitMs) {
            if (rebinds == null) {
                return RtHalf.super.rebind(port, segment, waitMs);
            }
            String what = (segment != null ? "BIND " : "UNBIND ") + port;
            events.add(inst + " " + what + " (unanswered)");
            return rebinds.apply(what);
        }

        @Override
        public long cycles() {
            return started ? 0 : -1;
        }

        @Override
        public boolean awaitCycles(long since, int n, long timeoutMs) {
            events.add(inst + " AWAIT " + n);
            duringAwait.run();
            return started;
        }

        @Override
        public void start() throws java.io.IOException {
            if (refuseStart.contains(inst)) {
                events.add(inst + " START refused");
                throw new java.io.IOException("START (seq 3): the RT half exited before it answered");
            }
            started = true;
            events.add(inst + " START");
        }

        @Override
        public void reset() {
            events.add(inst + " RESET");
        }

        @Override
        public long setParam(int index, long bits) {
            events.add(inst + " SET_PARAM " + index);
            params[index] = bits;
            return bits;
        }

        @Override
        public long paramValue(int index) {
            return params[index];
        }

        @Override
        public int rtState() {
            return started ? ControlBlock.STATE_RUNNING : ControlBlock.STATE_READY;
        }

        @Override
        public int flags() {
            return flags;
        }

        @Override
        public boolean canReadopt() { // a fake half has the hook unless the test says otherwise (D70)
            return !noReadoptHook.contains(inst);
        }

        @Override
        public int hold() {
            return hold;
        }

        @Override
        public long rtHeartbeatNs() {
            return rtHb;
        }

        @Override
        public void runtimeHeartbeat(long nowNs) {
            runtimeHb = nowNs;
        }

        @Override
        public ControlBlock.Stats stats(long wcetNs) {
            return stats;
        }

        @Override
        public ControlBlock.Detail detail(long wcetNs) {
            return new ControlBlock.Detail(stats, null, exec);
        }

        @Override
        public String shutdown(long deadlineMs, Runnable unanswered) {
            events.add(inst + " SHUTDOWN");
            boolean answered = answers;
            if (!answered) {
                unanswered.run();
                untilKilled.run();
                events.add(inst + " SIGKILL");
            }
            running.remove(inst);
            exit.complete(answered ? new Exit(0, false, "exited normally after SHUTDOWN")
                    : new Exit(137, true, "killed by signal 9"));
            cleanup();
            return answered ? "exited after SHUTDOWN in 0 ms" : "killed after " + deadlineMs + " ms (no answer to STOP)";
        }

        @Override
        public void kill() {
            events.add(inst + " SIGKILL");
            crash(137, "killed by signal 9");
        }

        /** Simulates an unexpected exit. */
        void crash(int status, String what) {
            running.remove(inst);
            exit.complete(new Exit(status, true, what));
        }

        @Override
        public void cleanup() {
            cleaned = true;
        }
    }

    @Override
    public RtHalf launch(Spec spec) throws IOException {
        specs.add(spec);
        int fails = failLaunches.getOrDefault(spec.instance(), 0);
        if (fails > 0) {
            failLaunches.put(spec.instance(), fails - 1);
            events.add(spec.instance() + " LAUNCH-FAILED");
            throw new IOException("RT half " + spec.instance() + " exited with status 4");
        }
        FakeHalf h = new FakeHalf(spec);
        running.put(spec.instance(), h);
        events.add(spec.instance() + " LAUNCH");
        return h;
    }

    @Override
    public Output createOutput(String segmentName, int method, String typeName, int major, int minor, int elemSize,
                               int depth, int overflow) {
        openOutputs.merge(segmentName, 1, Integer::sum);
        events.add("CREATE " + segmentName + " " + typeName + " " + elemSize);
        return new Output() {
            boolean closed;

            @Override
            public String name() {
                return segmentName;
            }

            @Override
            public long published() {
                return 0;
            }

            @Override
            public String damage() {
                return closed ? null : damaged.get(segmentName);
            }

            @Override
            public byte[] newest(String typeName, int bytes) {
                return values.get(segmentName);
            }

            @Override
            public void close() {
                if (!closed) {
                    closed = true;
                    openOutputs.merge(segmentName, -1, Integer::sum);
                    openOutputs.remove(segmentName, 0);
                }
            }
        };
    }
}
