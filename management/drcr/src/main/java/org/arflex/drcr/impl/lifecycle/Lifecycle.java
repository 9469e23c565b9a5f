package org.arflex.drcr.impl.lifecycle;

import java.util.function.Consumer;

/**
 * The state of one instance: current state, target state and the reason it is not at the
 * target. Not thread-safe by design: only the actor thread changes it (checked), readers on
 * other threads see the volatile fields.
 */
public final class Lifecycle {

    private final String name;
    private final Actor actor;
    private final Consumer<String> log;
    private volatile State state = State.INSTALLED;
    private volatile State target = State.ACTIVE;
    private volatile String reason;

    /**
     * @param name  instance name, for log lines
     * @param actor the actor whose thread alone may change this lifecycle
     * @param log   where refused transitions are reported
     */
    public Lifecycle(String name, Actor actor, Consumer<String> log) {
        this.name = name;
        this.actor = actor;
        this.log = log;
    }

    /** Current state. */
    public State state() {
        return state;
    }

    /** The state the DRCR drives the instance to. */
    public State target() {
        return target;
    }

    /** Why the instance is where it is (null when Active with nothing to say). */
    public String reason() {
        return reason;
    }

    /** Sets the target state (actor thread only). */
    public void target(State t) {
        actor.checkThread();
        target = t;
    }

    /** Sets the reason without changing state (actor thread only). */
    public void reason(String r) {
        actor.checkThread();
        reason = r;
    }

    /**
     * Moves to {@code to} if the table allows it. A refused transition changes nothing and is
     * logged with its reason; staying in the same state is a no-op that only updates the reason.
     *
     * @return true when the state is {@code to} afterwards
     */
    public boolean to(State to, String why) {
        actor.checkThread();
        State from = state;
        if (from == to) {
            reason = why;
            return true;
        }
        if (!Transitions.allowed(from, to)) {
            log.accept("arflex: " + name + ": refused transition " + from + " -> " + to + " (" + why
                    + "): allowed from " + from + " are " + Transitions.from(from));
            return false;
        }
        state = to;
        reason = why;
        return true;
    }

    @Override
    public String toString() {
        return name + " " + state + " (target " + target + (reason != null ? ", " + reason : "") + ")";
    }
}
