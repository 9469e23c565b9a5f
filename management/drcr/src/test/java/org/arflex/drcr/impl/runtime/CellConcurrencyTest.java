package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import java.io.IOException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Map;
import java.util.Random;
import java.util.Set;
import java.util.TreeMap;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ConcurrentHashMap;
import java.util.concurrent.CyclicBarrier;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import java.util.concurrent.Future;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.atomic.AtomicInteger;
import java.util.concurrent.atomic.AtomicReferenceArray;
import java.util.concurrent.locks.LockSupport;
import java.util.function.BooleanSupplier;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.lifecycle.ThreadActor;
import org.arflex.drcr.impl.services.ResourceManagerImpl;
import org.arflex.drcr.impl.services.Services;
import org.arflex.drcr.impl.shell.Commands;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * Issue 17, concurrency: several threads (shell, console, extender, update service) fire mixed
 * requests at the same few components through the real paths (the real {@link ThreadActor},
 * real stop threads, {@link Services}, {@link Commands}, {@link ResourceManagerImpl}, the
 * extender's sequence of actor calls), with a fake launcher that detects overlapping RT halves of
 * one name. Every request gets an outcome naming the component and the reason, none hangs, RT
 * halves of one name never overlap and no command reaches a half that is being stopped, and the
 * cell ends consistent and still answers.
 */
class CellConcurrencyTest {

    private static final int THREADS = 6;
    private static final int REQUESTS_PER_THREAD = 120;
    private static final long DEADLINE_S = 30;
    private static final String[] NAMES = {"p", "c", "q"};
    private static final String FAULT = "restart=\"permanent\" intensity=\"2\" window=\"10s\" backoff=\"20ms\"";

    private final List<String> log = Collections.synchronizedList(new ArrayList<>());
    private final ThreadActor actor = new ThreadActor(log::add);
    private final FakeLauncher fake = new FakeLauncher();
    private final Tracking launcher = new Tracking();
    private final ExecutorService stopper = Executors.newCachedThreadPool();
    private final ExecutorService launches = Executors.newCachedThreadPool();
    private final Cell cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), System::nanoTime),
            actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add, stopper, launches);
    private final ResourceManagerImpl resources = new ResourceManagerImpl(cell, 1.0);
    private final Services services = new Services(cell, resources, null, null, null, log::add);
    private final Commands shell = new Commands(services, resources, services, services::management, null);

    /** What went wrong across threads (overlaps, commands to stopping halves, unclear answers). */
    private final List<String> violations = Collections.synchronizedList(new ArrayList<>());

    private static String xml(String name, int minor) {
        String ports = switch (name) {
            case "p" -> CellTest.PROVIDER_PORTS;
            case "q" -> CellTest.PROVIDER_PORTS.replace("\"y\"", "\"w\"");
            default -> CellTest.CONSUMER_PORTS.replace("\"prov\"", "\"p\"");
        };
        return CellTest.contract(name, ports, FAULT, false, name.equals("c") ? 3 : 5, "50us")
                .replace("version=\"1.0.0\"", "version=\"1." + minor + ".0\"");
    }

    private static Contract contract(String name, int minor) {
        try {
            return ContractParser.create(PortTypes.builtin()).parse(xml(name, minor), name + ".xml");
        } catch (Exception e) {
            throw new AssertionError(e);
        }
    }

    private static long bundle(String name) {
        return 100 + name.charAt(0);
    }

    // ---- a launcher that watches the RT halves of each name ---------------------------------

    /** One RT half as the cell sees it; commands after its shutdown began are violations. */
    private final class Watched implements RtHalf {
        final FakeLauncher.FakeHalf h;
        final String name;
        volatile boolean stopping;

        Watched(FakeLauncher.FakeHalf h) {
            this.h = h;
            this.name = h.inst;
        }

        private void command(String what) {
            if (!actor.inActor()) {
                violations.add(name + " (pid " + h.pid + "): " + what + " off the actor thread ("
                        + Thread.currentThread().getName() + ")");
            }
            if (stopping) {
                violations.add(name + " (pid " + h.pid + "): " + what + " after its shutdown began");
            }
        }

        @Override public long pid() { return h.pid(); }
        @Override public CompletableFuture<Exit> exit() { return h.exit(); }
        @Override public void bind(String port, String segment) { command("BIND"); h.bind(port, segment); }
        @Override public void unbind(String port) { h.unbind(port); }
        @Override public long cycles() { return h.cycles(); }
        @Override public boolean awaitCycles(long since, int n, long timeoutMs) { return h.awaitCycles(since, n, timeoutMs); }
        @Override public void start() throws java.io.IOException { command("START"); h.start(); }
        @Override public void reset() { command("RESET"); h.reset(); }
        @Override public long setParam(int index, long bits) { command("SET_PARAM"); return h.setParam(index, bits); }
        @Override public long paramValue(int index) { return h.paramValue(index); }
        @Override public int rtState() { return h.rtState(); }
        @Override public int flags() { return h.flags(); }
        @Override public long rtHeartbeatNs() { return h.rtHeartbeatNs(); }
        @Override public void runtimeHeartbeat(long nowNs) { h.runtimeHeartbeat(nowNs); }
        @Override public ControlBlock.Stats stats(long wcetNs) { return h.stats(wcetNs); }
        @Override public void kill() { h.kill(); }
        @Override public void cleanup() { h.cleanup(); }

        @Override
        public String shutdown(long deadlineMs, Runnable unanswered) {
            stopping = true;
            return h.shutdown(deadlineMs, unanswered);
        }
    }

    /**
     * Delegates to the fake launcher; a launch on the actor thread, or while an earlier half of the
     * name lives, is a violation.
     */
    private final class Tracking implements RtLauncher {
        /** Halves launched whose process has not exited, by name. */
        final Map<String, Set<Watched>> live = new ConcurrentHashMap<>();
        /** The newest half of each name (what a crash hits). */
        final Map<String, Watched> newest = new ConcurrentHashMap<>();
        final AtomicInteger launches = new AtomicInteger();

        @Override
        public RtHalf launch(Spec spec) throws IOException {
            String name = spec.instance();
            if (actor.inActor()) { // spawn and READY wait must never hold the actor (issue 17)
                violations.add(name + ": launched on the actor thread");
            }
            Set<Watched> alive = live.computeIfAbsent(name, k -> ConcurrentHashMap.newKeySet());
            if (!alive.isEmpty()) {
                violations.add(name + ": launched while an earlier RT half of it is alive: "
                        + alive.stream().map(w -> w.h.pid).toList());
            }
            Watched w = new Watched((FakeLauncher.FakeHalf) fake.launch(spec));
            alive.add(w);
            newest.put(name, w);
            launches.incrementAndGet();
            // runs inside complete(), before anything that depends on the exit (the stop's record)
            w.h.exit.whenComplete((x, t) -> alive.remove(w));
            return w;
        }

        @Override
        public Output createOutput(String segmentName, int method, String typeName, int major, int minor, int elemSize,
                                   int depth, int overflow) throws IOException {
            if (!actor.inActor()) {
                violations.add(segmentName + ": created off the actor thread");
            }
            if (fake.openOutputs.getOrDefault(segmentName, 0) > 0) {
                violations.add(segmentName + ": created while it is open");
            }
            return fake.createOutput(segmentName, method, typeName, major, minor, elemSize, depth, overflow);
        }
    }

    // ---- the requests, as the shell, the console and the extender make them ----------------

    private <T> T onActor(java.util.concurrent.Callable<T> c) {
        return actor.call(c, 60_000);
    }

    /** Felix stops a bundle (the extender's deactivate): uninstall, INSTALLED again, wait for the stops. */
    private String stopBundle(String name, Contract c) throws Exception {
        CompletableFuture<Void> settled = onActor(() -> {
            boolean planned = cell.instance(name).map(i -> i.planned).orElse(false);
            if (!planned) {
                return null;
            }
            CompletableFuture<Void> f = cell.uninstall(List.of(name), "bundle of " + name + " stopped");
            cell.register(c, bundle(name));
            return f;
        });
        if (settled == null) {
            return name + ": not started";
        }
        settled.get(DEADLINE_S, TimeUnit.SECONDS);
        return name + ": stopped";
    }

    private String request(Random rnd, String name) throws Exception {
        int minor = rnd.nextInt(3);
        Contract c = contract(name, minor);
        long b = bundle(name);
        switch (rnd.nextInt(12)) {
            case 0: // bundle installed (extender: read)
                return name + ": register " + onActor(() -> cell.register(c, b));
            case 1: // bundle started (extender: activate)
            case 2: {
                boolean ok = onActor(() -> cell.install(c, b, Path.of("/nonexistent/" + name)));
                return name + (ok ? ": installed" : ": install refused");
            }
            case 3: // bundle stopped (extender: deactivate)
                return stopBundle(name, onActor(() -> cell.instance(name).map(i -> i.contract).orElse(c)));
            case 4: { // bundle updated (extender on UPDATED: deactivate, forget, read, activate), one call each
                Contract old = onActor(() -> cell.instance(name).map(i -> i.contract).orElse(c));
                stopBundle(name, old);
                onActor(() -> {
                    cell.unregister(name, b);
                    return null;
                });
                onActor(() -> cell.register(c, b));
                boolean ok = onActor(() -> cell.install(c, b, Path.of("/nonexistent/" + name)));
                return name + (ok ? ": updated to " + c.version() : ": update refused");
            }
            case 5: // bundle uninstalled (extender: deactivate, forget)
                stopBundle(name, c);
                onActor(() -> {
                    cell.unregister(name, b);
                    return null;
                });
                return name + ": uninstalled";
            case 6:
                return shell.reset(name);
            case 7:
                return shell.set(name, rnd.nextInt(4) == 0 ? "mode" : "gain", Integer.toString(rnd.nextInt(25) - 12));
            case 8:
                return shell.get(name, rnd.nextBoolean() ? "gain" : "mode");
            case 9: // re-planning: the memory for two components or for all, one CPU or two
                if (rnd.nextBoolean()) {
                    resources.setMemory(rnd.nextBoolean() ? 2L << 20 : 1L << 30);
                } else {
                    resources.setCpus(rnd.nextBoolean() ? List.of(0) : List.of(0, 1));
                }
                return name + ": re-planned";
            case 10: // dry runs and reads, as the console
                services.cell();
                return services.planUninstall(name);
            default: { // the RT half of the name crashes
                Watched w = launcher.newest.get(name);
                if (w == null || w.h.exit.isDone()) {
                    return name + ": nothing to crash";
                }
                // the process is gone before anyone hears of it: not alive from here
                launcher.live.get(name).remove(w);
                w.h.crash(139, "killed by signal 11");
                return name + ": crashed";
            }
        }
    }

    /** An answer that is an error names the component and says why. */
    private void check(String name, String outcome) {
        if (outcome.startsWith("error:") || outcome.startsWith("exception:")) {
            // a parameter's type or range check names the parameter of the request (not the component)
            boolean named = outcome.contains("'" + name + "'") || outcome.contains(name + ":")
                    || outcome.contains(name + ".") || outcome.matches("error: (gain|mode): .* is out of range .*");
            boolean plain = outcome.startsWith("error:") || outcome.endsWith("(IllegalArgumentException)")
                    || outcome.endsWith("(IllegalStateException)");
            if (!named || !plain) {
                violations.add("unclear answer for " + name + ": " + outcome);
            }
        }
    }

    @Test
    void concurrentChurnNeverInterleavesNeverLosesAndEndsConsistent() throws Exception {
        long t0 = System.nanoTime();
        CyclicBarrier start = new CyclicBarrier(THREADS);
        ExecutorService workers = Executors.newFixedThreadPool(THREADS);
        Map<String, AtomicInteger> outcomes = new ConcurrentHashMap<>();
        AtomicInteger answered = new AtomicInteger();
        AtomicReferenceArray<String> current = new AtomicReferenceArray<>(THREADS);
        List<Future<?>> fs = new ArrayList<>();
        for (int t = 0; t < THREADS; t++) {
            int id = t;
            fs.add(workers.submit(() -> {
                Random rnd = new Random(17L * 31 + id);
                start.await(DEADLINE_S, TimeUnit.SECONDS);
                for (int i = 0; i < REQUESTS_PER_THREAD; i++) {
                    String name = NAMES[rnd.nextInt(NAMES.length)];
                    current.set(id, "request " + i + " on " + name);
                    String outcome;
                    try {
                        outcome = request(rnd, name);
                    } catch (Exception | AssertionError e) {
                        Throwable cause = e instanceof java.util.concurrent.ExecutionException ? e.getCause() : e;
                        outcome = "exception: " + cause.getMessage() + " (" + cause.getClass().getSimpleName() + ")";
                    }
                    assertNotNull(outcome);
                    check(name, outcome);
                    String kind = outcome.replaceAll("[-0-9.]+", "#");
                    outcomes.computeIfAbsent(kind.length() > 90 ? kind.substring(0, 90) : kind,
                            k -> new AtomicInteger()).incrementAndGet();
                    answered.incrementAndGet();
                }
                current.set(id, null);
                return null;
            }));
        }
        long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(DEADLINE_S);
        for (Future<?> f : fs) {
            try {
                f.get(Math.max(1, deadline - System.nanoTime()), TimeUnit.NANOSECONDS);
            } catch (java.util.concurrent.TimeoutException e) {
                workers.shutdownNow();
                fail("a request hung: " + current + "\n" + tail());
            }
        }
        workers.shutdown();
        assertEquals(THREADS * REQUESTS_PER_THREAD, answered.get(), "every request answered once");

        // Quiet: every stop recorded, no restart pending, no start waiting for an old half.
        resources.setMemory(1L << 30);
        resources.setCpus(List.of(0, 1));
        waitUntil("the cell settles", () -> onActor(() -> cell.stopsDone().isDone()
                && cell.instances().stream().allMatch(i -> i.restartTimer == null
                        && (i.life.reason() == null || !i.life.reason().contains("previous RT half")))));

        onActor(() -> {
            assertConsistent();
            return null;
        });
        if (!violations.isEmpty()) {
            java.nio.file.Files.write(Path.of("target/CellConcurrencyTest.log"), List.copyOf(log));
        }
        assertEquals(List.of(), violations, () -> "violations\n" + tail());
        assertTrue(log.stream().noneMatch(l -> l.contains("actor task failed") || l.contains("failed: java")
                || l.contains("refused transition")), this::tail);

        // The cell still answers every request: all three installed, reset where FAILED, all run.
        for (String n : NAMES) {
            assertTrue(onActor(() -> cell.install(contract(n, 2), bundle(n), Path.of("/nonexistent/" + n))), n);
            shell.reset(n);
        }
        waitUntil("all three ACTIVE", () -> onActor(() -> cell.instances().stream()
                .allMatch(i -> i.life.state() == State.ACTIVE) && cell.instances().size() == 3));
        assertEquals("p.gain = 3.0", shell.set("p", "gain", "3"));
        assertEquals("3.0", shell.get("p", "gain"));
        onActor(() -> {
            assertConsistent();
            return null;
        });
        assertEquals(List.of(), violations, () -> "violations\n" + tail());
        System.out.printf("CellConcurrencyTest: %d requests from %d threads, %d RT halves launched, %.1f s; outcomes %s%n",
                answered.get(), THREADS, launcher.launches.get(), (System.nanoTime() - t0) / 1e9, new TreeMap<>(outcomes));
    }

    /** The cell agrees with the processes and segments (actor thread). */
    private void assertConsistent() {
        Set<String> active = cell.planner().active();
        for (Instance i : cell.instances()) {
            State s = i.life.state();
            String what = i.name + " " + i.life + " half " + (i.half == null ? "-" : i.half.pid());
            assertTrue(s != State.DESTROYED, what);
            if (!i.planned) {
                assertEquals(State.INSTALLED, s, what);
                assertTrue(i.half == null, what);
            }
            if (i.half != null) {
                assertEquals(State.ACTIVE, s, what);
                Set<Watched> alive = launcher.live.getOrDefault(i.name, Set.of());
                assertTrue(alive.size() == 1 && alive.contains(i.half), what + "; alive " + alive);
                assertTrue(((Watched) i.half).h.started, what);
            } else {
                assertTrue(s != State.ACTIVE, what);
            }
            // wanted and not failed: running; running: wanted
            assertEquals(i.planned && active.contains(i.name) && s != State.FAILED, i.half != null,
                    what + "; planner active " + active);
        }
        // no RT half alive that the cell does not know
        for (var e : launcher.live.entrySet()) {
            for (Watched w : e.getValue()) {
                assertTrue(cell.find(e.getKey()) != null && cell.find(e.getKey()).half == w,
                        "leaked RT half " + e.getKey() + " pid " + w.h.pid);
            }
        }
        // segments only of components in the cell, each open once
        for (var e : fake.openOutputs.entrySet()) {
            assertEquals(1, e.getValue(), e.getKey());
            String owner = e.getKey().split("\\.")[2];
            assertNotNull(cell.find(owner), "segment of a component no longer in the cell: " + e.getKey());
        }
    }

    private void waitUntil(String what, BooleanSupplier done) {
        long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(DEADLINE_S);
        while (!done.getAsBoolean()) {
            assertTrue(System.nanoTime() - deadline < 0, () -> "timed out waiting for " + what + "\n" + tail()
                    + "\n" + onActor(() -> cell.instances().stream().map(i -> i.life + " planned " + i.planned + " half "
                    + i.half + " timer " + i.restartTimer).toList()) + "\nplanner active " + onActor(() -> cell.planner().active())
                    + " blocked " + onActor(() -> cell.planner().blocked()));
            LockSupport.parkNanos(2_000_000);
        }
    }

    private String tail() {
        synchronized (log) {
            return String.join("\n", log.subList(Math.max(0, log.size() - 60), log.size()));
        }
    }

    @AfterEach
    void nothingLeaks() {
        actor.call(() -> {
            cell.shutdownAll("test end");
            return null;
        }, 10_000);
        waitUntil("every stop recorded", () -> cell.stopsDone().isDone());
        actor.call(() -> null, 10_000);
        actor.shutdown(10_000);
        stopper.shutdownNow();
        launches.shutdownNow();
        assertTrue(launcher.live.values().stream().allMatch(Set::isEmpty), "RT halves left alive: " + launcher.live);
        assertTrue(fake.openOutputs.isEmpty(), "segments left: " + fake.openOutputs);
    }
}
