package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertSame;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * The cell with a fake launcher, a steppable actor and a simulated clock: wiring, cascades,
 * restart policy, Failed, reset, parameters, hang detection. Deterministic, no processes.
 */
class CellTest {

    private final ManualActor actor = new ManualActor();
    private final FakeLauncher launcher = new FakeLauncher();
    private final List<String> log = new ArrayList<>();
    private long nowNs = 1_000_000_000L;
    private final Cell cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> nowNs),
            actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add);

    static String contract(String name, String extraPorts, String fault, boolean moves, int criticality, String wcet) {
        return "<component xmlns=\"urn:arflex:contract:1\" name=\"" + name + "\" version=\"1.0.0\">"
                + "<implementation executable=\"" + name + "\" task=\"periodic\" movesHardware=\"" + moves + "\"/>"
                + "<ports>" + extraPorts + "</ports>"
                + "<properties><property name=\"gain\" type=\"double\" default=\"2.0\" min=\"-10\" max=\"10\" mutable=\"true\"/>"
                + "<property name=\"mode\" type=\"int\" default=\"1\" min=\"0\" max=\"3\" mutable=\"false\"/></properties>"
                + "<timing period=\"1ms\" deadline=\"1ms\" wcet=\"" + wcet + "\" priority=\"80\"/>"
                + "<resources memory=\"1MiB\" network=\"0\"/><criticality>" + criticality + "</criticality>"
                + "<fault " + fault + " safe=\"hold\" heartbeatTimeout=\"100ms\"/></component>";
    }

    /** The safety input every motion component declares (contracts/SPEC.md §6.8). */
    static final String SAFETY_IN = "<in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\""
            + " safety=\"true\"/>";
    static final String PERMANENT = "restart=\"permanent\" intensity=\"2\" window=\"10s\" backoff=\"100ms\"";
    static final String PROVIDER_PORTS = "<out name=\"y\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>";
    static final String CONSUMER_PORTS = "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind component=\"prov\" port=\"y\"/></in>"
            + "<out name=\"z\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>";

    private Contract parse(String xml) throws Exception {
        return ContractParser.create(PortTypes.builtin()).parse(xml, "test.xml");
    }

    private void install(String xml) throws Exception {
        Contract c = parse(xml);
        assertTrue(actor.call(() -> cell.install(c, c.name().hashCode(), Path.of("/nonexistent/" + c.name())), 0), log::toString);
        actor.runAll();
    }

    private State state(String n) {
        return cell.instance(n).orElseThrow().life.state();
    }

    private String reason(String n) {
        return cell.instance(n).orElseThrow().life.reason();
    }

    private void installBoth() throws Exception {
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        install(contract("cons", CONSUMER_PORTS, PERMANENT, false, 3, "50us"));
    }

    @AfterEach
    void nothingLeaks() {
        actor.call(() -> {
            cell.shutdownAll("test end");
            return null;
        }, 0);
        actor.runAll();
        assertTrue(launcher.running.isEmpty(), "RT halves left running: " + launcher.running.keySet());
        assertTrue(launcher.openOutputs.isEmpty(), "segments left: " + launcher.openOutputs);
    }

    @Test
    void consumerFirstWaitsThenBothActiveWithBinding() throws Exception {
        install(contract("cons", CONSUMER_PORTS, PERMANENT, false, 3, "50us"));
        assertEquals(State.UNSATISFIED, state("cons"));
        assertTrue(reason("cons").contains("prov"), reason("cons"));
        assertTrue(launcher.running.isEmpty());
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(State.ACTIVE, state("cons"));
        assertTrue(launcher.events.contains("cons BIND x /arflex.t.prov.out.y"), launcher.events.toString());
        // the provider's segment exists before the consumer is bound, and starts come after binds
        assertTrue(launcher.events.indexOf("CREATE /arflex.t.prov.out.y arflex.Sample 16") >= 0
                || launcher.events.stream().anyMatch(e -> e.startsWith("CREATE /arflex.t.prov.out.y arflex.Sample")),
                launcher.events.toString());
        assertTrue(launcher.events.indexOf("cons BIND x /arflex.t.prov.out.y") < launcher.events.indexOf("cons START"));
        CellDTO dto = Snapshots.cell(cell, null);
        assertEquals(1, dto.bindings.length);
        assertEquals("prov", dto.bindings[0].provider);
    }

    /** Execution-time counters as an RT half would report them (declared WCET 50 us). */
    private static ControlBlock.Stats exec(long cycles, long meanNs, long maxNs, long overWcet) {
        return new ControlBlock.Stats(cycles, 0, 0, 0, 0, maxNs, cycles, cycles * meanNs, overWcet, 0);
    }

    private long sample() {
        long over = actor.call(cell::sample, 0);
        actor.runAll();
        return over;
    }

    @Test
    void anIsolatedWcetSpikeIsLoggedOnceAndDoesNotStopTheComponent() throws Exception {
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        FakeLauncher.FakeHalf h = launcher.running.get("prov");
        h.stats = exec(1000, 20_000, 3_000_000, 1);  // one 3 ms cycle (a stall) in 1000
        assertEquals(1, sample());
        h.stats = exec(2000, 20_000, 3_000_000, 2);
        sample();
        assertEquals(State.ACTIVE, state("prov"));
        assertSame(h, launcher.running.get("prov"), "not restarted");
        assertEquals(1, log.stream().filter(l -> l.contains("isolated cycles")).count(), log::toString);
        assertTrue(log.stream().noneMatch(l -> l.contains("re-planning")), log::toString);
    }

    // A sustained exceedance re-planned and refused with the measured value: MeasuredWcetTest (D82).

    @Test
    void sustainedMeansAtLeastOnePercentOfAWindowOrAMeanAboveTheWcet() {
        assertFalse(WcetMonitor.sustainedOverWcet(50_000, 1000, 1000 * 20_000L, 9));
        assertTrue(WcetMonitor.sustainedOverWcet(50_000, 1000, 1000 * 20_000L, 10));
        assertFalse(WcetMonitor.sustainedOverWcet(50_000, 30, 30 * 20_000L, 2));   // a 30 Hz task: 3 cycles at least
        assertTrue(WcetMonitor.sustainedOverWcet(50_000, 30, 30 * 20_000L, 3));
        assertTrue(WcetMonitor.sustainedOverWcet(50_000, 1000, 1000 * 60_000L, 0)); // mean above
        // above the histogram's 200 us the over count is an upper bound: only the mean decides
        assertFalse(WcetMonitor.sustainedOverWcet(300_000, 1000, 1000 * 250_000L, 1000));
        assertTrue(WcetMonitor.sustainedOverWcet(300_000, 1000, 1000 * 310_000L, 1000));
        assertFalse(WcetMonitor.sustainedOverWcet(50_000, 0, 0, 0));
    }

    @Test
    void uninstallProviderTakesConsumerDownAndReinstallBringsItBack() throws Exception {
        installBoth();
        actor.call(() -> {
            cell.uninstall("prov", "bundle stopped");
            return null;
        }, 0);
        assertEquals(State.UNSATISFIED, state("cons"));
        assertTrue(launcher.events.contains("cons UNBIND x"), launcher.events.toString());
        assertFalse(launcher.running.containsKey("cons"));
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertEquals(State.ACTIVE, state("cons"));
    }

    @Test
    void crashCascadesAndBackoffRestartsAll() throws Exception {
        installBoth();
        long consPid = launcher.running.get("cons").pid;
        launcher.running.get("prov").crash(137, "killed by signal 9");
        actor.runAll();
        assertEquals(State.UNSATISFIED, state("prov"));
        assertTrue(reason("prov").contains("restarting"), reason("prov"));
        assertEquals(State.UNSATISFIED, state("cons"), "dependent must go down with its provider");
        assertFalse(launcher.running.containsKey("cons"));
        actor.advance(99);
        assertEquals(State.UNSATISFIED, state("prov"), "restart must wait for the backoff");
        actor.advance(1);
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(State.ACTIVE, state("cons"));
        assertTrue(launcher.running.get("cons").pid != consPid);
        InstanceDTO p = Snapshots.instance(cell, "prov").orElseThrow();
        assertEquals(1, p.restarts);
        assertEquals(1, p.restartsLeft);
    }

    @Test
    void crashLoopEndsInFailedAndResetRevives() throws Exception {
        installBoth();
        for (int i = 0; i < 3; i++) {
            launcher.running.get("prov").crash(139, "killed by signal 11");
            actor.runAll();
            actor.advance(10_000 / 4 > 0 ? 500 : 0);
        }
        assertEquals(State.FAILED, state("prov"));
        assertTrue(reason("prov").contains("restart intensity exceeded"), reason("prov"));
        assertEquals(State.UNSATISFIED, state("cons"));
        actor.advance(60_000);
        assertEquals(State.FAILED, state("prov"), "Failed is final until reset");
        actor.call(() -> cell.reset("prov"), 0);
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(State.ACTIVE, state("cons"));
    }

    /**
     * D26 (found by CellConcurrencyTest): the install of a contract into an instance that is
     * planned already neither shows a running half as UNSATISFIED "resolving" when the plan
     * leaves it running, nor takes a FAILED one out of FAILED while the planner keeps it blocked
     * (a reset then said "nothing to reset" and the component stayed down for good).
     */
    @Test
    void reinstallOfARunningOrFailedComponentKeepsItsStateAndResetStillRevives() throws Exception {
        installBoth();
        FakeLauncher.FakeHalf h = launcher.running.get("prov");
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertEquals(State.ACTIVE, state("prov"), reason("prov"));
        assertSame(h, launcher.running.get("prov"), "an identical contract restarts nothing");
        for (int i = 0; i < 3; i++) {
            launcher.running.get("prov").crash(139, "killed by signal 11");
            actor.runAll();
            actor.advance(500);
        }
        assertEquals(State.FAILED, state("prov"));
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us").replace("1.0.0", "1.0.1"));
        assertEquals(State.FAILED, state("prov"), "still blocked in the planner: " + cell.planner().blocked());
        String reply = actor.call(() -> cell.reset("prov"), 0);
        assertTrue(reply.startsWith("prov: reset from FAILED"), reply);
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(State.ACTIVE, state("cons"));
    }

    @Test
    void resetFromFailedRecreatesADamagedOutputSegmentAndKeepsAnIntactOne() throws Exception {
        installBoth();
        for (int i = 0; i < 3; i++) {
            launcher.running.get("prov").crash(139, "killed by signal 11");
            actor.runAll();
            actor.advance(500);
        }
        assertEquals(State.FAILED, state("prov"));
        String seg = "/arflex.t.prov.out.y";
        long creates = launcher.events.stream().filter(e -> e.startsWith("CREATE " + seg + " ")).count();
        launcher.damaged.put(seg, "size 0 B, created with 4096 B");
        String reply = actor.call(() -> cell.reset("prov"), 0);
        assertTrue(reply.contains("output prov.y (" + seg + ") was damaged: size 0 B"), reply);
        assertTrue(log.stream().anyMatch(l -> l.contains("output prov.y (" + seg + ") was damaged")), log.toString());
        assertEquals(creates + 1, launcher.events.stream().filter(e -> e.startsWith("CREATE " + seg + " ")).count(),
                launcher.events.toString());
        int created = launcher.events.lastIndexOf(launcher.events.stream()
                .filter(e -> e.startsWith("CREATE " + seg + " ")).reduce((a, b) -> b).orElseThrow());
        assertTrue(created < launcher.events.lastIndexOf("prov START"), launcher.events.toString());
        assertEquals(1, launcher.openOutputs.get(seg), "the old segment is closed, one new one open");
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(State.ACTIVE, state("cons"));
        // an intact segment survives a reset from FAILED
        launcher.damaged.clear();
        for (int i = 0; i < 3; i++) {
            launcher.running.get("prov").crash(139, "killed by signal 11");
            actor.runAll();
            actor.advance(500);
        }
        assertEquals(State.FAILED, state("prov"));
        String again = actor.call(() -> cell.reset("prov"), 0);
        assertFalse(again.contains("damaged"), again);
        assertEquals(creates + 1, launcher.events.stream().filter(e -> e.startsWith("CREATE " + seg + " ")).count());
    }

    @Test
    void failingStartUsesTheRestartPolicy() throws Exception {
        launcher.failLaunches.put("prov", 1);
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertEquals(State.UNSATISFIED, state("prov"));
        assertTrue(reason("prov").contains("start failed"), reason("prov"));
        actor.advance(100);
        assertEquals(State.ACTIVE, state("prov"));
    }

    @Test
    void failedProviderStartDoesNotStartItsDependentsInTheSamePlan() throws Exception {
        install(contract("cons", CONSUMER_PORTS, PERMANENT, false, 3, "50us"));
        launcher.failLaunches.put("prov", 1);
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertEquals(State.UNSATISFIED, state("prov"));
        assertEquals(State.UNSATISFIED, state("cons"), "a consumer must not start bound to a provider that failed");
        assertFalse(launcher.running.containsKey("cons"));
        actor.advance(100);
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(State.ACTIVE, state("cons"));
    }

    @Test
    void temporaryIsNotRestarted() throws Exception {
        install(contract("prov", PROVIDER_PORTS, "restart=\"temporary\" intensity=\"1\" window=\"1s\" backoff=\"10ms\"", false, 5, "50us"));
        launcher.running.get("prov").crash(1, "exited with status 1");
        actor.runAll();
        actor.advance(5_000);
        assertEquals(State.FAILED, state("prov"));
        assertTrue(reason("prov").contains("temporary"), reason("prov"));
    }

    @Test
    void movingHardwareNeedsResetAfterRestart() throws Exception {
        install(contract("prov", PROVIDER_PORTS + SAFETY_IN, PERMANENT, true, 5, "50us"));
        assertFalse(launcher.specs.get(0).resetRequired(), "the first start needs no reset");
        launcher.running.get("prov").crash(137, "killed by signal 9");
        actor.runAll();
        actor.advance(100);
        assertEquals(State.ACTIVE, state("prov"));
        assertTrue(launcher.specs.get(1).resetRequired(), "a restart must set RESET_REQUIRED before the spawn");
        assertTrue(cell.instance("prov").orElseThrow().awaitingReset);
        actor.call(() -> cell.reset("prov"), 0);
        assertTrue(launcher.events.contains("prov RESET"));
        assertFalse(cell.instance("prov").orElseThrow().awaitingReset);
    }

    @Test
    void parametersAreCheckedForRangeTypeAndMutability() throws Exception {
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertEquals("3.5", actor.call(() -> cell.setParam("prov", "gain", "3.5"), 0));
        assertEquals("3.5", cell.getParam("prov", "gain"));
        IllegalArgumentException range = assertThrows(IllegalArgumentException.class,
                () -> actor.call(() -> cell.setParam("prov", "gain", "11"), 0));
        assertTrue(range.getMessage().contains("out of range"), range.getMessage());
        IllegalArgumentException type = assertThrows(IllegalArgumentException.class,
                () -> actor.call(() -> cell.setParam("prov", "gain", "abc"), 0));
        assertTrue(type.getMessage().contains("not a number"), type.getMessage());
        IllegalArgumentException imm = assertThrows(IllegalArgumentException.class,
                () -> actor.call(() -> cell.setParam("prov", "mode", "2"), 0));
        assertTrue(imm.getMessage().contains("immutable"), imm.getMessage());
        assertThrows(IllegalArgumentException.class, () -> actor.call(() -> cell.setParam("prov", "nope", "1"), 0));
        // a restart keeps the value that was set
        launcher.running.get("prov").crash(137, "killed by signal 9");
        actor.runAll();
        actor.advance(100);
        assertEquals("3.5", cell.getParam("prov", "gain"));
    }

    @Test
    void staleRtHeartbeatIsAHang() throws Exception {
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        FakeLauncher.FakeHalf h = launcher.running.get("prov");
        h.rtHb = nowNs;
        nowNs += 50_000_000L;
        cell.monitor().check(nowNs);
        actor.runAll();
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(nowNs, h.runtimeHb, "the monitor writes the runtime heartbeat");
        for (int i = 0; i < 10; i++) { // 200 ms of supervision at its 20 ms period
            nowNs += 20_000_000L;
            cell.monitor().check(nowNs);
        }
        actor.runAll();
        assertTrue(launcher.events.contains("prov SIGKILL"));
        assertTrue(reason("prov").contains("hung"), reason("prov"));
        actor.advance(100);
        assertEquals(State.ACTIVE, state("prov"));
    }

    @Test
    void shrinkingCpusStopsLowestCriticalityFirst() throws Exception {
        install(contract("hi", PROVIDER_PORTS.replace("\"y\"", "\"a\""), PERMANENT, false, 9, "600us"));
        install(contract("lo", PROVIDER_PORTS.replace("\"y\"", "\"b\""), PERMANENT, false, 1, "600us"));
        assertEquals(State.ACTIVE, state("hi"));
        assertEquals(State.ACTIVE, state("lo"));
        String dry = actor.call(() -> cell.dryRun(org.arflex.planner.Change.capacities(
                Capacities.of(1, 1.0, 1L << 30, 1_000_000_000L))).toText(), 0);
        assertTrue(dry.contains("lo"), dry);
        actor.call(() -> cell.capacities(Capacities.of(1, 1.0, 1L << 30, 1_000_000_000L)), 0);
        assertEquals(State.ACTIVE, state("hi"));
        assertEquals(State.UNSATISFIED, state("lo"));
        assertNotNull(reason("lo"));
        actor.call(() -> cell.capacities(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), 0);
        assertEquals(State.ACTIVE, state("lo"));
    }

    @Test
    void componentsUninstalledTogetherStopSideBySide() throws Exception {
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        install(contract("cons", CONSUMER_PORTS, PERMANENT, false, 3, "50us"));
        install(contract("cons2", CONSUMER_PORTS.replace("\"z\"", "\"z2\""), PERMANENT, false, 3, "50us"));
        assertEquals(State.ACTIVE, state("cons"));
        assertEquals(State.ACTIVE, state("cons2"));
        launcher.events.clear();
        // As a bundle with two components is stopped: both in one call.
        assertTrue(actor.call(() -> {
            cell.uninstall(List.of("cons", "cons2"), "bundle stopped");
            return true;
        }, 0));
        List<String> ev = launcher.events;
        for (String c : List.of("cons", "cons2")) {
            assertTrue(ev.contains(c + " UNBIND x") && ev.contains(c + " AWAIT 2") && ev.contains(c + " SHUTDOWN"), ev.toString());
            assertTrue(cell.instance(c).isEmpty(), c + " still known");
        }
        // Every input unbound before the first wait, every wait before the first shutdown: the
        // two waits for the consumers' safe behaviour run side by side, not one after the other.
        int lastUnbind = Math.max(ev.indexOf("cons UNBIND x"), ev.indexOf("cons2 UNBIND x"));
        int firstAwait = Math.min(ev.indexOf("cons AWAIT 2"), ev.indexOf("cons2 AWAIT 2"));
        int lastAwait = Math.max(ev.indexOf("cons AWAIT 2"), ev.indexOf("cons2 AWAIT 2"));
        int firstShutdown = Math.min(ev.indexOf("cons SHUTDOWN"), ev.indexOf("cons2 SHUTDOWN"));
        assertTrue(lastUnbind < firstAwait && lastAwait < firstShutdown, ev.toString());
        assertEquals(State.ACTIVE, state("prov"));
        assertTrue(launcher.running.keySet().equals(java.util.Set.of("prov")), launcher.running.keySet().toString());
    }

    @Test
    void aStoppingComponentKeepsTheRuntimeHeartbeatWhileItSettles() throws Exception {
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        install(contract("cons", CONSUMER_PORTS, PERMANENT, false, 3, "50us"));
        FakeLauncher.FakeHalf prov = launcher.running.get("prov");
        FakeLauncher.FakeHalf cons = launcher.running.get("cons");
        long[] seen = new long[1];
        // A slow consumer settles longer than its heartbeat timeout (100 ms here) after UNBIND.
        cons.duringAwait = () -> {
            nowNs += 300_000_000L;
            prov.rtHb = nowNs;
            cell.monitor().check(nowNs);
            seen[0] = cons.runtimeHb;
        };
        assertTrue(actor.call(() -> {
            cell.uninstall("cons", "bundle stopped");
            return true;
        }, 0));
        actor.runAll();
        assertEquals(nowNs, seen[0], "runtime heartbeat written while the stopping half settles");
        assertFalse(launcher.events.contains("cons SIGKILL"), launcher.events.toString());
        assertTrue(launcher.events.contains("cons SHUTDOWN"), launcher.events.toString());
        nowNs += 300_000_000L;
        prov.rtHb = nowNs;
        cell.monitor().check(nowNs);
        actor.runAll();
        assertEquals(seen[0], cons.runtimeHb, "no heartbeat into a half that is gone");
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals(1, cell.monitor().size(), "only prov watched");
    }

    @Test
    void aServiceDoesNotLockItsMemoryAPeriodicTaskDoes() throws Exception {
        String periodic = contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us");
        Contract p = parse(periodic);
        Contract s = parse(periodic.replace("task=\"periodic\"", "task=\"service\"").replace(" priority=\"80\"", ""));
        assertEquals(Contract.TaskType.SERVICE, s.taskType());
        assertEquals(0, ControlSetup.config(p, 1, false).cfgFlags() & ControlBlock.CFG_NO_MLOCK);
        assertEquals(ControlBlock.CFG_NO_MLOCK, ControlSetup.config(s, 1, false).cfgFlags() & ControlBlock.CFG_NO_MLOCK);
        assertEquals(0, ControlSetup.config(s, 1, false).priority());
        assertEquals(ControlBlock.CFG_NO_MLOCK, ControlSetup.config(p, 1, true).cfgFlags() & ControlBlock.CFG_NO_MLOCK);
    }

    @Test
    void installedBundleShowsInstalledUntilStartedAndAfterStopped() throws Exception {
        Contract c = parse(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertTrue(actor.call(() -> cell.register(c, 7), 0));
        assertEquals(State.INSTALLED, state("prov"));
        assertEquals("INSTALLED", Snapshots.instance(cell, "prov").orElseThrow().targetState);
        assertTrue(launcher.running.isEmpty());
        assertTrue(actor.call(() -> cell.install(c, 7, Path.of("/x/prov")), 0));
        assertEquals(State.ACTIVE, state("prov"));
        actor.call(() -> {
            cell.uninstall("prov", "bundle 7 stopped");
            return cell.register(c, 7);
        }, 0);
        assertEquals(State.INSTALLED, state("prov"));
        assertTrue(launcher.running.isEmpty());
        actor.call(() -> {
            cell.unregister("prov", 7);
            return null;
        }, 0);
        assertTrue(cell.instance("prov").isEmpty());
    }

    @Test
    void parametersSetWhileInstalledAreKeptWhenTheComponentStarts() throws Exception {
        Contract c = parse(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertTrue(actor.call(() -> cell.register(c, 7), 0));
        assertEquals("3.5", actor.call(() -> cell.setParam("prov", "gain", "3.5"), 0));
        assertEquals("2", actor.call(() -> cell.setParam("prov", "mode", "2"), 0));
        assertTrue(actor.call(() -> cell.install(c, 7, Path.of("/x/prov")), 0));
        assertEquals(State.ACTIVE, state("prov"));
        FakeLauncher.FakeHalf h = launcher.running.get("prov");
        assertEquals(Double.doubleToLongBits(3.5), h.params[0], "gain as set, not the default 2.0");
        assertEquals(2, h.params[1]);
        assertEquals("3.5", actor.call(() -> cell.getParam("prov", "gain"), 0));
    }

    @Test
    void anUpdateKeepsSetValuesItsRangesStillHoldAndDefaultsTheRest() throws Exception {
        String v1 = contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us");
        install(v1);
        actor.call(() -> cell.setParam("prov", "gain", "5"), 0);
        // version 1.1.0: gain now at most 3 (5 no longer fits), mode unchanged
        Contract v2 = parse(v1.replace("version=\"1.0.0\"", "version=\"1.1.0\"").replace("max=\"10\"", "max=\"3\""));
        long id = "prov".hashCode();
        assertTrue(actor.call(() -> cell.install(v2, id, Path.of("/x/prov")), 0), log::toString);
        actor.runAll();
        assertEquals(State.ACTIVE, state("prov"));
        assertEquals("2", actor.call(() -> cell.getParam("prov", "gain"), 0).replace(".0", ""), "out of the new range: default");
        assertEquals("1", actor.call(() -> cell.getParam("prov", "mode"), 0));
    }

    @Test
    void theDtoShowsAResetLatchedByTheRtHalfItselfAndItsSafeMode() throws Exception {
        install(contract("prov", PROVIDER_PORTS + SAFETY_IN, PERMANENT, true, 5, "50us"));
        FakeLauncher.FakeHalf h = launcher.running.get("prov");
        InstanceDTO d = Snapshots.instance(cell, "prov").orElseThrow();
        assertFalse(d.awaitingReset);
        assertFalse(d.safeMode);
        // the RT half lost the runtime heartbeat: it latched RESET_REQUIRED and runs its safe hook
        h.flags = ControlBlock.FLAG_RESET_REQUIRED | ControlBlock.FLAG_SAFE_ACTIVE;
        d = Snapshots.instance(cell, "prov").orElseThrow();
        assertTrue(d.awaitingReset);
        assertTrue(d.safeMode);
        assertEquals("ACTIVE", d.state);
    }

    /** Issue 15 finding 4: a component that holds the arm says so, with the input and its provider. */
    @Test
    void theDtoSaysWhyAComponentHoldsTheArm() throws Exception {
        install(contract("guard", "<out name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\"/>",
                PERMANENT, false, 5, "50us"));
        install(contract("arm", "<in name=\"ref\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\" optional=\"true\">"
                + "<bind component=\"prov\" port=\"y\"/></in>"
                + "<in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\" safety=\"true\">"
                + "<bind component=\"guard\" port=\"safety\"/></in>", PERMANENT, true, 4, "50us"));
        assertEquals(State.ACTIVE, state("arm"));
        FakeLauncher.FakeHalf h = launcher.running.get("arm");
        assertEquals(null, Snapshots.instance(cell, "arm").orElseThrow().holding);
        // hold word: SAFETY_INPUT, verdict 5 (stale), input 1 (declared second, as in the contract)
        h.hold = ControlBlock.HOLD_SAFETY_INPUT | 5 << 8 | 1 << 16;
        InstanceDTO d = Snapshots.instance(cell, "arm").orElseThrow();
        assertEquals("protective stop: safety input 'safety' stale (no fresh value) (provider guard ACTIVE)", d.holding);
        assertEquals("ACTIVE", d.state);
        // an RT half that declared its inputs in another order still names the safety input
        h.hold = ControlBlock.HOLD_SAFETY_INPUT | 2 << 8;
        assertEquals("protective stop: safety input 'safety' in a protective stop (provider guard ACTIVE)",
                Snapshots.instance(cell, "arm").orElseThrow().holding);
        // the reset latched too
        h.flags = ControlBlock.FLAG_RESET_REQUIRED | ControlBlock.FLAG_SAFE_ACTIVE;
        assertTrue(Snapshots.instance(cell, "arm").orElseThrow().holding.endsWith("; safe mode, awaiting operator reset"));
        // after the reset: waiting for the fresh command
        h.flags = 0;
        h.hold = ControlBlock.HOLD_AWAIT_COMMAND;
        assertTrue(Snapshots.instance(cell, "arm").orElseThrow().holding.startsWith("stopped: waits for a fresh command"));
        // validated data: the newest value of input 0 was rejected, the last valid one is held
        h.hold = ControlBlock.HOLD_REFERENCE | ControlBlock.HOLD_REF_INVALID << 8;
        String invalid = Snapshots.instance(cell, "arm").orElseThrow().holding;
        assertTrue(invalid.startsWith("holds the last valid reference: input 'ref' ")
                && invalid.endsWith("sends invalid values (NaN, Inf or out of range)"), invalid);
        h.hold = ControlBlock.HOLD_REFERENCE;
        assertTrue(Snapshots.instance(cell, "arm").orElseThrow().holding.startsWith("holds: waits for a reference"));
        // the supervisor lost (seen by a later runtime's snapshot of an orphan)
        h.flags = ControlBlock.FLAG_SUPERVISOR_LOST | ControlBlock.FLAG_SAFE_ACTIVE;
        assertTrue(Snapshots.instance(cell, "arm").orElseThrow().holding.startsWith("supervisor lost"));
        h.flags = 0;
        h.hold = 0;
        assertEquals(null, Snapshots.instance(cell, "arm").orElseThrow().holding);
    }

    /** Issue 15 finding 1: the guard fails for good; the arm holds, rewired, and says which guard is gone. */
    @Test
    void aGuardThatFailsIsAHoldNamingTheGuard() throws Exception {
        install(contract("guard", "<out name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\"/>",
                PERMANENT, false, 5, "50us"));
        install(contract("arm", "<in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\""
                + " safety=\"true\"><bind component=\"guard\" port=\"safety\"/></in>", PERMANENT, true, 4, "50us"));
        FakeLauncher.FakeHalf arm = launcher.running.get("arm");
        assertTrue(launcher.events.stream().anyMatch(e -> e.startsWith("arm BIND safety")), launcher.events.toString());
        for (int k = 0; k < 3; k++) {
            launcher.running.get("guard").crash(137, "killed by signal 9");
            actor.runAll();
            actor.advance(500);
        }
        assertEquals(State.FAILED, state("guard"));
        assertEquals(State.ACTIVE, state("arm"), "the arm is not stopped: it holds");
        assertEquals(arm, launcher.running.get("arm"), "and not restarted");
        assertTrue(launcher.events.contains("arm UNBIND safety"), "unbound from the dead guard: " + launcher.events);
        assertTrue(log.toString().contains("arm rewired while running (safety input 'safety' lost guard.safety: "
                + "protective stop until a guard is bound and the operator resets)"), log.toString());
        // its RT half reports the verdict NO_PROVIDER for input 0; the DTO names the guard and why
        arm.hold = ControlBlock.HOLD_SAFETY_INPUT | 3 << 8;
        String holding = Snapshots.instance(cell, "arm").orElseThrow().holding;
        assertTrue(holding.startsWith("protective stop: safety input 'safety' without a provider (provider guard FAILED: "
                + "restart intensity exceeded"), holding);
        actor.call(() -> {
            cell.uninstall("guard", "bundle stopped");
            return null;
        }, 0);
        actor.runAll();
        assertEquals("protective stop: safety input 'safety' without a provider (no guard installed)",
                Snapshots.instance(cell, "arm").orElseThrow().holding);
    }

    @Test
    void nameOwnedByAnotherBundleIsRefused() throws Exception {
        install(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        Contract c = parse(contract("prov", PROVIDER_PORTS, PERMANENT, false, 5, "50us"));
        assertFalse(actor.call(() -> cell.install(c, 4242, Path.of("/x")), 0));
        assertTrue(cell.problems().get(0).contains("already installed by bundle"), cell.problems().toString());
        assertEquals(State.ACTIVE, state("prov"));
    }
}
