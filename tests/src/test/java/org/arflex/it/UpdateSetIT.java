package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.util.HexFormat;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.concurrent.CompletableFuture;
import java.util.function.UnaryOperator;
import java.util.zip.ZipFile;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D38 through the real runtime, on the moving arm (FailSafeIT's looping
 * program; trajectory -> tcp-correction -> sim-robot): tcp-correction, the robot's reference
 * stage, is updated in a change set while the arm moves, {@code arflex:change apply update
 * tcp-correction file:<jar> <sha256> window <cycles>}. The new version's jar goes through the
 * code gate with its pin; its half runs beside the old one as {@code 1-tcp-correction} and
 * sim-robot is bound to its output with one BIND; the old half stays warm for the window.
 *
 * <p>Two versions, both built here from the tcp-correction bundle the build made: 1.0.1, the
 * same executable under a new contract version (committed after its window), and 1.0.2-faulty,
 * whose executable is a script that runs the real one with rt-core's test fault of a crash in its
 * 50th update after its START (D68; a deliberately broken build, pinned like any other): it
 * crashes 50 cycles after the switch and is rolled back to the old half. And 1.0.1 again with an envelope declared for
 * its output that the moving arm's reference leaves: rolled back.
 *
 * <p>Asserted for every case: the guard never leaves NORMAL and sim-robot runs no safe cycle from
 * the apply to 2000 references after. The released cycles it did not run (its states' release
 * times and sequence numbers) and its late cycles (the overrun counter) are printed beside those
 * of the same span before the apply without a change, not asserted: this machine, not
 * PREEMPT_RT and shared, skips single releases about once a second and now and then a few in a
 * row without any change. Nothing waits for a reset
 * or a command, sim-robot and the guard keep their pids, nothing is restarted, the other half and
 * its segment are gone afterwards. The robot's reference across the switch: whichever cycle
 * sim-robot took the new binding at, the step from the last value of one version to the next
 * value of the other, per cycle of their source, is bounded by ChangeSetIT's bound.
 */
class UpdateSetIT {

    static final long T = CellRig.T;
    static final String CONTRACT = "OSGI-INF/arflex/tcp-correction.xml";
    static final String EXE = "native/linux-x86_64/tcp-correction-rt";

    /** A copy of the tcp-correction bundle with its contract's version set, and its executable replaced when given. */
    static Path version(Path dir, String version, byte[] exe) throws IOException {
        Map<String, UnaryOperator<byte[]>> edits = new LinkedHashMap<>();
        edits.put(CONTRACT, BundleCopies.text(xml -> xml.replaceFirst("name=\"tcp-correction\" version=\"[^\"]+\"",
                "name=\"tcp-correction\" version=\"" + version + "\""), "the contract's version attribute"));
        if (exe != null) {
            edits.put(EXE, b -> exe);
        }
        // the bundle's version too, as a release would have it (OSGi: 1.0.2.faulty)
        edits.put("META-INF/MANIFEST.MF", BundleCopies.text(mf -> mf.replaceFirst("Bundle-Version: [^\r\n]+",
                "Bundle-Version: " + version.replace('-', '.')), "the manifest's Bundle-Version"));
        return BundleCopies.copy(dir, CellRig.TCP_CORRECTION, "tcp-correction-" + version, edits);
    }

    /**
     * The deliberately faulty build 1.0.2-faulty (also ReconfigBench's): the real executable, run by a
     * script that sets rt-core's test fault: SIGSEGV in its 50th update after its START (D68), which
     * is the switch's when it has no shadow run.
     */
    static Path faulty(Path dir, String who) throws IOException {
        return version(dir, "1.0.2-faulty", FaultyVersions.crashingAfterCycles(dir, CellRig.TCP_CORRECTION, EXE, 50, who));
    }

    static byte[] entry(Path jar, String name) throws IOException {
        try (ZipFile z = new ZipFile(jar.toFile())) {
            return z.getInputStream(z.getEntry(name)).readAllBytes();
        }
    }

    static String sha256(Path f) throws Exception {
        return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-256").digest(Files.readAllBytes(f)));
    }

    /** What one update on the moving arm gave. */
    record Run(String out, long applyMs, double jump, double before, long robotCycles, long robotMissed,
               long robotLongest, long quietMissed, long quietLongest, long robotOverruns, long quietOverruns, long robotSafe, double force, long oldPid) {
    }

    /**
     * Applies {@code update tcp-correction <jar> <pin> window <window>} on the moving arm,
     * recording the robot's reference from both versions, the guard and the arm, and checks what
     * both outcomes share: no safe stop, no reset, no missed robot cycle, the same robot and guard.
     */
    static Run update(Runtime rt, Path jar, long window) throws Exception {
        return update(rt, jar, "window " + window);
    }

    /** As above, with the options after the pin as given ({@code window <cycles>}, {@code envelope ...}). */
    static Run update(Runtime rt, Path jar, String options) throws Exception {
        return update(rt, jar, options, null);
    }

    /**
     * As above; {@code traces}, when given, gets the corrected references of the old and of the
     * new half recorded from before the apply to 2000 references after it (StateConversionIT).
     */
    static Run update(Runtime rt, Path jar, String options,
            java.util.function.BiConsumer<List<CellRig.Ref>, List<CellRig.Ref>> traces) throws Exception {
        return update(rt, jar, options, traces, 2000);
    }

    /**
     * As above, with {@code quietRefs} references recorded without a change before the apply (the
     * baseline of the releases not run; 2000 above), after 1000 seen, or fewer when {@code quietRefs}
     * is small: ShadowStateIT must apply within its fade (10 s).
     */
    static Run update(Runtime rt, Path jar, String options,
            java.util.function.BiConsumer<List<CellRig.Ref>, List<CellRig.Ref>> traces, int quietRefs) throws Exception {
        long robotPid = rt.pid("sim-robot");
        long guardPid = rt.pid("force-guard");
        long oldPid = rt.pid("tcp-correction");
        CellRig.Trace<CellRig.Ref> oldRef = new CellRig.Trace<>();
        CellRig.Trace<CellRig.Ref> newRef = new CellRig.Trace<>();
        CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
        CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
        Path newSeg = rt.segment("1-tcp-correction", "corrected");
        String pin = sha256(jar);
        try (CellRig.Port rp = new CellRig.Port(rt.segment("tcp-correction", "corrected"), CellRig.REF_SIZE);
                CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                CellRig.Recorder rec = new CellRig.Recorder()) {
            rec.add(rp, CellRig.Ref::of, CellRig.Ref::seq, oldRef::add);
            rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
            rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
            rec.start();
            int seen = Math.min(1000, 100 + quietRefs);
            rt.waitUntil("the arm moving and " + seen + " references seen", T,
                    () -> FailSafeIT.moving(js) && oldRef.size() > seen);
            assertTrue(CellRig.awaitingReset(rt).isEmpty(), "before: " + CellRig.awaitingReset(rt));
            // the same span without a change: what this machine gives sim-robot anyway
            Map<String, Object> quiet0 = ChangeSetIT.stats(rt, "sim-robot");
            int q = oldRef.size();
            int jsQuiet = js.size();
            rt.waitUntil(quietRefs + " references without a change", T, () -> oldRef.size() > q + quietRefs);
            Map<String, Object> robot0 = ChangeSetIT.stats(rt, "sim-robot");
            long quietOverruns = ChangeSetIT.delta(quiet0, robot0, "overruns");
            System.out.printf(Locale.ROOT, "UpdateSetIT: sim-robot over 2000 references before the apply, no change: "
                    + "%d cycles, %d overruns, %d safe cycles%n", ChangeSetIT.delta(quiet0, robot0, "cycles"),
                    quietOverruns, ChangeSetIT.delta(quiet0, robot0, "safeCycles"));
            int logMark = rt.logMark();
            int mark = oldRef.size();
            int jsMark = js.size();
            long[] quietSkips = skips(js.snapshot().subList(jsQuiet, jsMark), 0);
            long t0 = System.nanoTime();
            // the shell is busy until the window is over: the new version's segment is found on disk
            CompletableFuture<String> apply = CompletableFuture.supplyAsync(() -> rt.cmd(
                    "arflex:change apply update tcp-correction file:" + jar + " " + pin + " " + options));
            CellRig.Port np = null;
            try {
                np = rec.recordRefsWhenItAppears(newSeg, apply, newRef::add);
                long tSeen = System.nanoTime();
                String out = apply.get(T, java.util.concurrent.TimeUnit.MILLISECONDS);
                System.out.printf(Locale.ROOT, "UpdateSetIT: the new version's segment seen %.1f ms after the apply "
                        + "was typed, the command returned after %.1f ms%n", (tSeen - t0) / 1e6, (System.nanoTime() - t0) / 1e6);
                long tookMs = (System.nanoTime() - t0) / 1_000_000;
                System.out.println("UpdateSetIT: apply (" + tookMs + " ms):\n" + out);
                System.out.println("UpdateSetIT: the runtime's log of the update:\n" + String.join("\n", rt.logSince(logMark)
                        .stream().filter(l -> l.contains("tcp-correction") && !l.contains("  ")).toList()));
                assertTrue(out.contains("\napplied: "), out);
                assertTrue(np != null, "the new version's segment was never seen");
                int after = oldRef.size() + newRef.size();
                rt.waitUntil("2000 references after the apply", T, () -> oldRef.size() + newRef.size() > after + 2000);
                assertNull(rec.error, () -> "recorder: " + rec.error);

                // the step at a switch, whichever cycle sim-robot took it at: from a value of one
                // version to the next value (by stamp) of the other, per source cycle
                List<CellRig.Ref> o = oldRef.snapshot();
                List<CellRig.Ref> n = newRef.snapshot();
                double jump = Math.max(crossSteps(o, n), crossSteps(n, o));
                double before = 0;
                for (int i = 1; i < mark; i++) {
                    before = Math.max(before, ChangeSetIT.perSourceCycle(o.get(i - 1), o.get(i)));
                }
                List<CellRig.Safety> ss = safety.snapshot();
                CellRig.Safety worst = ss.stream().max(java.util.Comparator.comparingDouble(CellRig.Safety::forceNorm))
                        .orElseThrow();
                CellRig.Safety tripped = ss.stream().filter(s -> s.mode() != CellRig.Safety.NORMAL).findFirst().orElse(null);
                System.out.printf(Locale.ROOT, "UpdateSetIT: largest force %.1f N at %.1f ms after the apply was typed; "
                        + "first value of the new version stamped %.1f ms after it%n", worst.forceNorm(),
                        (worst.tNs() - t0) / 1e6, n.isEmpty() ? -1 : (n.get(0).tNs() - t0) / 1e6);
                if (tripped != null || worst.forceNorm() > 100) {
                    System.out.println("UpdateSetIT: the runtime since the apply:\n" + String.join("\n", rt.logSince(logMark)));
                }
                if (tripped != null) { // D75: what led to it (a force trip or a lost heartbeat, the robot's seq gaps)
                    VisionStateIT.printTrip("UpdateSetIT", tripped, ss, js.snapshot(), t0);
                }
                assertNull(tripped, () -> "the guard left NORMAL (" + tripped.causes() + "): " + tripped);
                int robotFlags = CellPorts.ctlFlags(Path.of("/dev/shm/arflex." + rt.rid + ".sim-robot.ctl"));
                assertEquals(0, robotFlags & CellPorts.FLAG_SAFE_ACTIVE, "sim-robot in safe mode");
                assertEquals(List.of(), CellRig.awaitingReset(rt));
                assertEquals(List.of(), CellRig.awaitingCommand(rt));
                assertNull(FailSafeIT.holding(rt, "sim-robot"));
                Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
                // cycles sim-robot never ran: its states carry their release time and a sequence
                // number per cycle; over the span recorded the releases are 1 ms apart
                List<CellRig.JointState> j = js.since(jsMark);
                CellRig.JointState first = j.get(0);
                CellRig.JointState last = j.get(j.size() - 1);
                long[] skips = skips(j, t0);
                Run r = new Run(out, tookMs, jump, before, last.seq() - first.seq(), skips[0], skips[1],
                        quietSkips[0], quietSkips[1], ChangeSetIT.delta(robot0, robot1, "overruns"), quietOverruns,
                        ChangeSetIT.delta(robot0, robot1, "safeCycles"), worst.forceNorm(), oldPid);
                System.out.printf(Locale.ROOT, "UpdateSetIT: largest step of the robot's reference between the two "
                        + "versions: %.3f mrad per source cycle (bound %.3f; the program alone before: %.3f); %d values "
                        + "of the new version seen; sim-robot from the apply to 2000 references after: %d cycles run, "
                        + "%d released and not run, at most %d in a row (%d, at most %d in a row, in the same span "
                        + "before, without a change), %d safe cycles, %d late (overruns; %d before); largest force the "
                        + "guard read %.1f N%n", jump * 1e3, ChangeSetIT.JUMP_BOUND * 1e3, before * 1e3, n.size(),
                        r.robotCycles(), r.robotMissed(), r.robotLongest(), r.quietMissed(), r.quietLongest(),
                        r.robotSafe(), r.robotOverruns(), r.quietOverruns(), r.force());
                assertTrue(r.robotCycles() > 2000, "sim-robot's states over the span: " + r.robotCycles());
                assertEquals(0, r.robotSafe(), "sim-robot ran safe cycles");
                // The releases sim-robot did not run are asserted where the switch acts (its turn
                // and the cycle boundary after it). Over the whole span they are not: this machine
                // (not PREEMPT_RT, shared with a CI run, two cores) skips single releases now and
                // then without any change (the span before says how many; D59 says whose they are);
                // a stall that matters to the arm shows as safe cycles or the guard's stop above.
                SwitchWindow.of(rt.logSince(logMark)).assertNoReleaseLost("UpdateSetIT", j);
                assertEquals(robotPid, rt.pid("sim-robot"));
                assertEquals(guardPid, rt.pid("force-guard"));
                if (traces != null) {
                    traces.accept(o, n);
                }
                return r;
            } finally {
                if (np != null) {
                    np.close();
                }
            }
        }
    }

    /**
     * Cycles sim-robot did not run over {@code js}: its states carry their release time and a
     * sequence number per cycle, releases 1 ms apart. Each gap is printed with its time after
     * {@code t0} ({@link System#nanoTime()}, the same clock; 0: not printed).
     */
    static long missed(List<CellRig.JointState> js, long t0) {
        return skips(js, t0)[0];
    }

    /** {cycles not run, the longest run of them} over {@code js}; see {@link #missed}. */
    static long[] skips(List<CellRig.JointState> js, long t0) {
        long missed = 0;
        long longest = 0;
        for (int i = 1; i < js.size(); i++) {
            CellRig.JointState a = js.get(i - 1);
            CellRig.JointState b = js.get(i);
            long skipped = Math.round((b.tNs() - a.tNs()) / 1e6) - (b.seq() - a.seq());
            if (skipped != 0) {
                missed += skipped;
                longest = Math.max(longest, skipped);
                if (t0 != 0) {
                    System.out.printf(Locale.ROOT, "UpdateSetIT: sim-robot did not run %d cycles %.1f ms after the "
                            + "apply was typed (releases %.3f ms apart, seq +%d)%n", skipped, (a.tNs() - t0) / 1e6,
                            (b.tNs() - a.tNs()) / 1e6, b.seq() - a.seq());
                }
            }
        }
        return new long[] {missed, longest};
    }

    /**
     * The largest step, per source cycle, from a value of {@code from} to the first value of
     * {@code to} with a later stamp (what sim-robot reads when it takes the other binding there).
     */
    static double crossSteps(List<CellRig.Ref> from, List<CellRig.Ref> to) {
        java.util.TreeMap<Long, CellRig.Ref> byStamp = new java.util.TreeMap<>();
        for (CellRig.Ref r : to) {
            byStamp.put(r.tNs(), r);
        }
        double m = 0;
        for (CellRig.Ref a : from) {
            var next = byStamp.higherEntry(a.tNs());
            if (next != null && next.getKey() - a.tNs() < 5_000_000L) { // both ran then
                m = Math.max(m, ChangeSetIT.perSourceCycle(a, next.getValue()));
            }
        }
        return m;
    }

    @Test
    void tcpCorrectionIsUpdatedToANewVersionOnTheMovingArm() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("update-set")) {
            List<String> cell = FailSafeIT.movingCell(rt);
            assertTrue(cell.contains("tcp-correction"), cell.toString());
            Path jar = version(Files.createDirectories(rt.dir.resolve("versions")), "1.0.1", null);
            String dry = rt.cmd("arflex:change plan update tcp-correction file:" + jar + " " + sha256(jar));
            System.out.println("UpdateSetIT: dry run:\n" + dry);
            assertTrue(dry.contains("admitted (dry run: nothing changed)") && dry.contains("RESTART  tcp-correction"), dry);
            String unpinned = rt.cmd("arflex:change apply update tcp-correction file:" + jar);
            assertTrue(unpinned.startsWith("error: ") && unpinned.contains("not signed by a trusted key"), unpinned);
            assertTrue(Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance 1-tcp-correction ")));

            Run r = update(rt, jar, 1000);
            assertTrue(r.out().contains("update tcp-correction: committed: the new version ran"), r.out());
            assertTrue(r.jump() <= ChangeSetIT.JUMP_BOUND, "reference step " + r.jump() + " rad per source cycle");
            rt.awaitState("ACTIVE", T, "tcp-correction", "sim-robot", "force-guard", "trajectory");
            assertNotEquals(r.oldPid(), rt.pid("tcp-correction"), "the new version runs");
            assertEquals(0, ((Number) rt.instance("tcp-correction").get("restarts")).intValue());
            assertTrue(rt.cmd("arflex:info tcp-correction").contains("1.0.1"), rt.cmd("arflex:info tcp-correction"));
            // D43: the bundle follows the committed version, and the running half is kept
            java.util.regex.Matcher kept = java.util.regex.Pattern.compile(
                    "bundle \\d+ updated \\S+ -> 1\\.0\\.1; 'tcp-correction' kept running \\(pid (\\d+)\\)").matcher(r.out());
            assertTrue(kept.find(), r.out());
            assertEquals(rt.pid("tcp-correction"), Long.parseLong(kept.group(1)), "the committed half keeps running");
            String lb = rt.cmd("lb");
            assertTrue(lb.lines().anyMatch(l -> l.contains("tcp-correction") && l.contains("(1.0.1)")), lb);
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
            rt.waitUntil("the old version's process and segment gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance tcp-correction ")) && !Files.exists(
                    rt.segment("tcp-correction", "corrected")));
        }
    }

    @Test
    void anUpdateWhoseOutputLeavesItsDeclaredEnvelopeIsRolledBack() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("update-envelope")) {
            FailSafeIT.movingCell(rt);
            Path jar = version(Files.createDirectories(rt.dir.resolve("versions")), "1.0.1", null);
            // the looping program moves joint 0 well beyond 0.01 rad: the new version's
            // reference leaves this envelope at its first value
            Run r = update(rt, jar, "window 5000 envelope corrected.q -0.01 0.01");
            assertTrue(r.out().contains("update tcp-correction: rolled back after ") && r.out().contains(
                    "left the envelope [-0.01, 0.01] declared for the update"), r.out());
            assertEquals(r.oldPid(), rt.pid("tcp-correction"), "the old half runs the component again");
            assertEquals(0, ((Number) rt.instance("tcp-correction").get("restarts")).intValue(), "no restart");
            rt.awaitState("ACTIVE", T, "tcp-correction", "sim-robot", "force-guard", "trajectory");
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
            rt.waitUntil("the new version's process and segment gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance 1-tcp-correction ")) && !Files.exists(
                    rt.segment("1-tcp-correction", "corrected")));
            assertTrue(r.jump() <= ChangeSetIT.JUMP_BOUND, "reference step " + r.jump() + " rad per source cycle");
        }
    }

    @Test
    void aVersionThatCrashesAfterTheSwitchIsRolledBackWithTheArmMoving() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("update-rollback")) {
            FailSafeIT.movingCell(rt);
            Path jar = faulty(Files.createDirectories(rt.dir.resolve("versions")), "UpdateSetIT");

            Run r = update(rt, jar, 5000);
            assertTrue(r.out().contains("update tcp-correction: rolled back after ") && r.out().contains("killed by signal 11")
                    && r.out().contains("pid " + r.oldPid() + " (tcp-correction) runs it again"), r.out());
            System.out.printf(Locale.ROOT, "UpdateSetIT: rollback: %s%n", r.out().lines()
                    .filter(l -> l.contains("rolled back")).findFirst().orElse(""));
            assertEquals(r.oldPid(), rt.pid("tcp-correction"), "the old half runs the component again");
            assertEquals(0, ((Number) rt.instance("tcp-correction").get("restarts")).intValue(), "no restart");
            rt.awaitState("ACTIVE", T, "tcp-correction", "sim-robot", "force-guard", "trajectory");
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
            assertTrue(rt.cmd("arflex:list").contains("rolled back"), rt.cmd("arflex:list"));
            rt.waitUntil("the faulty version's process and segment gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance 1-tcp-correction ")) && !Files.exists(
                    rt.segment("1-tcp-correction", "corrected")));
            System.out.printf(Locale.ROOT, "UpdateSetIT: rollback step %.3f mrad per source cycle (bound %.3f)%n",
                    r.jump() * 1e3, ChangeSetIT.JUMP_BOUND * 1e3);
            assertTrue(r.jump() <= ChangeSetIT.JUMP_BOUND, "reference step " + r.jump() + " rad per source cycle");
        }
    }

    /**
     * D73: a version late in every 10th cycle (rt-core's test fault ARFLEX_FAULT_LATE_EVERY_CYCLES=10:
     * that update spins past the next release) is rolled back early in its window on the moving
     * arm, however the machine's stalls are counted; the old half runs the component again.
     */
    @Test
    void aVersionLateInEveryTenthCycleIsRolledBackEarlyInItsWindow() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("update-late")) {
            FailSafeIT.movingCell(rt);
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            Path jar = version(dir, "1.0.3-late", FaultyVersions.lateEvery(dir, CellRig.TCP_CORRECTION, EXE, 10,
                    "UpdateSetIT"));
            Run r = update(rt, jar, 1000);
            String verdict = r.out().lines().filter(l -> l.contains("update tcp-correction:")).reduce("", (a, b) -> b);
            System.out.println("UpdateSetIT: a version late in every 10th cycle: " + verdict);
            java.util.regex.Matcher m = java.util.regex.Pattern.compile("rolled back after (\\d+) cycles of the new "
                    + "version \\([^)]*\\): the new version overran or missed its deadline in (\\d+) of its first").matcher(verdict);
            assertTrue(m.find(), r.out());
            assertTrue(Long.parseLong(m.group(1)) <= 200, "rolled back after " + m.group(1) + " cycles: " + verdict);
            assertEquals(r.oldPid(), rt.pid("tcp-correction"), "the old half runs the component again");
            rt.awaitState("ACTIVE", T, "tcp-correction", "sim-robot", "force-guard", "trajectory");
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
            rt.waitUntil("the late version's process and segment gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance 1-tcp-correction ")) && !Files.exists(
                    rt.segment("1-tcp-correction", "corrected")));
        }
    }
}
