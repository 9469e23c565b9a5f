package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.net.URI;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.concurrent.ConcurrentHashMap;
import java.util.function.BiFunction;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ContractReader;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;

/**
 * Deployment sets (docs/DECISIONS.md D45): a descriptor at one URL ({@link DeploymentDescriptor})
 * names several bundles, new components and updates of running ones, applied as one change set.
 *
 * <p>In this order, and nothing changes until the last step:
 * <ol>
 * <li>the descriptor is fetched ({@link Fetch}: https/file, timeouts, no redirects) and parsed
 * strictly;</li>
 * <li>every jar is fetched and admitted by the code gate, as every install is: its SHA-256 equals
 * the pin, or every entry is signed by a key of the trust store; its contracts are read. Every
 * jar that fails is named with why, and the set is refused whole;</li>
 * <li>the set must fit the cell: a new component's name is not known to the cell, its jar's
 * location is not installed in Felix, an updated one runs;</li>
 * <li>port formats ({@link PortFormats}): each new contract's ports against the peers they will
 * be bound to;</li>
 * <li>the planner's dry run of the whole set: every new or updated component is admitted, and
 * nothing the set does not name stops, restarts or holds;</li>
 * <li>applying only: the new components' bundles are installed in Felix, not started (their
 * components show as INSTALLED), and the set is handed to the {@link ChangeSets} as
 * {@code install <component>...} and {@code update <component> <jar> ...} actions; the update
 * jars are not fetched again ({@link #versions}), then its uninstalls and writes. A set the
 * change set refuses, tears down or rejects in a shadow run leaves no bundle behind: the
 * bundles installed for it are uninstalled again; a set one of whose updates is rolled back
 * after the switch is taken back ({@link DeploymentUndo}, D50).</li>
 * </ol>
 * A set refused before its change set is recorded in the change-set history (D50), as the change
 * set's own outcome is.
 */
public final class DeploymentSets {

    /** A jar read for the set: its bytes (as checked), how the gate admitted it, its contracts. */
    record Jar(DeploymentDescriptor.Entry entry, byte[] bytes, String how, List<Contract> contracts,
               ChangeSets.Version version) {
    }

    private final Cell cell;
    private final BundleContext context;
    private final VerifiedInstaller installer;
    private final CodeGate gate;
    private final BiFunction<String, byte[], ContractReader.Result> contracts;
    private final ChangeSets.Versions updates;
    private final ChangeSetService changeSets;
    private final Consumer<String> log;
    private final DeploymentUndo undo;
    /** Where refusals before the change set are recorded (the change sets' history, D50); null: nowhere. */
    private volatile ChangeSetHistory history;
    /** The update jars a set being applied has read, by component, URL and pin, for the change set. */
    private final Map<String, ChangeSets.Version> held = new ConcurrentHashMap<>();

    /**
     * @param contracts reads the contracts of a jar held in memory ({@code Services.readJar})
     * @param updates   reads an update's jar (fetched, gated, its contract read: {@link UpdateJars})
     */
    public DeploymentSets(Cell cell, BundleContext context, VerifiedInstaller installer, CodeGate gate,
                          BiFunction<String, byte[], ContractReader.Result> contracts, ChangeSets.Versions updates,
                          ChangeSetService changeSets, Consumer<String> log) {
        this.cell = cell;
        this.context = context;
        this.installer = installer;
        this.gate = gate;
        this.contracts = contracts;
        this.updates = updates;
        this.changeSets = changeSets;
        this.log = log;
        this.undo = new DeploymentUndo(changeSets, log);
    }

    /** Records refusals made before the change set into {@code h} (the change sets' own history). */
    void recordInto(ChangeSetHistory h) {
        history = h;
    }

    /**
     * What the change sets read updates through: the version a deployment set read already
     * (the same bytes it checked), else {@code updates}.
     */
    public ChangeSets.Versions versions() {
        return (component, location, sha256) -> {
            ChangeSets.Version v = held.get(key(component, location, sha256));
            return v != null ? v : updates.read(component, location, sha256);
        };
    }

    private static String key(String component, String location, String sha256) {
        return component + " " + location + " " + (sha256 == null ? "" : sha256.toLowerCase(java.util.Locale.ROOT));
    }

    /**
     * Plans ({@code apply} false: the dry run, nothing installed) or applies the deployment set
     * at {@code url}.
     */
    public ChangeSetDTO deploy(String url, boolean apply) {
        boolean[] handedOver = {false};
        ChangeSetDTO d = deployOnce(url, apply, handedOver);
        ChangeSetHistory h = history;
        if (apply && !handedOver[0] && h != null) {
            h.record(d); // a set's change set records its own outcome; a refusal before it is recorded here
        }
        return d;
    }

    private ChangeSetDTO deployOnce(String url, boolean apply, boolean[] handedOver) {
        StringBuilder text = new StringBuilder();
        URI source;
        try {
            source = URI.create(url);
        } catch (IllegalArgumentException e) {
            return refused(url, text, "'" + url + "' is not a URL: " + e.getMessage());
        }
        byte[] xml;
        try {
            xml = Fetch.read(source);
        } catch (IOException | IllegalArgumentException e) {
            return refused(url, text, "cannot read the descriptor " + url + ": " + e.getMessage());
        }
        DeploymentDescriptor d;
        try {
            d = DeploymentDescriptor.parse(xml, source);
        } catch (IllegalArgumentException e) {
            return refused(url, text, "descriptor: " + e.getMessage());
        }
        text.append("deployment set ").append(d.name() == null ? "" : d.name() + " ").append("from ").append(url)
                .append(": ").append(d.bundles().size()).append(d.bundles().size() == 1 ? " bundle" : " bundles")
                .append(d.changes().isEmpty() ? "" : ", " + d.changes().size() + (d.changes().size() == 1 ? " change"
                        : " changes")).append('\n');
        // 2. every jar through the gate; all failures named, nothing installed
        List<Jar> jars = new ArrayList<>();
        List<String> failed = new ArrayList<>();
        for (DeploymentDescriptor.Entry e : d.bundles()) {
            try {
                Jar j = read(e);
                jars.add(j);
                text.append("  ").append(line(j)).append('\n');
            } catch (IOException | RuntimeException ex) {
                String why = "jar " + e.jar() + " (line " + e.line() + ", " + (e.kind() == DeploymentDescriptor.Kind.INSTALL
                        ? "install" : "update " + e.component()) + "): " + ex.getMessage();
                failed.add(why);
                text.append("  REFUSED ").append(why).append('\n');
            }
        }
        if (!failed.isEmpty()) {
            return refused(url, text, String.join("; ", failed) + "; nothing installed");
        }
        // 3. the set against the cell and Felix
        d.changes().forEach(e -> text.append("  ").append(e.action()).append('\n'));
        String misfit = misfit(jars, d.changes());
        if (misfit != null) {
            return refused(url, text, misfit + "; nothing installed");
        }
        // 4. port formats, before anything is installed or spawned
        List<Contract> installs = new ArrayList<>();
        List<Contract> updated = new ArrayList<>();
        for (Jar j : jars) {
            if (j.version() != null) {
                updated.add(j.version().contract());
            } else {
                installs.addAll(j.contracts());
            }
        }
        List<String> changes = cell.actor().call(() -> DeploymentChanges.check(d.changes(), cell.planner().contracts(),
                installs, updated), Services.CALL_MS);
        if (!changes.isEmpty()) {
            return refused(url, text, String.join("; ", changes) + "; nothing installed");
        }
        Set<String> uninstalls = new LinkedHashSet<>();
        d.changes().stream().filter(e -> e.kind() == DeploymentDescriptor.Kind.UNINSTALL)
                .forEach(e -> uninstalls.add(e.component()));
        PortFormats formats = new PortFormats(cell.config().types());
        List<String> formatProblems = cell.actor().call(() -> formats.check(cell.planner().contracts(),
                cell.planner().wires(), installs, updated, uninstalls), Services.CALL_MS);
        if (!formatProblems.isEmpty()) {
            return refused(url, text, "port formats: " + String.join("; ", formatProblems) + "; nothing installed");
        }
        // 5. the planner's dry run of the whole set
        Change.Builder b = Change.builder();
        installs.forEach(b::install);
        updated.forEach(b::replace);
        uninstalls.forEach(b::uninstall);
        Change change = b.build();
        Plan plan;
        try {
            plan = cell.actor().call(() -> cell.dryRun(change), Services.CALL_MS);
        } catch (IllegalArgumentException e) {
            return refused(url, text, "the planner refused the set: " + e.getMessage() + "; nothing installed");
        }
        String admission = admission(plan, installs, updated, uninstalls);
        if (admission != null) {
            text.append(plan.toText());
            return refused(url, text, admission + "; nothing installed");
        }
        if (!apply) {
            ChangeSetDTO dto = dto(url, text.append("admitted (dry run: nothing installed, nothing changed)\n")
                    .append(plan.toText()).toString());
            dto.admitted = true;
            return dto;
        }
        return applySet(url, text, jars, d.changes(), handedOver);
    }

    /** 6: the bundles of new components installed, not started; the set applied; undone when refused. */
    private ChangeSetDTO applySet(String url, StringBuilder text, List<Jar> jars, List<DeploymentDescriptor.Entry> changes,
                                  boolean[] handedOver) {
        List<Bundle> installed = new ArrayList<>();
        List<String> newComponents = new ArrayList<>();
        List<String> actions = new ArrayList<>();
        List<String> keys = new ArrayList<>();
        try {
            for (Jar j : jars) {
                if (j.version() != null) {
                    continue;
                }
                Bundle bundle;
                try {
                    bundle = context.installBundle(j.entry().jar().toString(), new ByteArrayInputStream(j.bytes()));
                } catch (BundleException | IllegalStateException e) {
                    return undone(url, text, installed, "install of " + j.entry().jar() + " in Felix failed: "
                            + e.getMessage());
                }
                installed.add(bundle);
                log.accept("arflex: deployment set " + url + ": bundle " + bundle.getBundleId() + " installed from "
                        + j.entry().jar() + " (" + j.how() + "), not started");
                for (Contract c : j.contracts()) {
                    Long by = cell.actor().call(() -> cell.instance(c.name()).map(i -> i.bundleId).orElse(null),
                            Services.CALL_MS);
                    if (by == null || by != bundle.getBundleId()) {
                        return undone(url, text, installed, "bundle " + bundle.getBundleId() + " from " + j.entry().jar()
                                + ": its component '" + c.name() + "' did not appear in the cell as INSTALLED");
                    }
                    actions.add("install " + c.name());
                    newComponents.add(c.name());
                }
            }
            for (Jar j : jars) {
                if (j.version() != null) {
                    DeploymentDescriptor.Entry e = j.entry();
                    String k = key(e.component(), e.jar().toString(), e.sha256());
                    held.put(k, j.version());
                    keys.add(k);
                    actions.add(e.updateAction());
                }
            }
            changes.forEach(e -> actions.add(e.action()));
            DeploymentUndo.Done done = done(installed, newComponents, jars, changes);
            handedOver[0] = true;
            ChangeSetDTO r = changeSets.apply(actions);
            text.append(r.text);
            if (!r.applied) {
                return undone(url, text, installed, r.refusal == null ? "not applied" : r.refusal);
            }
            List<String> back = DeploymentUndo.notHeld(r.text, done.updated());
            if (!back.isEmpty()) {
                String why = undo.takeBack(url, text, done, back);
                ChangeSetDTO dto = refused(url, text, why);
                dto.actions = actions.toArray(String[]::new);
                dto.admitted = true;
                dto.applied = true;
                dto.prepareMs = r.prepareMs;
                dto.switchUs = r.switchUs;
                return dto;
            }
            ChangeSetDTO dto = dto(url, text.toString());
            dto.actions = actions.toArray(String[]::new);
            dto.admitted = true;
            dto.applied = true;
            dto.prepareMs = r.prepareMs;
            dto.switchUs = r.switchUs;
            log.accept("arflex: deployment set " + url + " applied: " + String.join("; ", actions));
            return dto;
        } catch (RuntimeException e) {
            return undone(url, text, installed, "failed: " + e);
        } finally {
            keys.forEach(held::remove);
        }
    }

    /** What the set will change, for {@link DeploymentUndo}: the old values of its writes read now. */
    private DeploymentUndo.Done done(List<Bundle> installed, List<String> newComponents, List<Jar> jars,
                                     List<DeploymentDescriptor.Entry> changes) {
        List<String> updated = jars.stream().filter(j -> j.version() != null).map(j -> j.entry().component()).toList();
        List<String> uninstalled = changes.stream().filter(e -> e.kind() == DeploymentDescriptor.Kind.UNINSTALL)
                .map(DeploymentDescriptor.Entry::component).toList();
        Map<String, String> old = new LinkedHashMap<>();
        for (DeploymentDescriptor.Entry e : changes) {
            if (e.kind() == DeploymentDescriptor.Kind.SET && !newComponents.contains(e.component())
                    && !updated.contains(e.component())) {
                old.put(e.component() + " " + e.parameter(), cell.actor().call(() -> cell.getParam(e.component(),
                        e.parameter()), Services.CALL_MS));
            }
        }
        return new DeploymentUndo.Done(List.copyOf(installed), List.copyOf(newComponents), uninstalled, updated, old);
    }

    /** Reads and gates one jar; an update's through {@link #updates}, which also reads its contract. */
    private Jar read(DeploymentDescriptor.Entry e) throws IOException {
        String location = e.jar().toString();
        if (e.kind() == DeploymentDescriptor.Kind.UPDATE) {
            ChangeSets.Version v = updates.read(e.component(), location, e.sha256());
            return new Jar(e, v.jar(), v.how(), List.of(v.contract()), v);
        }
        byte[] jar = installer.fetch(location, e.sha256()); // the pin checked (and recorded by the gate)
        String how = "sha256 verified";
        if (e.sha256() == null) {
            JarSignatures.Verdict v = gate.signature(location, jar);
            if (!v.accepted()) {
                throw new IOException("not signed by a trusted key: " + v.reason() + "; pin its SHA-256 (sha256=\"...\") "
                        + "or sign it with a key of the trust store " + gate.trustStore());
            }
            how = v.describe();
        }
        ContractReader.Result r = contracts.apply(location, jar);
        if (!r.problems().isEmpty()) {
            throw new IOException("its contracts are refused: " + String.join("; ", r.problems()));
        }
        if (r.contracts().isEmpty()) {
            throw new IOException("it carries no component contract");
        }
        return new Jar(e, jar, how, r.contracts(), null);
    }

    private static String line(Jar j) {
        if (j.version() != null) {
            return "update " + j.entry().component() + " -> " + j.version().contract().version() + " from "
                    + j.entry().jar() + " (" + j.how() + ")" + (j.entry().window() == null ? "" : ", window "
                    + j.entry().window()) + (j.entry().shadow() == null ? "" : ", shadow " + j.entry().shadow())
                    + (j.entry().options().isEmpty() ? "" : ", " + String.join(", ", j.entry().options()));
        }
        return "install " + String.join(", ", j.contracts().stream().map(c -> c.name() + " " + c.version()).toList())
                + " from " + j.entry().jar() + " (" + j.how() + ")";
    }

    /** Why the set does not fit the cell or Felix as they are, or null. */
    private String misfit(List<Jar> jars, List<DeploymentDescriptor.Entry> changes) {
        List<String> problems = new ArrayList<>();
        Set<String> named = new LinkedHashSet<>();
        List<String> uninstalled = changes.stream().filter(e -> e.kind() == DeploymentDescriptor.Kind.UNINSTALL)
                .map(DeploymentDescriptor.Entry::component).toList();
        for (String n : uninstalled) {
            problems.addAll(uninstallMisfit(n, uninstalled));
        }
        for (Jar j : jars) {
            for (Contract c : j.contracts()) {
                if (!named.add(c.name())) {
                    problems.add("'" + c.name() + "' is named twice in the set (" + j.entry().jar() + ")");
                }
            }
            if (j.version() != null) {
                String n = j.entry().component();
                boolean running = cell.actor().call(() -> cell.planner().contract(n).isPresent(), Services.CALL_MS);
                if (!running) {
                    String state = cell.actor().call(() -> cell.instance(n).isPresent() ? cell.state(n) : null,
                            Services.CALL_MS);
                    problems.add("update " + n + ": '" + n + "' is not running" + (state == null ? " (no such component)"
                            : " (" + state + "); install it instead"));
                }
                continue;
            }
            Bundle b = context == null ? null : context.getBundle(j.entry().jar().toString());
            if (b != null) {
                problems.add("install " + j.entry().jar() + ": already installed as bundle " + b.getBundleId()
                        + " (uninstall it, or name its components in an arflex:change set)");
            }
            for (Contract c : j.contracts()) {
                String state = cell.actor().call(() -> cell.instance(c.name()).isPresent() ? cell.state(c.name()) : null,
                        Services.CALL_MS);
                if (state != null) {
                    problems.add("install " + c.name() + " (" + j.entry().jar() + "): '" + c.name() + "' is known to "
                            + "the cell already (" + state + ")" + (state.equals("INSTALLED")
                            ? ": its bundle is installed, name it in arflex:change (install " + c.name() + ")"
                            : ": update it instead"));
                }
            }
        }
        return problems.isEmpty() ? null : String.join("; ", problems);
    }

    /**
     * An uninstall's bundle stops when the set is applied (as in arflex:change): it may carry no
     * component the set does not uninstall too.
     */
    private List<String> uninstallMisfit(String n, List<String> uninstalled) {
        Long bundle = cell.actor().call(() -> cell.instance(n).map(i -> i.bundleId).orElse(null), Services.CALL_MS);
        if (bundle == null || context == null) {
            return List.of(); // not running: DeploymentChanges says so
        }
        List<String> others = cell.actor().call(() -> cell.namesOfBundle(bundle), Services.CALL_MS).stream()
                .filter(o -> !uninstalled.contains(o)).toList();
        return others.isEmpty() ? List.of() : List.of("uninstall " + n + ": its bundle " + bundle + " also carries "
                + others + ", which the set does not uninstall");
    }

    /** The change-set rules (D35) on the planner's dry run: why the set would not be admitted, or null. */
    static String admission(Plan plan, List<Contract> installs, List<Contract> updates) {
        return admission(plan, installs, updates, Set.of());
    }

    /** As above; a component the set uninstalls may stop. */
    static String admission(Plan plan, List<Contract> installs, List<Contract> updates, Set<String> uninstalls) {
        List<String> refused = new ArrayList<>();
        Set<String> updated = new LinkedHashSet<>();
        updates.forEach(c -> updated.add(c.name()));
        Map<String, String> named = new LinkedHashMap<>();
        installs.forEach(c -> named.put(c.name(), "install"));
        updates.forEach(c -> named.put(c.name(), "update"));
        for (var e : named.entrySet()) {
            if (!plan.activeAfter().contains(e.getKey())) {
                refused.add(e.getValue() + " " + e.getKey() + ": not admitted: "
                        + plan.inactiveAfter().getOrDefault(e.getKey(), "not active"));
            }
        }
        for (Plan.Action a : plan.actions()) {
            switch (a.op()) {
                case STOP -> {
                    if (!uninstalls.contains(a.component())) {
                        refused.add("the set would stop '" + a.component() + "' (" + a.reason() + ")");
                    }
                }
                case RESTART -> {
                    if (!updated.contains(a.component())) {
                        refused.add("the set would restart '" + a.component() + "' (" + a.reason()
                                + "): a change set switches without restarts");
                    }
                }
                case HOLD -> refused.add("the set would hold '" + a.component() + "' in a protective stop (" + a.reason()
                        + ")");
                default -> {
                }
            }
        }
        return refused.isEmpty() ? null : String.join("; ", refused);
    }

    /** Uninstalls what the set installed in Felix, and says so. */
    private ChangeSetDTO undone(String url, StringBuilder text, List<Bundle> installed, String why) {
        undo.uninstall(url, text, installed);
        return refused(url, text, why);
    }

    private ChangeSetDTO refused(String url, StringBuilder text, String why) {
        log.accept("arflex: deployment set " + url + " refused: " + why);
        ChangeSetDTO d = dto(url, text.append("refused: ").append(why).append('\n').toString());
        d.refusal = why;
        return d;
    }

    private static ChangeSetDTO dto(String url, String text) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = new String[] {"deploy " + url};
        d.text = text;
        return d;
    }
}
