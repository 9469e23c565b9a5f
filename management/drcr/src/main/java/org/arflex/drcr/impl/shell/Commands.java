package org.arflex.drcr.impl.shell;

import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;
import java.util.Optional;
import java.util.function.Function;
import org.arflex.drcr.CellReset;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.UpdateService;
import org.arflex.drcr.dto.BindingDTO;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.ParamDTO;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.dto.PortValueDTO;
import org.arflex.drcr.dto.ResourcesDTO;
import org.arflex.drcr.dto.StatsDTO;

/**
 * The Gogo commands of scope {@code arflex}. Plain public methods (Gogo finds them by name);
 * each returns the text to print. They use the DRCR's public services only, exactly as the web
 * console does. Errors come back as a line starting with {@code error:} (Gogo would otherwise
 * print a stack trace).
 */
public final class Commands {

    /** Service property values for the Gogo registration. */
    public static final String SCOPE = "arflex";
    public static final String[] FUNCTIONS = {"list", "info", "bindings", "get", "set", "plan", "update", "deploy",
        "resources", "stats", "port", "reset", "dto", "summary", "await", "change"};

    private final DrcrService drcr;
    private final ResourceManager resources;
    private final UpdateService updates;
    private final Function<String, Optional<ComponentManagement>> management;
    private final BundleUpdater bundles;
    private final CellSummary.Ports ports;
    private final Readiness readiness;
    private final ChangeSetService changeSets;

    /** Bundle installs and updates through the DRCR's fetch and code gate. */
    public interface BundleUpdater {
        /**
         * Updates bundle {@code id} (from {@code location} when not null, checked against
         * {@code sha256} when not null); returns a report.
         */
        String update(long id, String location, String sha256);

        /**
         * Installs (or updates) and starts the bundle at {@code location}, checked against
         * {@code sha256}, or (null) by its signature.
         */
        String deploy(String location, String sha256);
    }

    public Commands(DrcrService drcr, ResourceManager resources, UpdateService updates,
                    Function<String, Optional<ComponentManagement>> management, BundleUpdater bundles) {
        this(drcr, resources, updates, management, bundles, (c, p) -> null, new CellWatch());
    }

    /**
     * Commands whose {@code summary} reads ports through {@code ports} and whose {@code await}
     * wakes up on the changes {@code watch} is told of.
     */
    public Commands(DrcrService drcr, ResourceManager resources, UpdateService updates,
                    Function<String, Optional<ComponentManagement>> management, BundleUpdater bundles,
                    CellSummary.Ports ports, CellWatch watch) {
        this(drcr, resources, updates, management, bundles, ports, watch, null);
    }

    /** As above, with the change sets of {@code arflex:change} (D35). */
    public Commands(DrcrService drcr, ResourceManager resources, UpdateService updates,
                    Function<String, Optional<ComponentManagement>> management, BundleUpdater bundles,
                    CellSummary.Ports ports, CellWatch watch, ChangeSetService changeSets) {
        this.changeSets = changeSets;
        this.drcr = drcr;
        this.resources = resources;
        this.updates = updates;
        this.management = management;
        this.bundles = bundles;
        this.ports = ports;
        this.readiness = new Readiness(drcr, watch);
    }

    /** One line per instance: name, state, pid, cpu, reason. */
    public String list() {
        CellDTO c = drcr.cell();
        if (c.instances.length == 0) {
            return "no components";
        }
        int w = 4;
        for (InstanceDTO i : c.instances) {
            w = Math.max(w, i.name.length());
        }
        StringBuilder sb = new StringBuilder(String.format("%-" + w + "s  %-11s  %7s  %3s  %s%n", "NAME", "STATE", "PID", "CPU", "REASON"));
        for (InstanceDTO i : c.instances) {
            boolean holding = i.holding != null && "ACTIVE".equals(i.state);
            String reason = holding ? i.holding : i.failureReason == null ? "" : i.failureReason;
            sb.append(String.format("%-" + w + "s  %-11s  %7s  %3s  %s%n", i.name, holding ? "HOLDING" : i.state,
                    i.pid == 0 ? "-" : Long.toString(i.pid), i.cpu < 0 ? "-" : Integer.toString(i.cpu), reason));
        }
        for (String p : c.problems) {
            sb.append("problem: ").append(p).append('\n');
        }
        return sb.toString().stripTrailing();
    }

    /** Contract and instance details of one component. */
    public String info(String name) {
        Optional<InstanceDTO> oi = drcr.instance(name);
        if (oi.isEmpty()) {
            return "error: no component '" + name + "'";
        }
        InstanceDTO i = oi.get();
        var c = drcr.contract(name).orElseThrow();
        StringBuilder sb = new StringBuilder();
        sb.append(c.name).append(' ').append(c.version).append(" (bundle ").append(c.bundleId).append(", ").append(c.source).append(")\n");
        sb.append("  state ").append(i.state).append(", target ").append(i.targetState);
        if (i.failureReason != null) {
            sb.append(", reason: ").append(i.failureReason);
        }
        if (i.holding != null) {
            sb.append(", HOLDING: ").append(i.holding);
        }
        sb.append('\n');
        sb.append("  pid ").append(i.pid == 0 ? "-" : i.pid).append(", cpu ").append(i.cpu < 0 ? "-" : i.cpu)
                .append(", restarts ").append(i.restarts).append(" (").append(i.restartsLeft).append(" left)")
                .append(i.awaitingReset ? ", awaiting operator reset" : "").append(i.safeMode ? ", safe mode" : "").append('\n');
        sb.append("  timing: ").append(c.taskType).append(" period ").append(c.periodNs).append(" ns, deadline ")
                .append(c.deadlineNs).append(" ns, wcet ").append(c.wcetNs).append(" ns, priority ").append(c.priority).append('\n');
        sb.append("  fault: ").append(c.restart).append(" intensity ").append(c.intensity).append("/").append(c.windowMs)
                .append(" ms, backoff ").append(c.backoffMs).append(" ms, safe ").append(c.safeOutput)
                .append(c.movesHardware ? ", moves hardware" : "").append('\n');
        for (var p : c.ports) {
            sb.append("  ").append(p.direction.toLowerCase()).append(' ').append(p.name).append(": ").append(p.type)
                    .append(' ').append(p.typeVersion).append(' ').append(p.method.toLowerCase());
            if (p.binding != null) {
                sb.append(" from ").append(p.binding);
            }
            for (BindingDTO b : i.bindings) {
                if (b.input.equals(p.name) && "IN".equals(p.direction) && b.rejected > 0) {
                    sb.append(", ").append(b.rejected).append(" values from ").append(b.provider).append(" refused");
                }
            }
            sb.append('\n');
        }
        for (ParamDTO p : i.params) {
            sb.append("  param ").append(p.name).append(" = ").append(p.value).append(p.unit.isEmpty() ? "" : " " + p.unit)
                    .append(" (").append(p.type.toLowerCase()).append(p.mutable ? ", mutable" : ", immutable").append(")\n");
        }
        return sb.toString().stripTrailing();
    }

    /** Every wire of the cell. */
    public String bindings() {
        CellDTO c = drcr.cell();
        if (c.bindings.length == 0) {
            return "no bindings";
        }
        StringBuilder sb = new StringBuilder();
        for (BindingDTO b : c.bindings) {
            sb.append(b.consumer).append('.').append(b.input).append(" <- ").append(b.provider).append('.').append(b.output)
                    .append(b.rejected > 0 ? " (" + b.rejected + " values refused)" : "").append('\n');
        }
        return sb.toString().stripTrailing();
    }

    /** A parameter as the RT half applied it. */
    public String get(String name, String param) {
        return guard(() -> cm(name).get(param));
    }

    /** Sets a parameter; prints the applied value. */
    public String set(String name, String param, String value) {
        return guard(() -> name + "." + param + " = " + cm(name).set(param, value));
    }

    /**
     * Dry runs: {@code plan install <url>}, {@code plan update <name>}, {@code plan uninstall <name>},
     * {@code plan cpus 0,1 [memory m] [network n]}.
     */
    public String plan(String... args) {
        return guard(() -> {
            if (args.length == 2 && args[0].equals("install")) {
                return drcr.planInstall(args[1]);
            }
            if (args.length == 2 && args[0].equals("update")) {
                return drcr.planUpdate(args[1]);
            }
            if (args.length == 2 && args[0].equals("uninstall")) {
                return drcr.planUninstall(args[1]);
            }
            if (args.length >= 1 && (args[0].equals("cpus") || args[0].equals("memory") || args[0].equals("network"))) {
                ResourcesDTO r = resources.resources();
                Caps caps = parseCaps(args, r);
                return drcr.planCapacity(caps.cpus, caps.memory, caps.network);
            }
            return "usage: plan install <jar-url> | plan update <name> | plan uninstall <name> | plan [cpus <list>] [memory <bytes>] [network <B/s>]";
        });
    }

    /**
     * Change sets (D35): {@code change plan <actions>} is the dry run of the whole set,
     * {@code change apply <actions>} applies it all or nothing; actions are
     * {@code install <component>} (its bundle installed, not started), {@code uninstall <component>},
     * {@code set <component> <parameter> <value>} and {@code update <component> <jar URL> [<sha256>]
     * [window <cycles>] [shadow <cycles>] [envelope ...] [tolerance ...]} (D38, D42; a shadow run of a
     * component with a state block needs a new half that can re-adopt it, D70), in any number, e.g.
     * {@code change apply install teach uninstall trajectory}. {@code change progress}: where the
     * set being applied is, or how the last one ended (D53). {@code change history [<count>]}: the
     * sets in the history (kept in the DRCR's data area across restarts, D66), newest first, each
     * update's last counters and verdict (D62).
     */
    public String change(String... args) {
        return guard(() -> {
            String usage = "usage: change plan|apply <action>... | change progress | change history [<count>] (actions: install <component>, uninstall <component>,"
                    + " set <component> <parameter> <value>, update <component> <jar URL> [<sha256>] [window <cycles>]"
                    + " [shadow <cycles>] [envelope <port>.<field> <min> <max>]... [tolerance <port>.<field> <max difference>]...;"
                    + " shadow: a component with a state block only when its new RT half registers a re-adopt hook"
                    + " (arflex_component_readopt), else the update is refused once that half is READY: apply it with shadow 0)";
            if (changeSets != null && args.length == 1 && args[0].equals("progress")) {
                return ChangeSetProgressText.of(changeSets.progress(), System.currentTimeMillis());
            }
            if (changeSets != null && args.length >= 1 && args.length <= 2 && args[0].equals("history")) {
                if (args.length == 2 && !args[1].matches("[1-9][0-9]{0,2}")) {
                    return "error: change history: '" + args[1] + "' is not a count of sets (1 to 999)";
                }
                return ChangeSetHistoryText.of(changeSets.history(), args.length == 2 ? Integer.parseInt(args[1])
                        : Integer.MAX_VALUE);
            }
            if (changeSets == null || args.length < 2 || !(args[0].equals("plan") || args[0].equals("apply"))) {
                return usage;
            }
            List<String> actions = List.of(Arrays.copyOfRange(args, 1, args.length));
            org.arflex.drcr.dto.ChangeSetDTO d = args[0].equals("plan") ? changeSets.plan(actions)
                    : changeSets.apply(actions);
            return d.refusal != null ? "error: " + d.text.stripTrailing() : d.text.stripTrailing();
        });
    }

    /**
     * Pulls the update of a component from its contract's update URL. A number is a bundle id
     * (component names start with a letter): Gogo resolves a bare {@code update} to this scope,
     * so {@code update <id> [url [sha256]]} behaves as {@code felix:update}, but reads through
     * the DRCR's fetch (https/file, timeouts) and, with a SHA-256, records the jar as verified.
     */
    public String update(String... args) {
        return guard(() -> {
            if (args.length >= 1 && args.length <= 3 && args[0].matches("\\d{1,18}")) {
                return bundles.update(Long.parseLong(args[0]), args.length >= 2 ? args[1] : null,
                        args.length == 3 ? args[2] : null);
            }
            if (args.length != 1) {
                return "usage: update <component> | update <bundle-id> [url [sha256]]";
            }
            return updates.update(args[0]);
        });
    }

    /**
     * {@code deploy <https-or-file-url> [<sha256>]}: the verified install of a bundle, then its
     * start; without a SHA-256 only a jar signed by a key of the runtime's trust store.
     * {@code deploy set <descriptor-url> [plan]}: a deployment set (D45), several bundles from one
     * descriptor as one change set; with {@code plan} the dry run (every jar gated, port formats
     * and admission checked, nothing installed).
     */
    public String deploy(String... args) {
        if (args.length >= 2 && args.length <= 3 && args[0].equals("set") && changeSets != null
                && (args.length == 2 || args[2].equals("plan"))) {
            return guard(() -> {
                org.arflex.drcr.dto.ChangeSetDTO d = changeSets.deploy(args[1], args.length == 2);
                return d.refusal != null ? "error: " + d.text.stripTrailing() : d.text.stripTrailing();
            });
        }
        return guard(() -> (args.length == 1 || args.length == 2) && !args[0].equals("set")
                ? bundles.deploy(args[0], args.length == 2 ? args[1] : null)
                : "usage: deploy <https-or-file-url> [<sha256>] (without a SHA-256: a jar signed by a trusted key)"
                        + " | deploy set <descriptor https-or-file-url> [plan] (a deployment set, D45; plan: the dry run)");
    }

    /** {@code resources} prints capacities; {@code resources set cpus 0,1 memory 512m network 10m} changes them. */
    public String resources(String... args) {
        return guard(() -> {
            if (args.length == 0) {
                ResourcesDTO r = resources.resources();
                StringBuilder sb = new StringBuilder();
                sb.append("cpus:");
                for (int k = 0; k < r.cpus.length; k++) {
                    sb.append(String.format(" %d(U=%.3f)", r.cpus[k], r.cpuUtilisation[k]));
                }
                sb.append("\nmemory: ").append(r.memoryUsed).append(" of ").append(r.memoryBytes).append(" bytes\n");
                sb.append("network: ").append(r.networkUsed).append(" of ").append(r.networkBps).append(" B/s\n");
                sb.append("wcet overruns: ").append(r.wcetOverruns);
                if (r.machine != null) {
                    sb.append("\nmachine: ").append(r.machine);
                }
                if (r.machineChange != null) {
                    sb.append("\nmachine change: ").append(r.machineChange);
                }
                if (r.machineProblem != null) {
                    sb.append("\nmachine problem: ").append(r.machineProblem);
                }
                return sb.toString();
            }
            if (!args[0].equals("set") || args.length < 3) {
                return "usage: resources | resources set [cpus <list>] [memory <bytes>] [network <B/s>]";
            }
            ResourcesDTO r = resources.resources();
            Caps caps = parseCaps(Arrays.copyOfRange(args, 1, args.length), r);
            if (!caps.cpus.equals(toList(r.cpus))) {
                resources.setCpus(caps.cpus);
            }
            if (caps.memory != r.memoryBytes) {
                resources.setMemory(caps.memory);
            }
            if (caps.network != r.networkBps) {
                resources.setNetwork(caps.network);
            }
            return "resources: cpus " + caps.cpus + ", memory " + caps.memory + ", network " + caps.network;
        });
    }

    /** RT statistics of one component. */
    public String stats(String name) {
        return guard(() -> {
            StatsDTO s = cm(name).stats();
            if (s == null) {
                return name + ": no RT half running";
            }
            return name + ": rt " + s.rtState + ", cycles " + s.cycles + ", overruns " + s.overruns + ", wcet overruns "
                    + s.wcetOverruns + ", latency max " + s.maxLatencyNs + " ns, exec max " + s.maxExecNs + " ns, exec mean "
                    + s.meanExecNs + " ns, update errors " + s.updateErrors + ", safe cycles " + s.safeCycles
                    + ", heartbeat age " + s.heartbeatAgeMs + " ms, forged requests ignored " + s.forgedRequests
                    + (s.latencyHistBins == null ? "" : "\n" + name + ": latency p50 " + s.latencyP50Ns + " ns, p99 "
                    + s.latencyP99Ns + " ns, p99.9 " + s.latencyP999Ns + " ns (" + s.latencyCount + " samples, "
                    + s.latencyHistOverflow + " >= " + s.histBinNs * 2000 / 1000 + " us); exec p50 " + s.execP50Ns
                    + " ns, p99 " + s.execP99Ns + " ns, p99.9 " + s.execP999Ns + " ns");
        });
    }

    /** The newest value of an output port (read-only peek), one line per field. */
    public String port(String name, String port) {
        return guard(() -> {
            PortValueDTO v = cm(name).portValue(port);
            String head = name + "." + port + " (" + v.type + " " + v.typeVersion + ", " + v.method.toLowerCase(java.util.Locale.ROOT)
                    + ")";
            if (v.index < 0) {
                return head + ": nothing published yet";
            }
            StringBuilder sb = new StringBuilder(head + ": element " + v.index + ", " + v.published + " published");
            for (PortFieldDTO f : v.fields) {
                sb.append("\n  ").append(f.name).append(" = ");
                for (int i = 0; i < f.values.length; i++) {
                    sb.append(i == 0 ? "" : ", ").append(f.scalar.startsWith("f") ? Double.toString(f.values[i])
                            : Long.toString((long) f.values[i]));
                }
                sb.append(f.truncated ? ", ... (" + f.count + ")" : "").append(f.unit.isEmpty() ? "" : " " + f.unit);
            }
            return sb.toString();
        });
    }

    /** Operator reset of one component, or of every one that waits ({@code --cell}). */
    public String reset(String name) {
        if ("--cell".equals(name)) {
            return guard(() -> CellReset.run(drcr, n -> cm(n).reset()));
        }
        return guard(() -> {
            cm(name).reset();
            return name + ": reset; now " + drcr.instance(name).map(i -> i.state).orElse("?");
        });
    }

    /**
     * {@code summary [--json]}: the demonstration cell in one line (RT halves, operator resets
     * awaited, robot cycles, vision-measured and TRUE TCP error; {@link CellSummary}).
     */
    public String summary(String... args) {
        return guard(() -> {
            boolean json = args.length == 1 && args[0].equals("--json");
            if (args.length > 0 && !json) {
                return "usage: summary [--json]";
            }
            CellSummary s = CellSummary.of(drcr.cell(), ports);
            return json ? s.json() : s.text();
        });
    }

    /**
     * {@code await <name> [<state>] [--timeout <s>]}: returns once the component is in that
     * state (default ACTIVE); {@code await --cell [--timeout <s>]}: once every component is
     * ACTIVE. Woken by the cell's changes, never polling; on timeout an {@code error:} line naming
     * the component, its state and its reason ({@link Readiness}).
     */
    public String await(String... args) {
        return guard(() -> readiness.await(args));
    }

    /** The whole cell as one line of JSON. */
    public String dto() {
        return Json.write(drcr.cell());
    }

    private ComponentManagement cm(String name) {
        return management.apply(name).orElseThrow(() -> new IllegalArgumentException("no component '" + name + "'"));
    }

    private interface Body {
        String run();
    }

    private static String guard(Body b) {
        try {
            return b.run();
        } catch (RuntimeException e) {
            return "error: " + e.getMessage();
        }
    }

    private record Caps(List<Integer> cpus, long memory, long network) {
    }

    private static List<Integer> toList(int[] a) {
        List<Integer> l = new ArrayList<>();
        for (int x : a) {
            l.add(x);
        }
        return l;
    }

    private static Caps parseCaps(String[] args, ResourcesDTO current) {
        List<Integer> cpus = toList(current.cpus);
        long mem = current.memoryBytes;
        long net = current.networkBps;
        if (args.length % 2 != 0) {
            throw new IllegalArgumentException("expected pairs of <cpus|memory|network> <value>, got " + Arrays.toString(args));
        }
        for (int i = 0; i < args.length; i += 2) {
            switch (args[i]) {
                case "cpus" -> cpus = parseCpus(args[i + 1]);
                case "memory" -> mem = parseSize(args[i + 1]);
                case "network" -> net = parseSize(args[i + 1]);
                default -> throw new IllegalArgumentException("unknown resource '" + args[i] + "' (cpus, memory, network)");
            }
        }
        return new Caps(cpus, mem, net);
    }

    /** {@code 0,1}, {@code 1-3}, {@code none}. */
    public static List<Integer> parseCpus(String s) {
        List<Integer> out = new ArrayList<>();
        if (s.equals("none") || s.isBlank()) {
            return out;
        }
        for (String part : s.split(",")) {
            String p = part.trim();
            try {
                int dash = p.indexOf('-');
                if (dash > 0) {
                    int a = Integer.parseInt(p.substring(0, dash));
                    int b = Integer.parseInt(p.substring(dash + 1));
                    if (a > b || b - a > 1024) {
                        throw new IllegalArgumentException("bad cpu range '" + p + "'");
                    }
                    for (int k = a; k <= b; k++) {
                        out.add(k);
                    }
                } else {
                    out.add(Integer.parseInt(p));
                }
            } catch (NumberFormatException e) {
                throw new IllegalArgumentException("bad cpu list '" + s + "' (examples: 0,1 or 1-3 or none)");
            }
        }
        return out;
    }

    /** Bytes with optional k/m/g suffix (binary multiples). */
    public static long parseSize(String s) {
        String t = s.trim().toLowerCase();
        long mul = 1;
        if (t.endsWith("k")) {
            mul = 1L << 10;
        } else if (t.endsWith("m")) {
            mul = 1L << 20;
        } else if (t.endsWith("g")) {
            mul = 1L << 30;
        }
        if (mul != 1) {
            t = t.substring(0, t.length() - 1);
        }
        try {
            long v = Long.parseLong(t);
            if (v < 0) {
                throw new NumberFormatException();
            }
            return Math.multiplyExact(v, mul);
        } catch (NumberFormatException | ArithmeticException e) {
            throw new IllegalArgumentException("bad size '" + s + "' (a number of bytes, k/m/g suffix allowed)");
        }
    }
}
