package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.locks.LockSupport;
import java.util.function.BooleanSupplier;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;

/**
 * A cell on the steppable actor with real stop threads and, when asked, real launch threads
 * (issue 17: what runs off the actor). Tests step the actor until a condition holds, with a
 * deadline, and end with {@link #close}, which checks that nothing was left behind. Its helpers
 * install, apply a change set, let the actor's timers fire and find the fake's events, as the
 * cell tests do; {@link UpdateRig} is the cell of the update tests on it.
 */
class SteppedCell implements AutoCloseable {

    final ManualActor actor = new ManualActor();
    final FakeLauncher fake;
    final List<String> log = java.util.Collections.synchronizedList(new ArrayList<>());
    final Cell cell;
    private final ExecutorService stopper = Executors.newCachedThreadPool();
    private final ExecutorService launches;

    /** @param launcher what spawns the halves (the fake, or a wrapper of it); threads: real launch threads */
    SteppedCell(FakeLauncher fake, RtLauncher launcher, boolean launchThreads) {
        this.fake = fake;
        this.launches = launchThreads ? Executors.newCachedThreadPool() : null;
        this.cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> 1_000_000_000L),
                actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add, stopper,
                launches != null ? launches : Runnable::run);
    }

    /** Installs {@code name} with CellTest's contract of {@code ports} and runs the actor. */
    void install(String name, String ports) throws Exception {
        Contract c = ContractParser.create(PortTypes.builtin()).parse(
                CellTest.contract(name, ports, CellTest.PERMANENT, false, 5, "50us"), "test.xml");
        assertTrue(actor.call(() -> cell.install(c, name.hashCode(), Path.of("/nonexistent/" + name)), 0), log::toString);
        actor.runAll();
    }

    /** Installs {@code c} and steps until it is ACTIVE. */
    void install(Contract c) {
        assertTrue(actor.call(() -> cell.install(c, c.name().hashCode(), Path.of("/nonexistent/" + c.name())), 0),
                log::toString);
        stepUntil(c.name() + " ACTIVE", () -> state(c.name()) == State.ACTIVE);
    }

    /** Applies {@code set} and steps until its outcome. */
    ChangeSetResult apply(ChangeSet set) {
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(set), 0);
        stepUntil("the change set's outcome", f::isDone);
        return f.join();
    }

    /** Lets a shadow run's look or a window's watch run: the actor's clock advances and its timers fire. */
    void look() {
        actor.advance(ChangeSetExecutor.WATCH_MS);
        actor.runAll();
    }

    /** Where {@code event} is in the fake's events; fails when it is not there. */
    int index(String event) {
        int i = fake.events.indexOf(event);
        assertTrue(i >= 0, "no event '" + event + "' in " + fake.events);
        return i;
    }

    /** The fake's events since {@code mark}. */
    List<String> since(int mark) {
        return fake.events.subList(mark, fake.events.size());
    }

    State state(String n) {
        return cell.instance(n).orElseThrow().life.state();
    }

    /** Steps the actor until {@code done} holds (other threads report through it), 10 s at most. */
    void stepUntil(String what, BooleanSupplier done) {
        long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(10);
        while (!done.getAsBoolean()) {
            assertTrue(System.nanoTime() - deadline < 0, "timed out waiting for " + what + "\n" + log + "\n" + fake.events);
            actor.runAll();
            LockSupport.parkNanos(1_000_000);
        }
    }

    /** Shuts the cell down, waits for every launch and stop to be recorded, checks nothing is left. */
    @Override
    public void close() {
        actor.call(() -> {
            cell.shutdownAll("test end");
            return null;
        }, 0);
        CompletableFuture<Void> all = cell.stopsDone();
        stepUntil("every launch and stop recorded", all::isDone);
        stopper.shutdownNow();
        if (launches != null) {
            launches.shutdownNow();
        }
        assertTrue(fake.running.isEmpty(), "RT halves left running: " + fake.running.keySet());
        assertTrue(fake.openOutputs.isEmpty(), "segments left: " + fake.openOutputs);
    }
}
