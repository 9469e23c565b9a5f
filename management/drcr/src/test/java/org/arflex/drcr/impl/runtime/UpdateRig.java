package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.abi.ControlBlock;

/**
 * The cell of the update tests (D38, D41, D42, D51, D53, D55): {@code src} (provides {@code y}),
 * {@code stage} (reads {@code src}, provides {@code y}) and {@code user} (reads {@code stage.y}),
 * on the steppable actor with real launch and stop threads and fake halves whose counters and
 * output values a test sets; {@code stage} is the one updated, to a version from
 * {@code file:/x/stage-1.1.jar}. Ends with {@link #close}, which checks nothing is left behind.
 */
final class UpdateRig extends SteppedCell {

    static final String IN_SRC = "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind filter=\"(role=src)\"/></in>";
    static final String OUT = "<out name=\"y\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>";
    static final String IN_STAGE = "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind filter=\"(role=stage)\"/></in>";
    /** The running stage's output, and its first new version's. */
    static final String OLD_Y = "/arflex.t.stage.out.y";
    static final String NEW_Y = "/arflex.t.1-stage.out.y";

    UpdateRig() {
        this(new FakeLauncher());
    }

    private UpdateRig(FakeLauncher fake) {
        super(fake, fake, true);
    }

    /**
     * A contract of {@link CellChangeSetTest#contract}'s shape at {@code version}, with
     * {@code wcet} and {@code extra} (e.g. a state or rollout element) at its end.
     */
    static Contract parse(String name, String role, String ports, String version, String wcet, String extra)
            throws Exception {
        String xml = CellChangeSetTest.contract(name, role, ports, wcet)
                .replace("version=\"1.0.0\"", "version=\"" + version + "\"")
                .replace("</component>", extra + "</component>");
        return ContractParser.create(PortTypes.builtin()).parse(xml, "test.xml");
    }

    /** As above, with a WCET of 50 us. */
    static Contract parse(String name, String role, String ports, String version, String extra) throws Exception {
        return parse(name, role, ports, version, "50us", extra);
    }

    /** As above, with nothing more. */
    static Contract parse(String name, String role, String ports, String version) throws Exception {
        return parse(name, role, ports, version, "50us", "");
    }

    /** An update of {@code stage} to {@code next}, with a window, a shadow run and its tolerances. */
    static ChangeSet update(Contract next, long window, long shadow, List<ChangeSet.Tolerance> tolerances) {
        return ChangeSet.builder().update("stage", next, Path.of("/nonexistent/stage-1.1"), "file:/x/stage-1.1.jar",
                window, List.of(), shadow, tolerances).build();
    }

    static ControlBlock.Stats cycles(long n, long overruns) {
        return new ControlBlock.Stats(n, overruns, 0, 0, 0, 0, 0, 0, 0, 0);
    }

    /**
     * Counters of a 1 ms half with {@code late} late cycles (D73): each overran its period and
     * missed its deadline, as rt-core counts a cycle late beyond deadline = period.
     */
    static ControlBlock.Stats late(long n, long late) {
        return new ControlBlock.Stats(n, late, late, 0, 0, 0, 0, 0, 0, 0);
    }

    /** An arflex.Sample payload: seq, t_ns, value. */
    static byte[] sample(long seq, long tNs, double value) {
        return ByteBuffer.allocate(24).order(ByteOrder.LITTLE_ENDIAN).putLong(seq).putLong(tNs).putDouble(value).array();
    }

    /** src, stage ({@code stageWcet}, {@code stageExtra} in its contract) and user at 1.0.0, running. */
    void runningCell(String stageWcet, String stageExtra) throws Exception {
        install(parse("src", "src", OUT, "1.0.0"));
        install(parse("stage", "stage", IN_SRC + OUT, "1.0.0", stageWcet, stageExtra));
        install(parse("user", null, IN_STAGE, "1.0.0"));
    }

    /** {@link #runningCell} with a 50 us stage and nothing more; user is bound to the running stage's output. */
    void boundCell() throws Exception {
        runningCell("50us", "");
        assertTrue(fake.events.contains("user BIND x " + OLD_Y), fake.events::toString);
    }

    /** Applies {@code set} and steps until the shadow run has begun (the new half STARTed), {@code eachStep} at each. */
    CompletableFuture<ChangeSetResult> applyIntoShadow(ChangeSet set, Runnable eachStep) {
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(set), 0);
        stepUntil("the new half started in shadow", () -> {
            eachStep.run();
            return fake.events.contains("1-stage START") || f.isDone();
        });
        return f;
    }
}
