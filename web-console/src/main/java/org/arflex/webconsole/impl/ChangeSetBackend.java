package org.arflex.webconsole.impl;

import java.nio.charset.StandardCharsets;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.ArrayList;
import java.util.HexFormat;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.atomic.AtomicReference;
import java.util.function.LongSupplier;
import java.util.function.Supplier;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;

/**
 * The Change sets page's endpoints (D46), over the DRCR's {@link ChangeSetService}:
 * <ul>
 * <li>{@code POST changeset-plan} ({@code actions}: one per line): the DRCR's dry run of the
 * whole set, its admission and its parts ({@link ChangeSetText}), and {@code planId}, a digest of
 * the actions and the plan. A dry run changes nothing, but an update's makes the DRCR download
 * its jar, so it is a CSRF-checked {@code POST} like Deploy's {@code plan-update};</li>
 * <li>{@code POST changeset-apply} ({@code actions}, {@code plan}: the {@code planId} shown):
 * plans the set again and refuses (409, nothing applied) when that plan is not the one shown
 * (the cell changed since) or is not admitted; otherwise starts the apply on its own thread and
 * answers 202 at once. One set at a time;</li>
 * <li>{@code GET changesets}: the set being applied (since when, by whom), the outcome of the
 * last one this console applied (with whether the plan the DRCR applied was the one shown), and
 * the DRCR's history of the sets applied in this runtime, each with its outcome
 * ({@link ChangeSetOutcome}).</li>
 * <li>{@code GET changeset-progress}: where the set being applied is (D53), as the DRCR says it
 * ({@link ChangeSetService#progress}): its phase, what it does, an update's shadow or window
 * cycles and the worst deviation so far, then the outcome; the page polls it while a set is
 * applied. Read-only, authenticated like every page's GET.</li>
 * </ul>
 * Every outcome of an apply started here is written to the audit log once it is known.
 */
final class ChangeSetBackend {

    /** Where an apply's outcome goes for the audit log: user, client, actions, outcome view. */
    interface Audit {
        void outcome(String user, String remote, List<String> actions, Map<String, Object> view);
    }

    /** Starts an apply off the HTTP thread. */
    interface Runner {
        void start(Runnable apply);
    }

    /** An apply in progress. */
    private record Running(List<String> actions, String planId, String user, long startedMillis) {
    }

    private final Supplier<ChangeSetService> service;
    private final Runner runner;
    private final Audit audit;
    private final LongSupplier clock;
    private final StagingSources sources;
    private final AtomicReference<Running> running = new AtomicReference<>();
    private volatile Map<String, Object> last;

    /** A backend that takes no {@code file:} URL (no staging folder configured). */
    ChangeSetBackend(Supplier<ChangeSetService> service, Runner runner, Audit audit, LongSupplier wallClockMillis) {
        this(service, runner, audit, wallClockMillis, StagingSources.parse(null));
    }

    /**
     * @param sources the folders an update's {@code file:} URL may name, the Deploy page's
     *                (issue 30, finding 9: the DRCR reads the location, and answers with its digest)
     */
    ChangeSetBackend(Supplier<ChangeSetService> service, Runner runner, Audit audit, LongSupplier wallClockMillis,
                     StagingSources sources) {
        this.service = service;
        this.runner = runner;
        this.audit = audit;
        this.clock = wallClockMillis;
        this.sources = sources;
    }

    /** Every update's {@code file:} URL names a file in a staging folder, else a 400 naming its line. */
    private ChangeSetInput staged(ChangeSetInput in) throws HttpError {
        for (int i = 0; i < in.lines().size(); i++) {
            String[] t = in.lines().get(i).split(" ");
            if (t[0].equals("update") && t[2].regionMatches(true, 0, "file:", 0, 5)) {
                try {
                    sources.file(java.net.URI.create(t[2]));
                } catch (HttpError e) {
                    throw new HttpError(e.status, "line " + in.number().get(i) + ": " + e.getMessage());
                } catch (IllegalArgumentException | java.io.IOException e) {
                    throw new HttpError(400, "line " + in.number().get(i) + ": url: '" + t[2] + "' is not a file URL ("
                            + e.getMessage() + ")");
                }
            }
        }
        return in;
    }

    Routes routes() {
        return new Routes()
                .get("changesets", call -> status())
                .get("changeset-progress", call -> progress())
                .post("changeset-plan", call -> plan(call.param("actions")))
                .post("changeset-apply", call -> apply(call.param("actions"), call.param("plan"), call.user(),
                        call.remote()));
    }

    private ChangeSetService service() throws HttpError {
        ChangeSetService s = service.get();
        if (s == null) {
            throw new HttpError(503, "the DRCR is not running (no ChangeSetService registered)");
        }
        return s;
    }

    /** The dry run of the whole set, with its parts and the id that an apply must name. */
    Map<String, Object> plan(String text) throws HttpError {
        ChangeSetInput in = staged(ChangeSetInput.parse(text));
        ChangeSetDTO d = dryRun(in);
        return view(in, d);
    }

    private ChangeSetDTO dryRun(ChangeSetInput in) throws HttpError {
        try {
            return service().plan(in.lines());
        } catch (RuntimeException e) {
            throw new HttpError(409, "the DRCR could not plan the set: " + HttpError.reason(e));
        }
    }

    private static Map<String, Object> view(ChangeSetInput in, ChangeSetDTO d) {
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("actions", in.lines());
        m.put("lines", in.number());
        m.put("admitted", d.admitted);
        m.put("refusal", d.refusal);
        m.put("refusedLine", in.lineOf(d.refusal));
        m.put("planId", planId(in.lines(), d));
        m.put("parts", ChangeSetText.parse(d.text));
        m.put("text", d.text);
        return m;
    }

    /** A digest of what was shown: the actions and the DRCR's whole answer to the dry run. */
    static String planId(List<String> actions, ChangeSetDTO d) {
        try {
            MessageDigest md = MessageDigest.getInstance("SHA-256");
            md.update(String.join("\n", actions).getBytes(StandardCharsets.UTF_8));
            md.update((byte) 0);
            md.update((d.admitted + "\n" + d.refusal + "\n" + d.text).getBytes(StandardCharsets.UTF_8));
            return HexFormat.of().formatHex(md.digest());
        } catch (NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }

    /**
     * Applies the set whose plan was shown: refused (409, nothing applied) when the plan it
     * gives now is another one or is not admitted, or while another set is applied.
     */
    Map<String, Object> apply(String text, String shownPlanId, String user, String remote) throws HttpError {
        ChangeSetInput in = staged(ChangeSetInput.parse(text));
        if (shownPlanId == null || !shownPlanId.matches("[0-9a-f]{64}")) {
            throw new HttpError(400, "plan: the id of the plan shown is missing or malformed: plan the set first,"
                    + " then apply the plan shown");
        }
        ChangeSetService s = service();
        Running r = new Running(in.lines(), shownPlanId, user, clock.getAsLong());
        if (!running.compareAndSet(null, r)) {
            Running other = running.get();
            throw new HttpError(409, "another change set is being applied (" + (other == null ? "just finished"
                    : String.join("; ", other.actions()) + ", since " + java.time.Instant.ofEpochMilli(
                            other.startedMillis())) + "): wait for its outcome, then plan again");
        }
        boolean started = false;
        try {
            ChangeSetDTO now = dryRun(in);
            if (!planId(in.lines(), now).equals(shownPlanId)) {
                throw new HttpError(409, "the cell changed since the plan was shown: its plan is not the one you "
                        + "confirmed, nothing was applied; plan the set again and review the new plan"
                        + (now.admitted ? "" : " (it is refused now: " + now.refusal + ")"));
            }
            if (!now.admitted) {
                throw new HttpError(409, "the plan shown is refused, nothing was applied: " + now.refusal
                        + lineSuffix(in, now.refusal));
            }
            String shownPlan = ChangeSetText.planPart(now.text);
            runner.start(() -> finish(r, shownPlan, s, remote));
            started = true;
        } finally {
            if (!started) {
                running.compareAndSet(r, null);
            }
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("state", "applying");
        m.put("actions", in.lines());
        m.put("startedMillis", r.startedMillis());
        return m;
    }

    private static String lineSuffix(ChangeSetInput in, String refusal) {
        int line = in.lineOf(refusal);
        return line > 0 ? " (line " + line + ")" : "";
    }

    /** The apply itself (the runner's thread): the DRCR returns once switched, refused or torn down, and windows ended. */
    private void finish(Running r, String shownPlan, ChangeSetService s, String remote) {
        Map<String, Object> view;
        try {
            ChangeSetDTO d;
            try {
                d = s.apply(r.actions());
            } catch (RuntimeException e) {
                d = new ChangeSetDTO();
                d.actions = r.actions().toArray(String[]::new);
                d.refusal = "the DRCR failed to apply the set: " + HttpError.reason(e);
                d.text = "change set: " + String.join("; ", r.actions()) + "\nrefused: " + d.refusal + "\n";
                d.finishedMillis = clock.getAsLong();
            }
            view = ChangeSetOutcome.of(d);
            String applied = ChangeSetText.planPart(d.text);
            // The DRCR plans the set again when applying (and once more in its switch turn): the plan it
            // applied is compared with the one shown, so a difference is said, not hidden.
            view.put("planAsShown", applied.isEmpty() || applied.equals(shownPlan));
        } catch (RuntimeException e) {
            view = new LinkedHashMap<>();
            view.put("actions", r.actions());
            view.put("outcome", "unknown");
            view.put("why", "the console could not read the DRCR's answer: " + HttpError.reason(e));
        }
        view.put("startedMillis", r.startedMillis());
        view.put("user", r.user());
        last = view;
        running.compareAndSet(r, null);
        if (audit != null) {
            audit.outcome(r.user(), remote, r.actions(), view);
        }
    }

    /**
     * Where the set being applied is, or how the last one ended (D53): {@code progress} null when
     * no set was applied in this runtime; {@code drcr} false without the DRCR.
     */
    Map<String, Object> progress() {
        Map<String, Object> m = new LinkedHashMap<>();
        ChangeSetService s = service.get();
        m.put("drcr", s != null);
        org.arflex.drcr.dto.ChangeSetProgressDTO p = s == null ? null : s.progress();
        if (p == null) {
            m.put("progress", null);
            return m;
        }
        Map<String, Object> v = new LinkedHashMap<>();
        v.put("actions", p.actions == null ? List.of() : List.of(p.actions));
        v.put("running", p.running);
        v.put("phase", p.phase);
        v.put("phases", p.phases == null ? List.of() : List.of(p.phases));
        v.put("step", p.step);
        v.put("component", p.component);
        v.put("cycle", p.cycle);
        v.put("cycles", p.cycles);
        v.put("worstField", p.worstField);
        v.put("worstDeviation", p.worstDeviation);
        v.put("tolerance", p.tolerance);
        v.put("startedMillis", p.startedMillis);
        v.put("phaseMillis", p.phaseMillis);
        v.put("forMs", Math.max(0, clock.getAsLong() - p.startedMillis));
        v.put("outcome", p.outcome);
        v.put("why", p.why);
        v.put("updates", UpdateEntries.of(p.updates));
        v.put("seq", p.seq);
        m.put("progress", v);
        return m;
    }

    /** What is being applied, the last outcome here, and the DRCR's history. */
    Map<String, Object> status() throws HttpError {
        Map<String, Object> m = new LinkedHashMap<>();
        Running r = running.get();
        if (r != null) {
            Map<String, Object> a = new LinkedHashMap<>();
            a.put("actions", r.actions());
            a.put("startedMillis", r.startedMillis());
            a.put("user", r.user());
            a.put("forMs", Math.max(0, clock.getAsLong() - r.startedMillis()));
            m.put("applying", a);
        } else {
            m.put("applying", null);
        }
        m.put("last", last);
        List<Map<String, Object>> history = new ArrayList<>();
        ChangeSetService s = service.get();
        m.put("drcr", s != null);
        if (s != null) {
            for (ChangeSetDTO d : s.history()) {
                history.add(ChangeSetOutcome.of(d));
            }
        }
        m.put("history", history);
        return m;
    }
}
