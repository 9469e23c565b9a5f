package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Set;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ExecutionException;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.TimeoutException;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ChangeSet;
import org.arflex.drcr.impl.runtime.ChangeSetResult;
import org.arflex.drcr.impl.runtime.Instance;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;

/**
 * The {@link ChangeSetService} (D35): parses the actions, finds the bundles behind them, has
 * the executables of the components to install checked by the code gate and extracted (off the
 * actor), hands the set to the cell, and once it is switched brings Felix in line: the bundles
 * of installed components are started (the extender adopts what the set started) and those of
 * uninstalled ones stopped.
 */
public final class ChangeSets implements ChangeSetService {

    /** How long an apply may take: preparing halves that load models can take seconds. */
    static final long APPLY_MS = 120_000;

    /** The extender's part: the executable of a component of an installed, not started bundle. */
    @FunctionalInterface
    public interface Executables {
        /** Checks the bundle with the code gate and extracts the component's executable. */
        Path executable(Bundle bundle, Contract c) throws IOException;
    }

    /** Default rollback window of an update, in cycles of the new version (D38). */
    static final long WINDOW = 1000;
    /** The usage of the actions. */
    static final String ACTIONS = "actions: install <component>, uninstall <component>, set <component> <parameter> "
            + "<value>, update <component> <jar URL> [<sha256>] [window <cycles>] [shadow <cycles>] [envelope <port>.<field> "
            + "<min> <max>]... [tolerance <port>.<field> <max difference>]...";

    /**
     * A new version of a component, from a jar that passed the code gate (D38); {@code jar}: its
     * bytes, as checked, for the component's bundle to follow once the update is committed.
     */
    public record Version(Contract contract, String from, String how, Extract extract, byte[] jar) {
    }

    /** Extracts a verified version's executable (apply only, never in a dry run). */
    @FunctionalInterface
    public interface Extract {
        Path executable() throws IOException;
    }

    /** Reads a new version of a component: fetched, pinned or signed, its contract read. */
    @FunctionalInterface
    public interface Versions {
        /**
         * @param sha256 the pinned SHA-256, or null: then the jar must be signed by a trusted key
         * @throws IOException saying why the jar is refused or unreadable
         */
        Version read(String component, String location, String sha256) throws IOException;
    }

    private final Cell cell;
    private final BundleContext context;
    private volatile Versions versions = (n, l, s) -> {
        throw new IOException("the DRCR is not started yet");
    };
    private volatile Executables executables = (b, c) -> {
        throw new IOException("the DRCR is not started yet");
    };
    private volatile UpdatedBundles bundles;
    private volatile DeploymentSets deployments;
    private final Consumer<String> log;
    /** The outcomes of the sets applied, for {@link #history} (D46). */
    private final ChangeSetHistory history = new ChangeSetHistory(System::currentTimeMillis);

    public ChangeSets(Cell cell, BundleContext context, Consumer<String> log) {
        this.cell = cell;
        this.context = context;
        this.log = log;
    }

    /** Where the new versions of updates come from. */
    public void versions(Versions v) {
        versions = v;
    }

    /** Who updates the bundle of a committed update (built with the extender, after this service). */
    public void bundles(UpdatedBundles b) {
        bundles = b;
    }

    /** Who applies deployment sets (D45). */
    public void deployments(DeploymentSets d) {
        deployments = d;
        d.recordInto(history); // its refusals before the change set, in the same history (D50)
    }

    @Override
    public ChangeSetDTO deploy(String url, boolean apply) {
        DeploymentSets d = deployments;
        return d != null ? d.deploy(url, apply) : refused(List.of("deploy " + url), "the DRCR is not started yet");
    }

    /** Where the executables of installs come from (the extender, built after this service). */
    public void executables(Executables e) {
        executables = e;
    }

    /**
     * The actions, parsed: {@code install n}, {@code uninstall n}, {@code set n p v},
     * {@code update n <url> [<sha256>] [window <cycles>]} (as {@code update n url sha|"" cycles|""}),
     * also as one token list.
     */
    static List<String[]> parse(List<String> actions) {
        List<String> tokens = new ArrayList<>();
        for (String a : actions) {
            for (String t : a.trim().split("[\\s;,]+")) {
                if (!t.isEmpty()) {
                    tokens.add(t);
                }
            }
        }
        List<String[]> out = new ArrayList<>();
        for (int i = 0; i < tokens.size(); ) {
            String verb = tokens.get(i);
            int n = switch (verb) {
                case "install", "uninstall" -> 2;
                case "set" -> 4;
                case "update" -> 3;
                default -> throw new IllegalArgumentException("unknown action '" + verb + "' (" + ACTIONS + ")");
            };
            if (i + n > tokens.size()) {
                throw new IllegalArgumentException("'" + String.join(" ", tokens.subList(i, tokens.size()))
                        + "' is incomplete (" + verb + switch (verb) {
                            case "set" -> " <component> <parameter> <value>";
                            case "update" -> " <component> <jar URL> [<sha256>] [window <cycles>] [shadow <cycles>] "
                                    + "[envelope <port>.<field> <min> <max>]... [tolerance <port>.<field> <max difference>]...";
                            default -> " <component>";
                        } + ")");
            }
            if (!verb.equals("update")) {
                out.add(tokens.subList(i, i + n).toArray(String[]::new));
                i += n;
                continue;
            }
            List<String> u = new ArrayList<>(List.of(verb, tokens.get(i + 1), tokens.get(i + 2), "", "", ""));
            i += 3;
            if (i < tokens.size() && tokens.get(i).matches("[0-9a-fA-F]{64}")) {
                u.set(3, tokens.get(i++));
            }
            while (i < tokens.size() && List.of("window", "shadow", "envelope", "tolerance").contains(tokens.get(i))) {
                if (tokens.get(i).equals("window") || tokens.get(i).equals("shadow")) {
                    if (i + 1 >= tokens.size() || !tokens.get(i + 1).matches("[0-9]{1,9}")) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": " + tokens.get(i)
                                + " needs a number of cycles");
                    }
                    u.set(tokens.get(i).equals("window") ? 4 : 5, tokens.get(i + 1));
                    i += 2;
                } else if (tokens.get(i).equals("tolerance")) {
                    if (i + 2 >= tokens.size() || !tokens.get(i + 1).matches("[a-z][a-z0-9_]*\\.[a-z][a-z0-9_]*")) {
                        throw new IllegalArgumentException("update " + u.get(1)
                                + ": tolerance needs <port>.<field> <max difference>");
                    }
                    try {
                        new ChangeSet.Tolerance("p", "f", Double.parseDouble(tokens.get(i + 2)));
                    } catch (IllegalArgumentException e) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": tolerance " + tokens.get(i + 1)
                                + ": " + tokens.get(i + 2) + " is not a tolerance (a finite number >= 0)");
                    }
                    u.add("tolerance " + tokens.get(i + 1) + " " + tokens.get(i + 2));
                    i += 3;
                } else {
                    if (i + 3 >= tokens.size() || !tokens.get(i + 1).matches("[a-z][a-z0-9_]*\\.[a-z][a-z0-9_]*")) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": envelope needs <port>.<field> <min> <max>");
                    }
                    try {
                        new ChangeSet.Envelope("p", "f", Double.parseDouble(tokens.get(i + 2)),
                                Double.parseDouble(tokens.get(i + 3)));
                    } catch (IllegalArgumentException e) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": envelope " + tokens.get(i + 1)
                                + ": " + tokens.get(i + 2) + " " + tokens.get(i + 3) + " is not a range (<min> <max>)");
                    }
                    u.add("envelope " + tokens.get(i + 1) + " " + tokens.get(i + 2) + " " + tokens.get(i + 3));
                    i += 4;
                }
            }
            out.add(u.toArray(String[]::new));
        }
        return out;
    }

    @Override
    public ChangeSetDTO plan(List<String> actions) {
        List<String[]> parsed;
        try {
            parsed = parse(actions);
        } catch (IllegalArgumentException e) {
            return refused(actions, e.getMessage());
        }
        ChangeSet set;
        try {
            set = build(parsed, false);
        } catch (IllegalStateException e) {
            return refused(actions, e.getMessage());
        }
        ChangeSetResult r = cell.actor().call(() -> cell.planChangeSet(set), Services.CALL_MS);
        String bundles = r.admitted() ? bundleProblems(parsed) : null;
        return bundles != null ? refused(actions, bundles) : dto(actions, r);
    }

    @Override
    public ChangeSetDTO apply(List<String> actions) {
        return history.record(applyOnce(actions));
    }

    @Override
    public List<ChangeSetDTO> history() {
        return history.list();
    }

    private ChangeSetDTO applyOnce(List<String> actions) {
        List<String[]> parsed;
        try {
            parsed = parse(actions);
        } catch (IllegalArgumentException e) {
            return refused(actions, e.getMessage());
        }
        String bundles = bundleProblems(parsed);
        if (bundles != null) {
            return refused(actions, bundles);
        }
        // the bundles behind the named components, before the set (an uninstalled one leaves the cell)
        java.util.Map<String, Long> bundleIds = new java.util.HashMap<>();
        for (String[] a : parsed) {
            Instance i = find(a[1]);
            if (i != null) {
                bundleIds.put(a[1], i.bundleId);
            }
        }
        // refused sets are refused before anything is extracted from a bundle or a jar
        java.util.Map<String, Version> read = new java.util.HashMap<>();
        ChangeSet dryRun;
        try {
            dryRun = build(parsed, false, read);
        } catch (IllegalStateException e) {
            return refused(actions, e.getMessage());
        }
        ChangeSetResult dry = cell.actor().call(() -> cell.planChangeSet(dryRun), Services.CALL_MS);
        if (!dry.admitted()) {
            return dto(actions, dry);
        }
        ChangeSet set;
        try {
            set = build(parsed, true, read);
        } catch (IllegalStateException e) {
            return refused(actions, e.getMessage());
        }
        CompletableFuture<ChangeSetResult> f = cell.actor().call(() -> cell.applyChangeSet(set), Services.CALL_MS);
        ChangeSetResult r;
        try {
            r = f.get(APPLY_MS, TimeUnit.MILLISECONDS);
        } catch (ExecutionException | TimeoutException e) {
            return refused(actions, "no outcome: " + e);
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            return refused(actions, "interrupted");
        }
        ChangeSetDTO d = dto(actions, r);
        if (r.applied()) {
            d.text += followBundles(parsed, bundleIds);
        }
        if (r.applied() && r.verdict() != null) {
            // an update's rollback window: the command says how it ended (committed or rolled back, why)
            try {
                String verdict = r.verdict().get(APPLY_MS, TimeUnit.MILLISECONDS);
                d.text += verdict + "\n" + followUpdates(parsed, bundleIds, read, verdict);
            } catch (ExecutionException | TimeoutException e) {
                d.text += "warning: no verdict of the rollback window yet: " + e + "\n";
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        }
        return d;
    }

    private ChangeSet build(List<String[]> parsed, boolean extract) {
        return build(parsed, extract, new java.util.HashMap<>());
    }

    /**
     * The cell's change set; {@code extract}: the executables of installs and updates are checked
     * and extracted. {@code read}: the new versions of updates read so far (each jar is fetched
     * and checked once per apply).
     */
    private ChangeSet build(List<String[]> parsed, boolean extract, java.util.Map<String, Version> read) {
        ChangeSet.Builder b = ChangeSet.builder();
        for (String[] a : parsed) {
            switch (a[0]) {
                case "install" -> b.install(a[1], extract ? executable(a[1]) : Path.of("(not extracted in a dry run)"));
                case "update" -> {
                    Version v = read.get(a[1]);
                    if (v == null) {
                        try {
                            v = versions.read(a[1], a[2], a[3].isEmpty() ? null : a[3]);
                        } catch (IOException | RuntimeException e) {
                            throw new IllegalStateException("update " + a[1] + ": " + e.getMessage());
                        }
                        read.put(a[1], v);
                        log.accept("arflex: change set: update " + a[1] + ": " + v.from() + " (" + v.how() + "), version "
                                + v.contract().version());
                    }
                    Path exe;
                    try {
                        exe = extract ? v.extract().executable() : Path.of("(not extracted in a dry run)");
                    } catch (IOException e) {
                        throw new IllegalStateException("update " + a[1] + ": cannot extract its executable: " + e.getMessage());
                    }
                    List<ChangeSet.Envelope> envelopes = new ArrayList<>();
                    List<ChangeSet.Tolerance> tolerances = new ArrayList<>();
                    for (int k = 6; k < a.length; k++) {
                        String[] e = a[k].split(" ");
                        int dot = e[1].indexOf('.');
                        if (e[0].equals("envelope")) {
                            envelopes.add(new ChangeSet.Envelope(e[1].substring(0, dot), e[1].substring(dot + 1),
                                    Double.parseDouble(e[2]), Double.parseDouble(e[3])));
                        } else {
                            tolerances.add(new ChangeSet.Tolerance(e[1].substring(0, dot), e[1].substring(dot + 1),
                                    Double.parseDouble(e[2])));
                        }
                    }
                    // the command line over the new version's <rollout> (SPEC 12.1) over the defaults (D42)
                    b.add(ChangeSet.rules(a[1], v.contract(), exe, a[2], a[4].isEmpty() ? null : Long.parseLong(a[4]),
                            a[5].isEmpty() ? null : Long.parseLong(a[5]), envelopes, tolerances, WINDOW));
                }
                case "uninstall" -> b.uninstall(a[1]);
                default -> b.set(a[1], a[2], a[3]);
            }
        }
        return b.build();
    }

    private Path executable(String name) {
        Instance inst = find(name);
        Bundle bundle = inst == null || context == null ? null : context.getBundle(inst.bundleId);
        if (bundle == null) {
            return Path.of("/nonexistent/" + name); // the cell refuses the set and says why
        }
        try {
            return executables.executable(bundle, inst.contract());
        } catch (IOException e) {
            throw new IllegalStateException("install " + name + ": " + e.getMessage());
        }
    }

    /**
     * Felix follows the cell only bundle by bundle: a bundle whose start or stop would change
     * components the set does not name is refused.
     */
    private String bundleProblems(List<String[]> parsed) {
        if (context == null) {
            return null;
        }
        Set<String> named = new LinkedHashSet<>();
        for (String[] a : parsed) {
            if (!a[0].equals("set")) {
                named.add(a[1]);
            }
        }
        List<String> problems = new ArrayList<>();
        for (String[] a : parsed) {
            if (a[0].equals("set") || a[0].equals("update")) {
                continue; // an update does not start or stop a bundle (D38)
            }
            Instance inst = find(a[1]);
            if (inst == null) {
                continue; // the cell says so
            }
            Bundle bundle = context.getBundle(inst.bundleId);
            if (bundle == null) {
                problems.add(a[0] + " " + a[1] + ": its bundle " + inst.bundleId + " is gone");
                continue;
            }
            if (a[0].equals("install") && bundle.getState() == Bundle.ACTIVE) {
                problems.add("install " + a[1] + ": its bundle " + inst.bundleId + " is started but the component is not"
                        + " running (see arflex:list for why)");
            }
            List<String> others = cell.actor().call(() -> cell.namesOfBundle(inst.bundleId), Services.CALL_MS)
                    .stream().filter(n -> !named.contains(n)).toList();
            if (!others.isEmpty()) {
                problems.add(a[0] + " " + a[1] + ": its bundle " + inst.bundleId + " also carries " + others
                        + ", which the set does not name");
            }
        }
        return problems.isEmpty() ? null : String.join("; ", problems);
    }

    /** After the switch: the bundles of installed components started, of uninstalled ones stopped. */
    private String followBundles(List<String[]> parsed, java.util.Map<String, Long> bundleIds) {
        if (context == null) {
            return "";
        }
        StringBuilder sb = new StringBuilder();
        for (String[] a : parsed) {
            if (a[0].equals("set") || a[0].equals("update")) {
                continue;
            }
            long id = bundleIds.getOrDefault(a[1], -1L);
            Bundle bundle = id < 0 ? null : context.getBundle(id);
            if (bundle == null) {
                continue;
            }
            try {
                if (a[0].equals("install")) {
                    bundle.start();
                } else {
                    bundle.stop();
                }
                sb.append("bundle ").append(id).append(a[0].equals("install") ? " started" : " stopped").append('\n');
            } catch (BundleException | IllegalStateException e) {
                String p = "change set: bundle " + id + " of '" + a[1] + "' could not be "
                        + (a[0].equals("install") ? "started" : "stopped") + ": " + e.getMessage();
                log.accept("arflex: " + p);
                sb.append("warning: ").append(p).append('\n');
            }
        }
        return sb.toString();
    }

    /** After a committed update: its bundle is updated to the jar that runs (D43). */
    private String followUpdates(List<String[]> parsed, java.util.Map<String, Long> bundleIds,
                                 java.util.Map<String, Version> read, String verdict) {
        UpdatedBundles b = bundles;
        StringBuilder sb = new StringBuilder();
        for (String[] a : parsed) {
            if (b != null && a[0].equals("update") && bundleIds.containsKey(a[1]) && read.containsKey(a[1])
                    && verdict.contains("update " + a[1] + ": committed")) {
                sb.append(b.follow(bundleIds.get(a[1]), a[1], read.get(a[1]).jar()));
            }
        }
        return sb.toString();
    }

    /** The instance of that name, looked up on the actor (which alone changes the registry). */
    private Instance find(String name) {
        return cell.actor().call(() -> cell.instance(name).orElse(null), Services.CALL_MS);
    }

    private static ChangeSetDTO dto(List<String> actions, ChangeSetResult r) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = actions.toArray(String[]::new);
        d.admitted = r.admitted();
        d.applied = r.applied();
        d.refusal = r.refusal();
        d.text = r.text();
        d.prepareMs = r.prepareMs();
        d.switchUs = r.switchUs();
        return d;
    }

    private static ChangeSetDTO refused(List<String> actions, String why) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = actions.toArray(String[]::new);
        d.refusal = why;
        d.text = "change set: " + String.join("; ", actions) + "\nrefused: " + why + "\n";
        return d;
    }
}
