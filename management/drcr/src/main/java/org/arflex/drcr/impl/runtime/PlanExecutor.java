package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.ArrayList;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeMap;
import java.util.function.Consumer;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Plan;
import org.arflex.planner.Wire;

/**
 * Executes the planner's plans on the actor thread: unbinds what a rewiring changes, detaches
 * the halves a plan stops and hands them to {@link Stops}, starts what it starts (in its start
 * order, with its CPU assignment and wiring; {@link Starter}), binds the new wiring, and shows the
 * planner's reason for everything left inactive. A start whose name's previous RT half is still
 * on its way out waits for it, and so do components bound to it.
 */
final class PlanExecutor {

    private final Cell cell;
    private final Stops stops;
    private final Segments segments;
    private final Starter starter;
    private final Consumer<String> log;
    /**
     * Components the planner wants running whose start waits until an earlier RT half of the
     * same name has exited (or until a provider they bind to has started), in start order.
     */
    private final Set<String> waiting = new LinkedHashSet<>();

    PlanExecutor(Cell cell, Stops stops, Segments segments, Starter starter, Consumer<String> log) {
        this.cell = cell;
        this.stops = stops;
        this.segments = segments;
        this.starter = starter;
        this.log = log;
    }

    void execute(Plan plan) {
        // Live rewiring: inputs whose provider changes or goes are unbound before any stop, so
        // no consumer reads a provider while it goes away; new bindings come after the starts,
        // when every provider's segment exists.
        List<Sent> unbinds = new ArrayList<>();
        for (Plan.Action a : plan.rewires()) {
            rebind(cell.find(a.component()), plan.wiringOf(a.component()), false, a.reason(), unbinds);
        }
        List<java.util.concurrent.CompletableFuture<Void>> unbinding = settle(unbinds);
        // The plan's stops in three sweeps, so that their waits overlap: every half to stop is
        // detached and its inputs unbound, then each is given its cycles to run its safe
        // behaviour (counted from the unbind, so the waits run side by side), then each is
        // stopped and shut down in the plan's stop order.
        // They run on a stop thread (Stops), so the actor is free for crashes and the shell
        // while a half that does not answer is terminated.
        List<Stops.Going> going = new ArrayList<>();
        for (String name : plan.stopOrder()) {
            Instance inst = cell.find(name);
            Stops.Going g = inst == null ? null : detach(inst, plan.inactiveAfter().getOrDefault(name,
                    plan.action(name).map(Plan.Action::reason).orElse("stopped by plan")));
            if (g != null) {
                going.add(g);
            }
        }
        stops.submit(going, unbinding);
        // A component whose previous half is still on its way out starts when it is gone (its
        // objects have the same names), and so does one bound to such a component.
        Set<String> later = new LinkedHashSet<>();
        for (String name : plan.startOrder()) {
            Instance inst = cell.find(name);
            if (inst != null && inst.half == null && (stops.pending(name) || waiting.contains(name) || starter.launching(name)
                    || plan.wiringOf(name).stream().anyMatch(w -> later.contains(w.provider())))) {
                later.add(name);
            }
        }
        for (String name : later) {
            waitFor(cell.find(name));
        }
        // Every output segment of every component about to start exists before the first one
        // starts: a member of a start group (a cycle) binds to its partners' outputs at once.
        // A failure here is reported by that component's own start below.
        for (String name : plan.startOrder()) {
            Instance inst = cell.find(name);
            if (inst != null && inst.half == null && !starter.launching(name) && !later.contains(name)) {
                try {
                    segments.ensure(inst);
                } catch (IOException | RuntimeException e) {
                    // Starter.start tries again and fails the component with this reason.
                }
            }
        }
        for (String name : plan.startOrder()) {
            Instance inst = cell.find(name);
            // A start that failed earlier in this loop blocked its component, and the nested
            // plan took its dependents out of the active set: ask the planner again.
            if (inst != null && inst.half == null && !starter.launching(name) && inst.life.state() != State.FAILED
                    && cell.planner().active().contains(name) && !later.contains(name)) {
                starter.start(inst, plan.cpuAssignment().getOrDefault(name, -1));
            }
        }
        List<Sent> binds = new ArrayList<>();
        for (Plan.Action a : plan.rewires()) {
            rebind(cell.find(a.component()), plan.wiringOf(a.component()).stream()
                    .filter(w -> !waiting.contains(w.provider())).toList(), true, a.reason(), binds);
        }
        settle(binds);
        // Everything the plan leaves inactive shows the planner's reason (a start that waited is
        // off when the planner no longer wants it).
        Set<String> activeNow = cell.planner().active();
        waiting.removeIf(n -> !activeNow.contains(n));
        for (var e : plan.inactiveAfter().entrySet()) {
            Instance inst = cell.find(e.getKey());
            if (inst != null && inst.half == null && inst.life.state() != State.FAILED
                    && inst.life.state() != State.DESTROYED && !waiting.contains(inst.name)) {
                if (inst.restartTimer == null || inst.life.reason() == null) {
                    inst.life.to(State.UNSATISFIED, e.getValue());
                }
            }
        }
    }

    /** A BIND or UNBIND sent to a running half, its answer not yet looked at. */
    private record Sent(Instance inst, RtHalf h, String port, String segment,
                        java.util.concurrent.CompletableFuture<Void> answer) {
    }

    /**
     * One phase of a REBIND: sends the UNBINDs (bindPhase false) of the inputs whose segment
     * changes or goes, or the BINDs (bindPhase true) of the inputs to their new segments, to
     * {@code inst}'s running half without waiting for its answers; {@link #settle} looks at them.
     * The RT half picks a binding up at a cycle boundary and keeps running.
     */
    private void rebind(Instance inst, List<Wire> wires, boolean bindPhase, String why, List<Sent> into) {
        if (inst == null || inst.half == null) {
            return;
        }
        Map<String, String> target = new TreeMap<>();
        for (Wire w : wires) {
            target.put(w.inPort(), segments.name(w.provider(), w.outPort()));
        }
        RtHalf h = inst.half;
        Map<String, String> changes = new TreeMap<>();
        if (!bindPhase) {
            for (String port : List.copyOf(inst.bound.keySet())) {
                if (!inst.bound.get(port).equals(target.get(port))) {
                    changes.put(port, null);
                }
            }
        } else {
            for (var e : target.entrySet()) {
                if (!e.getValue().equals(inst.bound.get(e.getKey()))) {
                    changes.put(e.getKey(), e.getValue());
                }
            }
        }
        for (var e : changes.entrySet()) {
            String port = e.getKey();
            java.util.concurrent.CompletableFuture<Void> f = h.rebind(port, e.getValue(), 0);
            if (f.isCompletedExceptionally()) {
                rewiringFailed(inst, h, f);
                return;
            }
            if (e.getValue() == null) {
                inst.bound.remove(port);
            } else {
                inst.bound.put(port, e.getValue());
            }
            into.add(new Sent(inst, h, port, e.getValue(), f));
        }
        if (bindPhase) {
            log.accept("arflex: " + inst.name + " rewired while running (" + why + "); inputs " + inst.bound);
        }
    }

    /**
     * Looks at the answers of a phase's BINDs or UNBINDs, all sent first: the actor waits at most
     * {@link #ANSWER_MS} for all of them together (D39; the consumers' cycles run side by side,
     * so n consumers cost the actor one wait, not n). A half that is slower (a long period) or
     * frozen answers later, on a confirmer thread, and the plan goes on meanwhile. A refusal, or
     * no answer within the call timeout, means the half cannot follow the new wiring: it is
     * restarted through the normal failure path, as a crash would be. UNBINDs still unanswered
     * are returned: the plan's stops wait for them before any provider is stopped.
     */
    private List<java.util.concurrent.CompletableFuture<Void>> settle(List<Sent> sent) {
        List<java.util.concurrent.CompletableFuture<Void>> open = new ArrayList<>();
        long deadline = System.nanoTime() + ANSWER_MS * 1_000_000L;
        for (Sent s : sent) {
            try {
                s.answer().get(Math.max(0, deadline - System.nanoTime()), java.util.concurrent.TimeUnit.NANOSECONDS);
            } catch (java.util.concurrent.TimeoutException | java.util.concurrent.ExecutionException e) {
                // looked at below
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        }
        for (Sent s : sent) {
            java.util.concurrent.CompletableFuture<Void> f = s.answer();
            if (f.isCompletedExceptionally()) {
                rewiringFailed(s.inst(), s.h(), f);
            } else if (!f.isDone()) {
                log.accept("arflex: " + s.inst().name + " has not answered " + (s.segment() == null ? "UNBIND " : "BIND ")
                        + s.port() + " within " + ANSWER_MS + " ms; the plan goes on, its answer is awaited apart");
                f.whenComplete((v, ex) -> {
                    if (ex != null) {
                        cell.actor().submit(() -> rewiringFailed(s.inst(), s.h(), f));
                    }
                });
                if (s.segment() == null) {
                    open.add(f);
                }
            }
        }
        return open;
    }

    /** The actor waits this long for a running half's answer to BIND or UNBIND (D39). */
    static final long ANSWER_MS = 20;

    /** A rebind of {@code h} was refused or not answered: it is restarted as a crash would be (actor). */
    private void rewiringFailed(Instance inst, RtHalf h, java.util.concurrent.CompletableFuture<Void> f) {
        if (inst.half != h) {
            return; // gone or replaced meanwhile
        }
        Throwable t = f.handle((v, ex) -> ex).join();
        if (t instanceof java.util.concurrent.CompletionException && t.getCause() != null) {
            t = t.getCause();
        }
        log.accept("arflex: " + inst.name + ": rewiring failed: " + (t == null ? "?" : t.getMessage()) + "; restarting it");
        h.kill();
    }

    /**
     * First step of a stop, on the actor: the half is detached (its exit is expected from here
     * and ignored by {@link Failures#onExit}, a hang by {@link Failures#onHang}) and the instance
     * is no longer Active. The rest (UNBIND, the wait for its safe behaviour, STOP, SHUTDOWN, the
     * signals) runs on a stop thread ({@link Stops}). The half stays watched until then, so the
     * runtime heartbeat goes on while it settles: a slow component (cameras at 500 ms) must not
     * see the runtime lost and latch safe mode on its way out. Returns null when nothing runs.
     */
    Stops.Going detach(Instance inst, String why) {
        if (inst.launching) {
            inst.launchSeq++; // the half being launched is not wanted any more (Starter stops it)
        }
        RtHalf half = inst.half;
        if (half == null) {
            return null;
        }
        inst.half = null;
        List<String> inputs = List.copyOf(inst.bound.keySet());
        inst.bound.clear();
        inst.cpu = -1;
        if (inst.life.state() == State.ACTIVE) {
            inst.life.to(State.UNSATISFIED, why);
        }
        long periods = 3 * inst.contract.timing().periodNs() / 1_000_000L;
        return new Stops.Going(inst, half, inputs, Math.max(100, periods), why);
    }

    /** The instance is gone from the cell: no start waits for it any more. */
    void forget(String name) {
        waiting.remove(name);
    }

    /**
     * Records a batch of stops (actor thread): the log line with how each half ended, the reason
     * of an instance whose half had to be killed, the output segments of uninstalled instances
     * (closed only now that their producer is gone), and the starts that waited for a name.
     */
    void stopped(Stops.Batch b) {
        for (Stops.Going g : b.halves) {
            Instance inst = g.inst;
            log.accept("arflex: " + inst.name + " (pid " + g.half.pid() + ") stopped: " + g.why + " (" + g.outcome + ")");
            boolean destroyed = inst.life.target() == State.DESTROYED && cell.find(inst.name) != inst;
            String why = g.forced() ? g.why + "; RT half " + g.outcome : g.why;
            if (destroyed) {
                segments.close(inst);
                String base = inst.destroyReason != null ? inst.destroyReason : g.why;
                inst.life.to(State.DESTROYED, g.forced() ? base + "; RT half " + g.outcome : base);
            } else if (inst.half == null && g.forced() && g.why.equals(inst.life.reason())) {
                inst.life.reason(why);
            }
        }
        resume();
        cell.changed();
    }

    /** Marks a component as starting once its name is free (actor thread). */
    private void waitFor(Instance inst) {
        if (waiting.add(inst.name) && inst.life.state() != State.FAILED) {
            inst.life.to(State.UNSATISFIED, "starts when its previous RT half has exited");
            log.accept("arflex: " + inst.name + ": start waits for its previous RT half to exit");
        }
    }

    /**
     * Starts what waited for a name that is free now, with the planner's current CPU and
     * wiring, providers first; then binds running consumers to providers that started here.
     */
    void resume() {
        if (waiting.isEmpty()) {
            return;
        }
        Plan now = cell.planner().current();
        List<String> ready = new ArrayList<>();
        Set<String> still = new LinkedHashSet<>();
        for (String name : List.copyOf(waiting)) {
            Instance inst = cell.find(name);
            if (inst == null || inst.half != null || inst.life.state() == State.FAILED
                    || !cell.planner().active().contains(name)) {
                waiting.remove(name);
                continue;
            }
            if (stops.pending(name) || starter.launching(name) || now.wiringOf(name).stream().anyMatch(w -> still.contains(w.provider()))) {
                still.add(name);
            } else {
                ready.add(name);
            }
        }
        if (ready.isEmpty()) {
            return;
        }
        waiting.removeAll(ready);
        for (String name : ready) {
            Instance inst = cell.find(name);
            try {
                segments.ensure(inst);
            } catch (IOException | RuntimeException e) {
                // Starter.start tries again and fails the component with this reason
            }
        }
        for (String name : ready) {
            Instance inst = cell.find(name);
            if (inst.half == null && !starter.launching(name) && inst.life.state() != State.FAILED
                    && cell.planner().active().contains(name)) {
                log.accept("arflex: " + name + ": its previous RT half has exited; starting");
                starter.start(inst, now.cpuAssignment().getOrDefault(name, -1));
            }
        }
        List<Sent> binds = new ArrayList<>();
        for (Instance inst : cell.instances()) {
            if (inst.half == null) {
                continue;
            }
            List<Wire> wires = now.wiringOf(inst.name).stream().filter(w -> !waiting.contains(w.provider())).toList();
            if (wires.stream().anyMatch(w -> !segments.name(w.provider(), w.outPort()).equals(inst.bound.get(w.inPort())))) {
                rebind(inst, wires, true, "its provider started after its previous RT half exited", binds);
            }
        }
        settle(binds);
    }
}
