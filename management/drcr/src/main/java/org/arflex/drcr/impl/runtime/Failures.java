package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.List;
import java.util.function.Consumer;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RestartPolicy;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;

/**
 * Failure handling, on the actor thread: an unexpected exit of an RT half (crash, kill, hang)
 * or a failed start blocks the component in the planner (its dependents stop as if the provider
 * were gone), then the restart policy either schedules an unblock after the backoff or leaves
 * it blocked as FAILED, until an operator reset.
 */
final class Failures {

    private final Cell cell;
    private final Consumer<Plan> execute;
    private final Consumer<String> log;

    /** @param execute executes a plan of the planner ({@link PlanExecutor#execute}) */
    /** Sees an exit first: true when it handled it (an update's rollback window, D38). */
    interface Intercept {
        boolean exited(Instance inst, RtHalf half, RtHalf.Exit exit);
    }

    private final Intercept intercept;

    Failures(Cell cell, Consumer<Plan> execute, Consumer<String> log) {
        this(cell, execute, log, (i, h, e) -> false);
    }

    Failures(Cell cell, Consumer<Plan> execute, Consumer<String> log, Intercept intercept) {
        this.intercept = intercept;
        this.cell = cell;
        this.execute = execute;
        this.log = log;
    }

    /** The heartbeat monitor saw a half hang: kill it; its exit is handled by {@link #onExit}. */
    void onHang(RtHalf half, String why) {
        for (Instance inst : cell.instances()) {
            if (inst.half == half) {
                log.accept("arflex: " + inst.name + ": " + why + "; killing pid " + half.pid());
                inst.hangReason = why;
                half.kill();
            }
        }
    }

    /** A half exited; ignored when it was stopped in order (detached before). */
    void onExit(Instance inst, RtHalf half, RtHalf.Exit exit) {
        cell.actor().checkThread();
        if (inst.half != half) {
            return; // an orderly stop, already handled
        }
        if (intercept.exited(inst, half, exit)) {
            return; // rolled back to the version it ran before (D38)
        }
        inst.half = null;
        cell.monitor().unwatch(half);
        half.cleanup();
        inst.bound.clear();
        inst.cpu = -1;
        String what = inst.hangReason != null ? inst.hangReason : exit.description();
        inst.hangReason = null;
        log.accept(String.format(java.util.Locale.ROOT, "arflex: %s (pid %d) %s (handled %.1f ms after the exit was seen)",
                inst.name, half.pid(), what, (System.nanoTime() - exit.seenNanos()) / 1e6));
        OutputRepair.dropDamaged(inst.name, inst.outputs, log);
        failed(inst, exit.abnormal(), "RT half " + what);
        cell.changed();
    }

    /** The restart policy decides after a crash, hang or failed start. */
    void failed(Instance inst, boolean abnormal, String what) {
        RestartPolicy.Decision d = inst.policy.onExit(abnormal, what);
        if (d.restart()) {
            inst.restarts++;
            String why = "restarting in " + d.delayMs() + " ms (" + d.reason() + ")";
            inst.life.to(State.UNSATISFIED, why);
            execute.accept(cell.planner().apply(Change.block(inst.name, why)));
            inst.life.reason(why);
            cancelRestart(inst);
            inst.restartTimer = cell.actor().schedule(() -> {
                inst.restartTimer = null;
                if (cell.find(inst.name) == inst && inst.life.state() != State.FAILED) {
                    inst.life.reason("restarting");
                    execute.accept(cell.planner().apply(Change.unblock(inst.name)));
                    cell.changed();
                }
            }, d.delayMs());
        } else {
            inst.life.to(State.FAILED, d.reason());
            execute.accept(cell.planner().apply(Change.block(inst.name, "failed: " + d.reason())));
        }
    }

    /** A scheduled restart is off (the instance goes). */
    void cancelRestart(Instance inst) {
        if (inst.restartTimer != null) {
            inst.restartTimer.cancel();
            inst.restartTimer = null;
        }
    }

    /**
     * Operator reset: a FAILED instance gets a new chance; a running one that moves hardware is
     * allowed to drive outputs again (RESET command).
     */
    String reset(Instance inst) {
        String name = inst.name;
        if (inst.life.state() == State.FAILED) {
            List<String> repaired = OutputRepair.dropDamaged(name, inst.outputs, log);
            inst.policy.reset();
            inst.life.to(State.UNSATISFIED, "reset by operator");
            execute.accept(cell.planner().apply(Change.unblock(name)));
            cell.changed();
            return name + ": reset from FAILED, now " + inst.life.state() + (repaired.isEmpty() ? ""
                    : "; " + String.join("; ", repaired));
        }
        RtHalf half = inst.half;
        if (half == null) {
            return name + ": nothing to reset (" + inst.life.state() + ")";
        }
        try {
            half.reset();
        } catch (IOException e) {
            String why = Holding.reason(cell, inst, half.flags(), half.hold(), true);
            throw new IllegalStateException(name + ": reset refused, the cause persists: "
                    + (why != null ? why : e.getMessage()) + " (" + e.getMessage() + ")");
        }
        inst.awaitingReset = false;
        if (inst.life.state() == State.ACTIVE) {
            inst.life.reason(null);
        }
        cell.changed();
        return name + ": reset sent, outputs enabled";
    }
}
