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

    private final Cell cell;
    private final BundleContext context;
    private volatile Executables executables = (b, c) -> {
        throw new IOException("the DRCR is not started yet");
    };
    private final Consumer<String> log;

    public ChangeSets(Cell cell, BundleContext context, Consumer<String> log) {
        this.cell = cell;
        this.context = context;
        this.log = log;
    }

    /** Where the executables of installs come from (the extender, built after this service). */
    public void executables(Executables e) {
        executables = e;
    }

    /** The actions, parsed: {@code install n}, {@code uninstall n}, {@code set n p v}, also as one token list. */
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
                default -> throw new IllegalArgumentException("unknown action '" + verb
                        + "' (actions: install <component>, uninstall <component>, set <component> <parameter> <value>)");
            };
            if (i + n > tokens.size()) {
                throw new IllegalArgumentException("'" + String.join(" ", tokens.subList(i, tokens.size()))
                        + "' is incomplete (" + verb + (n == 2 ? " <component>" : " <component> <parameter> <value>") + ")");
            }
            out.add(tokens.subList(i, i + n).toArray(String[]::new));
            i += n;
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
        ChangeSet set = build(parsed, false);
        ChangeSetResult r = cell.actor().call(() -> cell.planChangeSet(set), Services.CALL_MS);
        String bundles = r.admitted() ? bundleProblems(parsed) : null;
        return bundles != null ? refused(actions, bundles) : dto(actions, r);
    }

    @Override
    public ChangeSetDTO apply(List<String> actions) {
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
        // refused sets are refused before anything is extracted from a bundle
        ChangeSetResult dry = cell.actor().call(() -> cell.planChangeSet(build(parsed, false)), Services.CALL_MS);
        if (!dry.admitted()) {
            return dto(actions, dry);
        }
        ChangeSet set;
        try {
            set = build(parsed, true);
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
        return d;
    }

    /** The cell's change set; {@code extract}: the executables of installs are checked and extracted. */
    private ChangeSet build(List<String[]> parsed, boolean extract) {
        ChangeSet.Builder b = ChangeSet.builder();
        for (String[] a : parsed) {
            switch (a[0]) {
                case "install" -> b.install(a[1], extract ? executable(a[1]) : Path.of("(not extracted in a dry run)"));
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
            if (a[0].equals("set")) {
                continue;
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
            if (a[0].equals("set")) {
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
