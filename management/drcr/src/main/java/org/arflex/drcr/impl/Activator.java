package org.arflex.drcr.impl;

import java.security.SecureRandom;
import java.time.LocalTime;
import java.util.ArrayList;
import java.util.Hashtable;
import java.util.List;
import java.util.Map;
import java.util.concurrent.Executors;
import java.util.concurrent.ScheduledExecutorService;
import java.util.concurrent.ScheduledThreadPoolExecutor;
import java.util.concurrent.TimeUnit;
import java.util.function.Consumer;
import java.util.regex.Pattern;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.UpdateService;
import org.arflex.drcr.dto.PortValueDTO;
import org.arflex.drcr.impl.abi.Posix;
import org.arflex.drcr.impl.extender.ContractExtender;
import org.arflex.drcr.impl.lifecycle.ThreadActor;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ContractReader;
import org.arflex.drcr.impl.runtime.PortValues;
import org.arflex.drcr.impl.services.ResourceManagerImpl;
import org.arflex.drcr.impl.services.CodeGate;
import org.arflex.drcr.impl.services.Services;
import org.arflex.drcr.impl.services.VerifiedInstaller;
import org.arflex.drcr.impl.shell.CellWatch;
import org.arflex.drcr.impl.shell.Commands;
import org.arflex.drcr.impl.supervisor.HeartbeatBridge;
import org.arflex.drcr.impl.supervisor.HalfRecords;
import org.arflex.drcr.impl.supervisor.ProcessLauncher;
import org.arflex.drcr.impl.supervisor.RecordingLauncher;
import org.arflex.drcr.impl.supervisor.VerifiedExecutables;
import org.arflex.planner.Planner;
import org.osgi.annotation.bundle.Header;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleActivator;
import org.osgi.framework.BundleContext;
import org.osgi.framework.Constants;
import org.osgi.framework.ServiceRegistration;
import org.osgi.util.tracker.BundleTracker;

/**
 * Starts the DRCR: sweeps what dead runtimes left, builds the cell (actor, planner, launcher),
 * registers the services and Gogo commands, starts the heartbeat thread and the extender. Stop
 * undoes all of it and leaves no process or shared object behind.
 *
 * <p>Framework properties: {@code arflex.runtime.id} (default {@code rt<pid>-<10 random hex>}),
 * {@code arflex.cpus} (default all), {@code arflex.cpus.reserved} (CPUs admission gives only
 * to components naming them in {@code timing/@cpus}; default none), {@code arflex.cpu.cap}
 * (utilisation cap per CPU, default 1.0), {@code arflex.memory} (default 1g), {@code arflex.network} (default 125m B/s),
 * {@code arflex.ready.timeout.ms} (default 5000), {@code arflex.nomlock} (true: RT halves skip
 * mlockall, for tests with many instances), {@code arflex.code.trusted} (the folders whose jars
 * may run RT halves without a pinned SHA-256, comma separated; default
 * {@code bundle,cell,tools,console} of the working directory: docs/DECISIONS.md D12),
 * {@code arflex.code.truststore} (the folder of certificates whose keys may sign component
 * bundles; default {@code trust} of the working directory, {@code none}: no signature is
 * trusted; D14), {@code arflex.test.hooks} (true: RT halves get {@code ARFLEX_TEST_HOOKS=1}, so
 * rt-core honours its test fault variables; the tests' runtimes only; D80), {@code arflex.machine.poll.ms}
 * (how often the CPUs online and in the runtime's cpuset and its memory limit are read, default 1000;
 * 0: not watched; D85).
 */
@Header(name = Constants.BUNDLE_ACTIVATOR, value = "${@class}")
public final class Activator implements BundleActivator {

    private static final Pattern RID = Pattern.compile("[a-z0-9-]{1,40}");
    private static final SecureRandom RANDOM = new SecureRandom();
    private static final long HEARTBEAT_MS = org.arflex.drcr.impl.supervisor.HeartbeatMonitor.PERIOD_MS;
    /** An actor task running longer than this is reported with its stack (issue 17: stalls under 50 ms). */
    private static final long ACTOR_WATCH_MS = 50;
    private static final long SAMPLE_MS = 1_000;

    private ThreadActor actor;
    private java.util.concurrent.ExecutorService stopper;
    private java.util.concurrent.ExecutorService launches;
    private java.util.concurrent.ExecutorService prepares;
    private java.util.concurrent.ExecutorService registrar;
    private org.arflex.drcr.impl.services.ManagementRegistrations registrations;
    private Cell cell;
    private Services services;
    private org.arflex.drcr.impl.services.HistoryStore history;
    private ScheduledExecutorService ticker;
    private org.arflex.drcr.impl.machine.MachineWatch machineWatch;
    private HeartbeatBridge bridge;
    private CellWatch watch;
    private BundleTracker<ContractExtender.Tracked> tracker;
    private final List<ServiceRegistration<?>> regs = new ArrayList<>();
    private String rid;
    private final Consumer<String> log = line -> System.err.println(LocalTime.now() + " " + line);

    private static String prop(BundleContext ctx, String key, String def) {
        String v = ctx.getProperty(key);
        return v == null || v.isBlank() ? def : v.trim();
    }

    @Override
    public void start(BundleContext ctx) throws Exception {
        try {
            doStart(ctx);
        } catch (Exception | Error e) {
            // Felix does not call stop() after a failed start: undo what was started here.
            if (actor != null) {
                try {
                    stop(ctx);
                } catch (Exception ignored) {
                    // the original failure is the one to report
                }
            }
            throw e;
        }
    }

    /**
     * The default runtime id, {@code rt<pid>-<10 random hex>}: the pid lets the Sweeper tell a
     * dead runtime's objects, the random part makes the object names unpredictable
     * (DECISIONS.md D13).
     */
    static String defaultRuntimeId(long pid) {
        long r = RANDOM.nextLong() & 0xFF_FFFF_FFFFL;
        return String.format("rt%d-%010x", pid, r);
    }

    private void doStart(BundleContext ctx) throws Exception {
        rid = prop(ctx, "arflex.runtime.id", defaultRuntimeId(ProcessHandle.current().pid()));
        if (!RID.matcher(rid).matches()) {
            throw new IllegalArgumentException("arflex.runtime.id '" + rid + "' must match [a-z0-9-]{1,40}");
        }
        Sweeper.sweep(rid, log);
        PortTypes types = PortTypes.builtin();
        double cap = Double.parseDouble(prop(ctx, "arflex.cpu.cap", "1.0"));
        List<Integer> wanted = prop(ctx, "arflex.cpus", "").isEmpty() ? null : Commands.parseCpus(prop(ctx, "arflex.cpus", ""));
        List<Integer> cpus = wanted == null ? allCpus() : wanted;
        java.util.Set<Integer> reserved = prop(ctx, "arflex.cpus.reserved", "").isEmpty() ? java.util.Set.of()
                : new java.util.TreeSet<>(Commands.parseCpus(prop(ctx, "arflex.cpus.reserved", "")));
        if (!cpus.containsAll(reserved)) {
            throw new IllegalArgumentException("arflex.cpus.reserved " + reserved + " is not within arflex.cpus " + cpus);
        }
        long memory = Commands.parseSize(prop(ctx, "arflex.memory", "1g"));
        long network = Commands.parseSize(prop(ctx, "arflex.network", "125000000"));
        java.nio.file.Path storage = java.nio.file.Path.of(prop(ctx, Constants.FRAMEWORK_STORAGE, "felix-cache"));
        StoragePermissions.secure(storage, Posix.LIBC::umask, log);
        actor = new ThreadActor(log);
        // RT halves are stopped, killed and reaped here, never on the actor (issue 17 finding 1)
        stopper = Executors.newCachedThreadPool(r -> {
            Thread t = new Thread(r, "arflex-drcr-stop");
            t.setDaemon(true);
            return t;
        });
        // ... and spawned and awaited until READY here (a simulator loads its model meanwhile),
        // one at a time: halves that load models, renderers and detectors all at once starve the
        // running ones on a small machine (D33)
        launches = Executors.newSingleThreadExecutor(r -> {
            Thread t = new Thread(r, "arflex-drcr-launch");
            t.setDaemon(true);
            return t;
        });
        // installed contract bundles have their executables extracted ahead of their start (D54)
        prepares = Executors.newSingleThreadExecutor(r -> {
            Thread t = new Thread(r, "arflex-drcr-prepare");
            t.setDaemon(true);
            return t;
        });
        VerifiedExecutables executables = new VerifiedExecutables(storage, log);
        // halves get an explicit environment; rt-core's test faults only under a test runtime (D80)
        boolean testHooks = Boolean.parseBoolean(prop(ctx, "arflex.test.hooks", "false"));
        if (testHooks) {
            log.accept("arflex: TEST HOOKS ON (arflex.test.hooks=true): RT halves honour rt-core's ARFLEX_FAULT_* "
                    + "variables; never on a cell");
        }
        Map<String, String> halfEnv = org.arflex.drcr.impl.supervisor.HalfEnvironment.of(System.getenv(), testHooks);
        log.accept("arflex: RT halves get only the environment variables " + new java.util.TreeSet<>(halfEnv.keySet()));
        Cell.Config cfg = new Cell.Config(rid, Long.parseLong(prop(ctx, "arflex.ready.timeout.ms", "5000")), 3_000,
                Boolean.parseBoolean(prop(ctx, "arflex.nomlock", "false")), types, Posix::monotonicNs,
                Boolean.parseBoolean(prop(ctx, "arflex.evaluation", "false")));
        // The cell is built on the actor so that the planner is only ever touched there.
        // what the machine gives the runtime: the capacities stay within it (D85)
        long machinePollMs = Long.parseLong(prop(ctx, "arflex.machine.poll.ms", "1000"));
        org.arflex.drcr.impl.machine.MachineReader machineReader = new org.arflex.drcr.impl.machine.MachineReader(
                java.nio.file.Path.of("/"));
        org.arflex.drcr.impl.machine.MachineView machine = null;
        if (machinePollMs > 0) {
            try {
                machine = machineReader.read();
                log.accept("arflex: machine: " + machine.describe());
            } catch (org.arflex.drcr.impl.machine.MachineReadException e) {
                log.accept("arflex: machine: " + e.getMessage() + "; capacities from the configuration until it reads");
            }
        }
        org.arflex.drcr.impl.machine.MachineView machineAtStart = machine;
        ResourceManagerImpl[] rm = new ResourceManagerImpl[1];
        cell = actor.call(() -> {
            ResourceManagerImpl tmp = new ResourceManagerImpl(null, cap, reserved, wanted, memory, machineAtStart);
            org.arflex.planner.Capacities caps = tmp.effective(cpus, memory, network);
            if (wanted != null && caps.cpus().size() < wanted.size()) {
                log.accept("arflex: machine: arflex.cpus " + wanted + " names cpus the runtime may not use now; using "
                        + caps.cpus().stream().map(org.arflex.planner.Capacities.Cpu::id).toList());
            }
            Planner planner = new Planner(caps);
            Cell c = new Cell(cfg, actor, new RecordingLauncher(new ProcessLauncher(log, executables, halfEnv),
                    HalfRecords.system(log)), planner, log, stopper, launches);
            rm[0] = new ResourceManagerImpl(c, cap, reserved, wanted, memory, machineAtStart);
            return c;
        }, 10_000);
        if (machinePollMs > 0) {
            machineWatch = new org.arflex.drcr.impl.machine.MachineWatch(machineReader, machine,
                    (before, now, cause) -> rm[0].machine(now, cause), log);
            rm[0].machineProblem(machineWatch::problem);
            machineWatch.start(machinePollMs);
        }
        ContractReader reader = new ContractReader(types);
        String store = prop(ctx, "arflex.code.truststore", "trust");
        CodeGate gate = new CodeGate(trustedFolders(prop(ctx, "arflex.code.trusted", "bundle,cell,tools,console")),
                store.equals("none") ? null : java.nio.file.Path.of(store).toAbsolutePath().normalize(), log);
        log.accept("arflex: code gate: trusted folders " + gate.trusted() + ", trust store for signed code "
                + (gate.trustStore() == null ? "none" : gate.trustStore()));
        // Java code too: a bundle the gate refuses does not resolve, so none of its classes load.
        org.arflex.drcr.impl.services.CodeGateHook gateHook = new org.arflex.drcr.impl.services.CodeGateHook(gate);
        regs.add(ctx.registerService(org.osgi.framework.hooks.resolver.ResolverHookFactory.class, gateHook, null));
        services = new Services(cell, rm[0], reader, ctx, gate, log);
        VerifiedInstaller installer = new VerifiedInstaller(ctx, gate, log);
        // arflex:await looks at the cell again on each of its changes
        watch = new CellWatch();
        // the ComponentManagement registrations are made off the actor (D54)
        registrar = Executors.newSingleThreadExecutor(r -> {
            Thread t = new Thread(r, "arflex-drcr-registrar");
            t.setDaemon(true);
            return t;
        });
        registrations = new org.arflex.drcr.impl.services.ManagementRegistrations(cell, ctx, registrar);
        cell.onChange(() -> {
            registrations.sync();
            watch.changed();
        });
        regs.add(ctx.registerService(DrcrService.class, services, null));
        regs.add(ctx.registerService(UpdateService.class, services, null));
        regs.add(ctx.registerService(ResourceManager.class, rm[0], null));
        // the change-set history, kept in the data area across restarts (D66)
        history = org.arflex.drcr.impl.services.HistoryStore.open(java.util.Objects.requireNonNull(ctx.getDataFile(""),
                "the framework has no data area for bundles").toPath(), Posix.LIBC.geteuid(), log);
        org.arflex.drcr.impl.services.ChangeSets changeSets = new org.arflex.drcr.impl.services.ChangeSets(cell, ctx, log,
                history);
        regs.add(ctx.registerService(org.arflex.drcr.ChangeSetService.class, changeSets, null));
        // updates in change sets (D38): the new version's jar through the same gate as a deploy
        org.arflex.drcr.impl.services.UpdateJars updateJars = new org.arflex.drcr.impl.services.UpdateJars(installer, gate,
                reader, executables, java.util.Objects.requireNonNull(ctx.getDataFile("updates"),
                        "the framework has no data area for bundles").toPath());
        // deployment sets (D45): several jars through the same gate, then one change set
        org.arflex.drcr.impl.services.DeploymentSets deployments = new org.arflex.drcr.impl.services.DeploymentSets(cell,
                ctx, installer, gate, services::readJar, updateJars, changeSets, log);
        changeSets.versions(deployments.versions());
        changeSets.deployments(deployments);
        Hashtable<String, Object> shell = new Hashtable<>();
        shell.put("osgi.command.scope", Commands.SCOPE);
        shell.put("osgi.command.function", Commands.FUNCTIONS);
        // The shell finds management services in the registry, as any other client does.
        regs.add(ctx.registerService(Commands.class, new Commands(services, rm[0], services, name -> lookup(ctx, name),
                new Commands.BundleUpdater() {
                    @Override
                    public String update(long id, String location, String sha256) {
                        return installer.update(id, location, sha256);
                    }

                    @Override
                    public String deploy(String location, String sha256) {
                        return installer.deploy(location, sha256);
                    }
                }, (component, port) -> readPort(ctx, component, port), watch, changeSets), shell));
        // The runtime heartbeat is what keeps the RT halves out of safe mode: its thread runs at a
        // low SCHED_FIFO priority (below every component, above all ordinary load) so that a
        // busy machine cannot starve it past a 100 ms heartbeat timeout.
        int hbPriority = Integer.parseInt(prop(ctx, "arflex.heartbeat.priority", "1"));
        if (hbPriority < 0 || hbPriority > 98) {
            throw new IllegalArgumentException("arflex.heartbeat.priority " + hbPriority + " is not in 0..98 (0: no SCHED_FIFO)");
        }
        long graceMs = Long.parseLong(prop(ctx, "arflex.heartbeat.grace.ms", "1000"));
        if (graceMs < HEARTBEAT_MS || graceMs > 60_000) {
            throw new IllegalArgumentException("arflex.heartbeat.grace.ms " + graceMs + " is not in " + HEARTBEAT_MS + "..60000");
        }
        // D17: a native thread writes the heartbeat while this JVM's round is at most graceMs late
        bridge = HeartbeatBridge.open(ctx.getBundle()::getEntry, executables, java.util.Objects.requireNonNull(ctx.getDataFile("native"),
                "the framework has no data area for bundles").toPath(),
                Boolean.parseBoolean(prop(ctx, "arflex.heartbeat.native", "true")), HEARTBEAT_MS, graceMs, hbPriority, log);
        ticker = new ScheduledThreadPoolExecutor(1, r -> {
            Thread t = new Thread(() -> {
                if (hbPriority > 0) {
                    String why = Posix.fifoThisThread(hbPriority);
                    if (why != null) {
                        log.accept("arflex: heartbeat thread stays SCHED_OTHER (SCHED_FIFO " + hbPriority + " refused: "
                                + why + "); a loaded machine may delay heartbeats");
                    }
                }
                r.run();
            }, "arflex-drcr-heartbeat");
            t.setDaemon(true);
            return t;
        });
        ticker.scheduleAtFixedRate(() -> {
            try {
                bridge.round();
                cell.monitor().check(Posix.monotonicNs());
                actor.watch(ACTOR_WATCH_MS); // a task that holds supervision: where it is
            } catch (RuntimeException e) {
                log.accept("arflex: heartbeat round failed: " + e);
            }
        }, HEARTBEAT_MS, HEARTBEAT_MS, TimeUnit.MILLISECONDS);
        ticker.scheduleAtFixedRate(() -> actor.submit(() -> rm[0].overruns(cell.sample())), SAMPLE_MS, SAMPLE_MS,
                TimeUnit.MILLISECONDS);
        ContractExtender extender = new ContractExtender(cell, reader, ctx,
                new ContractExtender.Extractor() {
                    @Override
                    public java.nio.file.Path extract(java.nio.file.Path dir, String name, ContractExtender.Opener source)
                            throws java.io.IOException {
                        return executables.extract(dir, name, source::open);
                    }

                    @Override
                    public void forget(java.nio.file.Path exe) {
                        executables.forget(exe);
                    }
                }, gateHook::refusal, prepares, log);
        changeSets.executables(extender::executable);
        changeSets.bundles(new org.arflex.drcr.impl.services.UpdatedBundles(ctx, cell,
                new org.arflex.drcr.impl.services.UpdatedBundles.Carrier() {
                    @Override
                    public void carryOver(long bundleId, java.util.Set<String> names) {
                        extender.carryOver(bundleId, names);
                    }

                    @Override
                    public void carryDone(long bundleId) {
                        extender.carryDone(bundleId);
                    }
                }, log));
        tracker = new BundleTracker<>(ctx, ContractExtender.MASK, extender);
        tracker.open();
        org.arflex.planner.Capacities started = actor.call(() -> cell.planner().capacities(), 10_000);
        log.accept("arflex: DRCR started, runtime id " + rid + ", cpus "
                + started.cpus().stream().map(org.arflex.planner.Capacities.Cpu::id).toList() + ", memory "
                + started.memoryBytes() + ", network " + network);
    }

    /**
     * A port value for arflex:summary, or null when it cannot be read: a contract output through
     * the component's management service (as the web console reads it), the evaluation-only
     * {@code truth} segment through the cell.
     */
    private PortValueDTO readPort(BundleContext ctx, String component, String port) {
        try {
            PortValues.Ref truth = actor.call(() -> PortValues.evaluationRef(cell, component, port), 10_000);
            if (truth != null) {
                return PortValues.read(truth, Posix.monotonicNs());
            }
            return lookup(ctx, component).map(m -> m.portValue(port)).orElse(null);
        } catch (RuntimeException e) {
            return null;
        }
    }

    private static java.util.Optional<org.arflex.drcr.ComponentManagement> lookup(BundleContext ctx, String name) {
        if (!name.matches("[a-z][a-z0-9-]{0,47}")) {
            return java.util.Optional.empty();
        }
        try {
            for (var ref : ctx.getServiceReferences(org.arflex.drcr.ComponentManagement.class,
                    "(" + org.arflex.drcr.ComponentManagement.COMPONENT_PROPERTY + "=" + name + ")")) {
                org.arflex.drcr.ComponentManagement cm = ctx.getService(ref);
                if (cm != null) {
                    // our own service object: no need to keep the reference counted
                    ctx.ungetService(ref);
                    return java.util.Optional.of(cm);
                }
            }
        } catch (org.osgi.framework.InvalidSyntaxException e) {
            return java.util.Optional.empty();
        }
        return java.util.Optional.empty();
    }

    /** The trusted folders of the code gate: a comma list, relative to the working directory. */
    private static List<java.nio.file.Path> trustedFolders(String list) {
        List<java.nio.file.Path> l = new ArrayList<>();
        for (String f : list.split(",")) {
            if (!f.isBlank()) {
                l.add(java.nio.file.Path.of(f.trim()).toAbsolutePath().normalize());
            }
        }
        return l;
    }

    private static List<Integer> allCpus() {
        List<Integer> l = new ArrayList<>();
        for (int i = 0; i < Runtime.getRuntime().availableProcessors(); i++) {
            l.add(i);
        }
        return l;
    }

    @Override
    public void stop(BundleContext ctx) throws Exception {
        if (machineWatch != null) {
            machineWatch.close();
        }
        if (tracker != null) {
            tracker.close();
        }
        if (prepares != null) {
            prepares.shutdownNow();
        }
        for (ServiceRegistration<?> r : regs) {
            try {
                r.unregister();
            } catch (IllegalStateException ignored) {
                // already gone
            }
        }
        regs.clear();
        if (history != null) {
            history.close(10_000); // the last set's record on disk before the DRCR is gone
        }
        if (registrar != null) {
            // its last registrations made (off the actor: a listener may call into the cell);
            // from here on the actor makes them itself, until they are closed
            registrar.shutdown();
            if (!registrar.awaitTermination(30, TimeUnit.SECONDS)) {
                log.accept("arflex: the registrar of the management services did not end within 30 s");
            }
        }
        if (cell != null) {
            actor.call(() -> {
                cell.shutdownAll("DRCR stopping");
                if (registrations != null) {
                    registrations.close();
                }
                return null;
            }, 120_000);
            // the halves stop on the stop threads; their outcomes are recorded on the actor
            try {
                cell.stopsDone().get(60_000, TimeUnit.MILLISECONDS);
            } catch (java.util.concurrent.ExecutionException | java.util.concurrent.TimeoutException e) {
                log.accept("arflex: RT halves not all stopped: " + e + "; the sweep takes what is left");
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        }
        if (stopper != null) {
            stopper.shutdown();
        }
        if (launches != null) {
            launches.shutdown();
        }
        if (ticker != null) {
            ticker.shutdownNow();
        }
        if (bridge != null) {
            bridge.close();
        }
        if (actor != null) {
            actor.shutdown(10_000);
        }
        Sweeper.sweep(rid, log);
        if (watch != null) {
            watch.changed(); // an arflex:await still waiting looks again and ends
        }
        log.accept("arflex: DRCR stopped");
    }
}
