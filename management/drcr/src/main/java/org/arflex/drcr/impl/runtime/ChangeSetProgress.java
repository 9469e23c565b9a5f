package org.arflex.drcr.impl.runtime;

import java.util.ArrayList;
import java.util.List;
import java.util.function.LongSupplier;
import org.arflex.drcr.dto.ChangeSetProgressDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;

/**
 * The live progress of the change set being applied (D53): its phase, what it does in it, an
 * update's shadow or window cycles, then its outcome. Whoever applies a set publishes through
 * its {@link Apply}; {@link #snapshot} reads the last snapshot without a lock (a volatile
 * field holding a DTO that is never changed once published), so a reader never holds up the
 * actor, and publishing is a few field writes under this object's lock, no I/O.
 *
 * <p>Each update of the set has its own entry (D60, {@link ChangeSetProgressDTO#updates}), in
 * the set's order, moved by the shadow run's and the window's publishing about its component and
 * kept after the apply ends; an entry is replaced, never changed, once published.
 *
 * <p>One set is shown: an apply begun while another is shown and still running is not shown
 * (its publishing is ignored) unless the executor takes it ({@link Apply#claim}), which happens
 * only to the one set it accepts; the executor applies one set at a time.
 */
public final class ChangeSetProgress {
    /** The phases, in their order. */
    public static final String CHECKING = "checking";
    public static final String PREPARING = "preparing";
    public static final String SHADOW = "shadow";
    public static final String SWITCHING = "switching";
    public static final String WINDOW = "window";
    public static final String BUNDLES = "bundles";
    public static final String DONE = "done";
    /** An update's own verdicts (D60), in the outcome's words. */
    public static final String COMMITTED = "committed";
    public static final String ROLLED_BACK = "rolled-back";
    public static final String REJECTED_IN_SHADOW = "rejected-in-shadow";
    /** An update whose set another update's shadow run rejected (D62): it did not happen, not for its own reason. */
    public static final String CANCELLED = "cancelled";
    /** An update refused once its new half was READY, before its shadow run (D70: it cannot re-adopt). */
    public static final String REFUSED = "refused";

    private final LongSupplier clock;
    private volatile ChangeSetProgressDTO shown;
    /** The apply shown (guarded by this). */
    private Apply owner;
    private long seq;

    public ChangeSetProgress(LongSupplier wallClockMillis) {
        this.clock = wallClockMillis;
    }

    /** The last snapshot (a copy), or null when no set was applied in this runtime. */
    public ChangeSetProgressDTO snapshot() {
        ChangeSetProgressDTO d = shown;
        return d == null ? null : copy(d);
    }

    /**
     * An apply of {@code actions} begins: shown from now on in phase {@link #CHECKING}, unless
     * another apply is shown and still running.
     */
    public synchronized Apply begin(List<String> actions) {
        Apply a = new Apply(actions);
        if (owner == null || !owner.running) {
            a.take();
        }
        return a;
    }

    private static ChangeSetProgressDTO copy(ChangeSetProgressDTO d) {
        ChangeSetProgressDTO c = new ChangeSetProgressDTO();
        c.actions = d.actions.clone();
        c.running = d.running;
        c.phase = d.phase;
        c.step = d.step;
        c.component = d.component;
        c.cycle = d.cycle;
        c.cycles = d.cycles;
        c.worstField = d.worstField;
        c.worstDeviation = d.worstDeviation;
        c.tolerance = d.tolerance;
        c.phases = d.phases.clone();
        c.updates = new UpdateProgressDTO[d.updates.length];
        for (int i = 0; i < c.updates.length; i++) {
            c.updates[i] = copy(d.updates[i]);
        }
        c.startedMillis = d.startedMillis;
        c.phaseMillis = d.phaseMillis;
        c.outcome = d.outcome;
        c.why = d.why;
        c.seq = d.seq;
        return c;
    }

    /** Copies of {@code updates} (an empty array for null): for the history, which keeps them (D62). */
    public static UpdateProgressDTO[] copies(UpdateProgressDTO[] updates) {
        UpdateProgressDTO[] out = new UpdateProgressDTO[updates == null ? 0 : updates.length];
        for (int i = 0; i < out.length; i++) {
            out[i] = copy(updates[i]);
        }
        return out;
    }

    private static UpdateProgressDTO copy(UpdateProgressDTO u) {
        UpdateProgressDTO c = new UpdateProgressDTO();
        c.component = u.component;
        c.phase = u.phase;
        c.step = u.step;
        c.cycle = u.cycle;
        c.cycles = u.cycles;
        c.worstField = u.worstField;
        c.worstDeviation = u.worstDeviation;
        c.tolerance = u.tolerance;
        c.verdict = u.verdict;
        c.why = u.why;
        return c;
    }

    /**
     * The outcome of an apply in the console's words (D46): {@code verdict}, the lines of the
     * updates' windows (null when the set has no update, or none came: {@code verdictMissing}).
     */
    public static String outcomeOf(boolean applied, String refusal, String verdict, boolean verdictMissing) {
        if (!applied) {
            String r = refusal == null ? "" : refusal;
            if (r.matches("(?s)update \\S+: rejected in shadow after \\d+ cycles.*")) {
                return "rejected-in-shadow";
            }
            return r.startsWith("preparation failed") || r.contains("the cell changed while the set was prepared")
                    ? "torn-down" : "refused";
        }
        if (verdict != null && verdict.lines().anyMatch(l -> l.matches("update \\S+: rolled back after \\d+ cycles.*"))) {
            return "rolled-back";
        }
        return verdictMissing ? "applied" : "committed";
    }

    /** One apply's publisher. Every method may be called from any thread. */
    public final class Apply {
        private final String[] actions;
        private final List<String> phases = new ArrayList<>();
        /** Each update's last entry, in the set's order (guarded by the progress); never changed once placed. */
        private UpdateProgressDTO[] updates = new UpdateProgressDTO[0];
        private long startedMillis;
        private long phaseMillis;
        private String phase;
        private boolean running = true;

        private Apply(List<String> actions) {
            this.actions = actions.toArray(String[]::new);
        }

        /**
         * Shown from now on (the executor accepted this set): its phases start afresh, and
         * {@code components}, the components its updates replace in the set's order, each get
         * an entry (D60).
         */
        public void claim(List<String> components) {
            synchronized (ChangeSetProgress.this) {
                updates = new UpdateProgressDTO[components.size()];
                for (int i = 0; i < updates.length; i++) {
                    updates[i] = new UpdateProgressDTO();
                    updates[i].component = components.get(i);
                }
                if (owner != this) {
                    take();
                } else if (running) {
                    ChangeSetProgressDTO d = copy(shown);
                    d.updates = updates.clone();
                    d.seq = ++seq;
                    shown = d;
                }
            }
        }

        private void take() {
            owner = this;
            startedMillis = clock.getAsLong();
            phases.clear();
            phase = null;
            shown = next(CHECKING, "checking the actions", null, 0, 0);
        }

        /** Enters {@code phase} (or stays in it) doing {@code step}; an entered phase is listed once. */
        public void phase(String phase, String step) {
            cycles(phase, step, null, 0, 0, null, 0, 0);
        }

        /** In {@code phase}, {@code step}, about {@code component} at {@code cycle} of {@code cycles}. */
        public void cycles(String phase, String step, String component, long cycle, long cycles, String worstField,
                           double worstDeviation, double tolerance) {
            synchronized (ChangeSetProgress.this) {
                if (owner != this || !running) {
                    return;
                }
                int i = (SHADOW.equals(phase) || WINDOW.equals(phase)) ? indexOf(component) : -1;
                if (i >= 0) {
                    UpdateProgressDTO u = copy(updates[i]);
                    u.phase = phase;
                    u.step = step;
                    u.cycle = cycle;
                    u.cycles = cycles;
                    if (worstField != null) {
                        u.worstField = worstField;
                        u.worstDeviation = worstDeviation;
                        u.tolerance = tolerance;
                    }
                    updates[i] = u;
                }
                ChangeSetProgressDTO d = next(phase, step, component, cycle, cycles);
                d.worstField = worstField;
                d.worstDeviation = worstDeviation;
                d.tolerance = tolerance;
                shown = d;
            }
        }

        /**
         * The update of {@code component} has its own verdict ({@code committed},
         * {@code rolled-back}, {@code rejected-in-shadow} or {@code refused}), {@code why}, after {@code cycle}
         * cycles of its shadow run or window: its entry says so; the set's phase and step are
         * unchanged (D60).
         */
        public void verdict(String component, String verdict, String why, long cycle) {
            synchronized (ChangeSetProgress.this) {
                int i = indexOf(component);
                if (owner != this || !running || i < 0) {
                    return;
                }
                UpdateProgressDTO u = copy(updates[i]);
                u.verdict = verdict;
                u.why = why;
                u.cycle = cycle;
                updates[i] = u;
                ChangeSetProgressDTO d = copy(shown);
                d.updates = updates.clone();
                d.seq = ++seq;
                shown = d;
            }
        }

        /**
         * The shadow run of {@code component} rejected it after {@code cycle} cycles for
         * {@code reason} ({@code refusal}: the set's refusal line): its entry says
         * {@code rejected-in-shadow}, and every other update without a verdict of its own is
         * {@code cancelled}, naming it and the reason (D62), its counters kept.
         */
        public void rejectedInShadow(String component, String refusal, String reason, long cycle) {
            ended(component, REJECTED_IN_SHADOW, refusal, ShadowReport.cancelled(component, reason), cycle);
        }

        /**
         * The update of {@code component} was refused once its new half was READY, before its
         * shadow run (D70), for {@code reason} ({@code refusal}: the set's refusal line): its entry
         * says {@code refused}, every other update without a verdict of its own {@code cancelled},
         * naming it and the reason, as {@link #rejectedInShadow}.
         */
        public void refused(String component, String refusal, String reason) {
            ended(component, REFUSED, refusal, ReadoptCheck.cancelled(component, reason), 0);
        }

        /** {@code component}'s verdict ends the set: the updates without one are cancelled by {@code cancelled}. */
        private void ended(String component, String verdict, String refusal, String cancelled, long cycle) {
            synchronized (ChangeSetProgress.this) {
                if (owner != this || !running || indexOf(component) < 0) {
                    return;
                }
                for (int i = 0; i < updates.length; i++) {
                    if (updates[i].verdict == null && !updates[i].component.equals(component)) {
                        UpdateProgressDTO u = copy(updates[i]);
                        u.verdict = CANCELLED;
                        u.why = cancelled;
                        updates[i] = u;
                    }
                }
                verdict(component, verdict, refusal, cycle); // publishes them all in one snapshot
            }
        }

        /**
         * Each update's last entry, in the set's order (copies): what the history keeps of the
         * apply (D62); empty when the executor never accepted the set.
         */
        public UpdateProgressDTO[] updates() {
            synchronized (ChangeSetProgress.this) {
                return copies(updates);
            }
        }

        private int indexOf(String component) {
            for (int i = 0; i < updates.length; i++) {
                if (updates[i].component.equals(component)) {
                    return i;
                }
            }
            return -1;
        }

        /** The outcome: shown until the next apply begins. */
        public void done(String outcome, String why) {
            synchronized (ChangeSetProgress.this) {
                if (owner != this || !running) {
                    return;
                }
                ChangeSetProgressDTO d = next(DONE, outcome + (why == null ? "" : ": " + why), null, 0, 0);
                d.running = false;
                d.outcome = outcome;
                d.why = why;
                running = false;
                shown = d;
            }
        }

        /** True while this apply is shown and running. */
        public boolean shown() {
            synchronized (ChangeSetProgress.this) {
                return owner == this && running;
            }
        }

        /** The next snapshot (under the lock); the caller publishes it once complete. */
        private ChangeSetProgressDTO next(String phase, String step, String component, long cycle, long cycles) {
            long now = clock.getAsLong();
            if (!phase.equals(this.phase)) {
                this.phase = phase;
                phaseMillis = now;
                phases.add(phase);
            }
            ChangeSetProgressDTO d = new ChangeSetProgressDTO();
            d.actions = actions;
            d.running = true;
            d.phase = phase;
            d.step = step;
            d.component = component;
            d.cycle = cycle;
            d.cycles = cycles;
            d.phases = phases.toArray(String[]::new);
            d.updates = updates.clone();
            d.startedMillis = startedMillis;
            d.phaseMillis = phaseMillis;
            d.seq = ++seq;
            return d;
        }
    }
}
