package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Path;
import java.util.List;
import java.util.Set;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.CountDownLatch;
import java.util.concurrent.TimeUnit;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * Change sets (D35): several actions planned as one, admitted whole or refused whole, prepared
 * while the old configuration runs, switched in one actor turn, and torn down without a trace
 * when the preparation fails. The actor is the steppable one; launches and stops run on real
 * threads, and the launcher can hold a launch until the test releases it.
 *
 * <p>The cell: {@code old} provides {@code y} with {@code role=src}; {@code user} reads it through
 * the filter {@code (role=src)}; {@code new} (and {@code new2}) provide the same and are known to
 * the cell as INSTALLED (their bundle installed, not started), as teach is next to trajectory.
 */
class CellChangeSetTest {

    private static final String OUT = "<out name=\"y\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>";
    private static final String BY_ROLE = "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind filter=\"(role=src)\"/></in>";

    private final FakeLauncher fake = new FakeLauncher();
    /** Launches of these names wait for {@link #release}. */
    private final Set<String> held = java.util.concurrent.ConcurrentHashMap.newKeySet();
    private final CountDownLatch release = new CountDownLatch(1);
    private final RtLauncher launcher = new RtLauncher() {
        @Override
        public RtHalf launch(Spec spec) throws IOException {
            if (held.contains(spec.instance())) {
                try {
                    assertTrue(release.await(10, TimeUnit.SECONDS), "never released");
                } catch (InterruptedException e) {
                    Thread.currentThread().interrupt();
                    throw new IOException("interrupted");
                }
            }
            return fake.launch(spec);
        }

        @Override
        public Output createOutput(String segmentName, int method, String typeName, int major, int minor,
                                   int elemSize, int depth, int overflow) throws IOException {
            return fake.createOutput(segmentName, method, typeName, major, minor, elemSize, depth, overflow);
        }
    };
    private final SteppedCell rig = new SteppedCell(fake, launcher, true);
    private final ManualActor actor = rig.actor;
    private final Cell cell = rig.cell;

    @AfterEach
    void nothingLeaks() {
        release.countDown();
        rig.close();
    }

    static String contract(String name, String role, String ports, String wcet) {
        return "<component xmlns=\"urn:arflex:contract:1\" name=\"" + name + "\" version=\"1.0.0\">"
                + "<implementation executable=\"" + name + "\" task=\"periodic\" movesHardware=\"false\"/>"
                + (role == null ? "" : "<attributes><attribute name=\"role\" value=\"" + role + "\"/></attributes>")
                + "<ports>" + ports + "</ports>"
                + "<properties><property name=\"gain\" type=\"double\" default=\"2.0\" min=\"-10\" max=\"10\" mutable=\"true\"/>"
                + "<property name=\"mode\" type=\"int\" default=\"1\" min=\"0\" max=\"3\" mutable=\"false\"/></properties>"
                + "<timing period=\"1ms\" deadline=\"1ms\" wcet=\"" + wcet + "\" priority=\"80\"/>"
                + "<resources memory=\"1MiB\" network=\"0\"/><criticality>5</criticality>"
                + "<fault restart=\"permanent\" intensity=\"2\" window=\"10s\" backoff=\"100ms\" safe=\"hold\""
                + " heartbeatTimeout=\"100ms\"/></component>";
    }

    private static Contract parse(String xml) throws Exception {
        return ContractParser.create(PortTypes.builtin()).parse(xml, "test.xml");
    }

    private void install(String xml) throws Exception {
        rig.install(parse(xml));
    }

    /** Known to the cell, not started: what an installed, not started bundle gives. */
    private void register(String xml) throws Exception {
        Contract c = parse(xml);
        assertTrue(actor.call(() -> cell.register(c, c.name().hashCode()), 0), rig.log::toString);
    }

    private void runningCell() throws Exception {
        install(contract("old", "src", OUT, "50us"));
        install(contract("user", null, BY_ROLE, "50us"));
        register(contract("new", "src", OUT, "50us"));
        assertTrue(fake.events.contains("user BIND x /arflex.t.old.out.y"), fake.events::toString);
    }

    private static ChangeSet replaceOldByNew() {
        return ChangeSet.builder().install("new", Path.of("/nonexistent/new")).uninstall("old").build();
    }

    @Test
    void theDryRunShowsTheWholeSetAdmittedAndChangesNothing() throws Exception {
        runningCell();
        int before = fake.events.size();
        ChangeSetResult r = actor.call(() -> cell.planChangeSet(replaceOldByNew()), 0);
        assertTrue(r.admitted(), r.text());
        assertFalse(r.applied());
        assertTrue(r.text().startsWith("change set: install new; uninstall old\nadmitted (dry run: nothing changed)\n"),
                r.text());
        assertTrue(r.text().contains("START    new"), r.text());
        assertTrue(r.text().contains("STOP     old"), r.text());
        assertTrue(r.text().contains("REBIND   user"), r.text());
        assertTrue(r.text().contains("user.x <- new.y"), r.text());
        assertEquals(before, fake.events.size(), "nothing launched, bound or stopped: " + fake.events);
        assertEquals(State.INSTALLED, rig.state("new"));
        assertEquals(Set.of("old", "user"), cell.planner().active());
    }

    @Test
    void theNewHalfIsReadyBeforeTheSwitchAndTheOldStopsOnlyAfterItsConsumerMoved() throws Exception {
        runningCell();
        held.add("new");
        ChangeSet set = ChangeSet.builder().install("new", Path.of("/nonexistent/new")).uninstall("old")
                .set("user", "gain", "3").set("new", "mode", "2").build();
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(set), 0);
        rig.stepUntil("new being launched", () -> fake.specs.stream().anyMatch(s -> s.instance().equals("new"))
                || cell.instance("new").orElseThrow().launching);
        actor.runAll();
        // while new is prepared the old configuration runs untouched, the planner unchanged
        assertFalse(f.isDone());
        assertEquals(State.ACTIVE, rig.state("old"));
        assertEquals(State.ACTIVE, rig.state("user"));
        assertEquals(Set.of("old", "user"), cell.planner().active());
        assertFalse(fake.events.contains("user UNBIND x"), fake.events::toString);
        assertTrue(fake.openOutputs.containsKey("/arflex.t.new.out.y"), "new's segment exists before the switch");
        // a second set is refused while this one is prepared
        ChangeSetResult second = actor.call(() -> cell.planChangeSet(replaceOldByNew()), 0);
        assertTrue(second.refusal().startsWith("another change set is being applied"), second.text());

        release.countDown();
        rig.stepUntil("the change set's outcome", f::isDone);
        ChangeSetResult r = f.join();
        assertTrue(r.applied(), r.text());
        assertNull(r.refusal());
        rig.stepUntil("old stopped and its segment gone", () -> cell.instance("old").isEmpty()
                && !fake.running.containsKey("old") && !fake.openOutputs.containsKey("/arflex.t.old.out.y"));
        // order: spawned and READY, then started and bound, then the consumer moved, then the old one stops
        int launched = rig.index("new LAUNCH");
        int started = rig.index("new START");
        int moved = rig.index("user BIND x /arflex.t.new.out.y");
        int stopped = rig.index("old SHUTDOWN");
        assertTrue(launched < started && started < moved && moved < stopped, fake.events.toString());
        assertFalse(fake.events.contains("user UNBIND x"), "a BIND replaces the binding, no gap: " + fake.events);
        assertEquals(1, fake.events.stream().filter(e -> e.equals("user SET_PARAM 0")).count(), fake.events::toString);
        assertEquals(3.0, Double.longBitsToDouble(fake.running.get("user").paramValue(0)));
        assertEquals(2L, fake.running.get("new").paramValue(1), "an immutable parameter of a new component, set before its spawn");
        assertEquals(State.ACTIVE, rig.state("new"));
        assertEquals(State.ACTIVE, rig.state("user"));
        assertEquals(Set.of("new", "user"), cell.planner().active());
    }

    @Test
    void aSetThatCannotBeAdmittedWholeIsRefusedNamingTheActionAndNothingChanges() throws Exception {
        runningCell();
        register(contract("lonely", null, "<in name=\"x\" type=\"arflex.Pose\" typeVersion=\"1.0\" method=\"state\">"
                + "<bind filter=\"(role=nobody)\"/></in>", "50us"));
        int before = fake.events.size();
        ChangeSet set = ChangeSet.builder().install("new", Path.of("/nonexistent/new"))
                .install("lonely", Path.of("/nonexistent/lonely")).uninstall("old").build();
        ChangeSetResult r = rig.apply(set);
        assertFalse(r.applied());
        assertFalse(r.admitted());
        assertTrue(r.refusal().startsWith("install lonely: not admitted: input 'x' of 'lonely'"), r.refusal());
        assertTrue(r.text().contains("START    new"), "the plan is shown with the refusal: " + r.text());
        // a set naming what the cell does not have is refused before planning
        ChangeSetResult unknown = rig.apply(ChangeSet.builder().uninstall("ghost").set("user", "mode", "2")
                .set("user", "speed", "1").build());
        assertEquals("uninstall ghost: 'ghost' is not installed; set user mode 2: user.mode is immutable while it runs "
                + "(mutable=false); set user speed 1: user: no parameter 'speed' (has [gain, mode])", unknown.refusal());
        // a set that stops what it does not name is refused (uninstalling the only provider)
        ChangeSetResult sideEffect = rig.apply(ChangeSet.builder().uninstall("old").build());
        assertTrue(sideEffect.refusal().startsWith("the set would stop 'user'"), sideEffect.refusal());
        actor.runAll();
        assertEquals(before, fake.events.size(), "nothing launched, bound or stopped: " + fake.events);
        assertEquals(Set.of("old", "user"), cell.planner().active());
        assertEquals(State.INSTALLED, rig.state("new"));
        assertEquals(State.INSTALLED, rig.state("lonely"));
    }

    @Test
    void aSpawnThatFailsTearsDownWhatWasPreparedAndTheOldConfigurationRunsOn() throws Exception {
        runningCell();
        register(contract("new2", null, "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\">"
                + "<bind component=\"new\" port=\"y\"/></in>" + OUT.replace("\"y\"", "\"w\""), "50us"));
        fake.failLaunches.put("new2", 1);
        long oldPid = fake.running.get("old").pid;
        ChangeSetResult r = rig.apply(ChangeSet.builder().install("new", Path.of("/nonexistent/new"))
                .install("new2", Path.of("/nonexistent/new2")).uninstall("old").set("new", "gain", "5").build());
        assertFalse(r.applied());
        assertTrue(r.refusal().startsWith("preparation failed, nothing changed: preparing 'new2': RT half new2 exited"),
                r.refusal());
        rig.stepUntil("new's prepared half stopped and the segments gone", () -> !fake.running.containsKey("new")
                && !fake.openOutputs.containsKey("/arflex.t.new.out.y") && !fake.openOutputs.containsKey("/arflex.t.new2.out.w"));
        assertTrue(rig.index("new LAUNCH") < rig.index("new SHUTDOWN"), fake.events.toString());
        assertFalse(fake.events.contains("new START"), fake.events::toString);
        assertFalse(fake.events.stream().anyMatch(e -> e.startsWith("user BIND x /arflex.t.new")), fake.events::toString);
        assertFalse(fake.events.stream().anyMatch(e -> e.startsWith("old ") && !e.equals("old LAUNCH") && !e.equals("old START")
                && !e.startsWith("old BIND")), "old was not touched: " + fake.events);
        assertEquals(oldPid, fake.running.get("old").pid);
        assertEquals(Set.of("old", "user"), cell.planner().active());
        assertEquals(State.INSTALLED, rig.state("new"));
        assertEquals(State.INSTALLED, rig.state("new2"));
        assertEquals("2", actor.call(() -> cell.getParam("new", "gain"), 0).replace(".0", ""), "the set's write undone");
        // and the same set applies once the spawn works
        ChangeSetResult again = rig.apply(ChangeSet.builder().install("new", Path.of("/nonexistent/new"))
                .install("new2", Path.of("/nonexistent/new2")).uninstall("old").build());
        assertTrue(again.applied(), again.text());
        rig.stepUntil("new2 ACTIVE", () -> rig.state("new2") == State.ACTIVE && !fake.running.containsKey("old"));
        assertTrue(fake.events.contains("new2 BIND x /arflex.t.new.out.y"), fake.events::toString);
    }

    @Test
    void aCellThatChangedWhileTheSetWasPreparedIsNotSwitchedAndTheChangeStands() throws Exception {
        runningCell();
        held.add("new");
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(replaceOldByNew()), 0);
        actor.runAll();
        // meanwhile a second provider with role=src is installed the ordinary way: user's input
        // is ambiguous and user stops (the planner's rule), so the set's plan is not the one shown
        install(contract("rival", "src", OUT, "50us"));
        rig.stepUntil("user stopped by the ambiguity", () -> rig.state("user") != State.ACTIVE);
        release.countDown();
        rig.stepUntil("the change set's outcome", f::isDone);
        ChangeSetResult r = f.join();
        assertFalse(r.applied());
        assertTrue(r.refusal().startsWith("preparation failed, nothing changed: the cell changed while the set was prepared"),
                r.refusal());
        rig.stepUntil("new's prepared half stopped", () -> !fake.running.containsKey("new")
                && !fake.openOutputs.containsKey("/arflex.t.new.out.y"));
        assertFalse(fake.events.contains("new START"), fake.events::toString);
        assertEquals(Set.of("old", "rival"), cell.planner().active());
        assertEquals(State.ACTIVE, rig.state("old"));
        assertEquals(State.INSTALLED, rig.state("new"));
    }

    @Test
    void aPreparedHalfThatExitsBeforeTheSwitchTearsTheSetDown() throws Exception {
        runningCell();
        register(contract("new2", null, OUT.replace("\"y\"", "\"w\""), "50us"));
        held.add("new2");
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(ChangeSet.builder()
                .install("new", Path.of("/nonexistent/new")).install("new2", Path.of("/nonexistent/new2"))
                .uninstall("old").build()), 0);
        rig.stepUntil("new READY", () -> fake.running.containsKey("new"));
        actor.runAll();
        fake.running.get("new").crash(139, "killed by signal 11");
        rig.stepUntil("the change set's outcome", f::isDone);
        ChangeSetResult r = f.join();
        assertFalse(r.applied());
        assertTrue(r.refusal().contains("'new' (pid ") && r.refusal().contains("exited before the switch: killed by signal 11"),
                r.refusal());
        // new2's launch comes back after the teardown: its half is stopped at once
        release.countDown();
        rig.stepUntil("new2's late half stopped", () -> fake.events.contains("new2 SHUTDOWN") && !fake.running.containsKey("new2")
                && !fake.openOutputs.containsKey("/arflex.t.new2.out.w") && !fake.openOutputs.containsKey("/arflex.t.new.out.y"));
        assertEquals(Set.of("old", "user"), cell.planner().active());
        assertEquals(State.ACTIVE, rig.state("old"));
        assertEquals(List.of(), fake.events.stream().filter(e -> e.startsWith("user UNBIND") || e.startsWith("old SHUTDOWN")).toList());
    }
}
