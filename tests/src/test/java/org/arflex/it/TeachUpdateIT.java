package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.channels.FileChannel;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.concurrent.CompletableFuture;
import java.util.function.UnaryOperator;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D57 through the real runtime: teach, moving the arm in teach mode (the
 * simulator's hand pulls the tool) with a recording in progress, is updated in a change set to a
 * new build of itself (1.1.1, the built bundle under a new contract version, pinned). Its state
 * block (arflex.TeachState) carries the motion and what identifies the recording (count, a keyed
 * checksum chain, its newest 128 waypoints); the recording itself goes through the old half's
 * journal file in the data folder, which the new half reads at the ADOPT and joins with the
 * state block's tail at its START. Asserted: committed, no safe stop, no reset; teach's joint
 * reference across the two halves within one cycle of motion ({@link ChangeSetIT#JUMP_BOUND});
 * the recording whole (the new half's journal begins with the old half's waypoints, byte for
 * byte, and counts on from them). Then the new half's journal is damaged (one waypoint changed,
 * then the file cut short) and another update is applied: refused at its preparation with the
 * reason naming what is wrong, the running half untouched, the arm never stops.
 */
class TeachUpdateIT {

    static final long T = CellRig.T;
    static final String CONTRACT = "OSGI-INF/arflex/teach.xml";
    // arflex.TeachState 1.0 (contracts/types/arflex.TeachState.xml): size and offsets
    static final int TS_SIZE = 6456;
    static final int TS_REC_COUNT = 28;
    static final int TS_REC_KEY = 32;
    static final int TS_REC_NONCE = 48;
    static final int TS_JOURNAL_PID = 72;
    static final int TS_TAIL_FIRST = 76;
    static final int HEADER = 64;

    static Path version(Path dir, String version) throws IOException {
        Map<String, UnaryOperator<byte[]>> edits = new LinkedHashMap<>();
        edits.put(CONTRACT, BundleCopies.text(xml -> {
            assertTrue(xml.contains("<state type=\"arflex.TeachState\""), "the built teach declares its state");
            return xml.replaceFirst("name=\"teach\" version=\"[^\"]+\"", "name=\"teach\" version=\"" + version + "\"");
        }, "the contract's version attribute"));
        edits.put("META-INF/MANIFEST.MF", BundleCopies.text(mf -> mf.replaceFirst("Bundle-Version: [^\r\n]+",
                "Bundle-Version: " + version), "the manifest's Bundle-Version"));
        return BundleCopies.copy(dir, CellRig.TEACH, "teach-" + version, edits);
    }

    /** The newest value of a half's state block ({@code id}: "teach" or "1-teach"), null if none. */
    static ByteBuffer state(Runtime rt, String id) {
        try (CellRig.Port p = new CellRig.Port(Path.of("/dev/shm/arflex." + rt.rid + "." + id + ".state"), TS_SIZE)) {
            return p.read();
        } catch (IOException e) {
            return null;
        }
    }

    static Path journal(Runtime rt, ByteBuffer st) {
        return rt.dir.resolve("data").resolve(String.format(Locale.ROOT, "teach-rec-%d-%016x.bin",
                Integer.toUnsignedLong(st.getInt(TS_JOURNAL_PID)), st.getLong(TS_REC_NONCE)));
    }

    @Test
    void teachIsUpdatedWhileItMovesTheArmAndRecordsAndKeepsItsRecording() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TEACH, CellRig.FORCE_GUARD);
        try (Runtime rt = new Runtime("teach-update")) {
            List<String> cell = new java.util.ArrayList<>(CellRig.installArm(rt));
            rt.installAndStart(CellRig.TEACH);
            cell.add("teach");
            rt.awaitState("ACTIVE", T, cell.toArray(String[]::new));
            rt.waitUntil("the arm follows teach", T, () -> CellRig.armFollows(rt, "teach"));
            assertTrue(state(rt, "teach") != null, "teach publishes its state block");
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            Path jar = version(dir, "1.1.1");
            long robotPid = rt.pid("sim-robot");
            long guardPid = rt.pid("force-guard");
            long oldPid = rt.pid("teach");

            // teach mode; a hand pulls the tool 0.35 m along +y over 14 s (the arm still moves at the
            // switch however long the machine takes to get there); a waypoint every 0.2 mrad
            CellRig.set(rt, "teach", "record_step", "0.0002");
            CellRig.set(rt, "teach", "teach", "true");
            CellRig.set(rt, "sim-robot", "guide_dx", "0");
            CellRig.set(rt, "sim-robot", "guide_dy", "0.35");
            CellRig.set(rt, "sim-robot", "guide_dz", "0");
            CellRig.set(rt, "sim-robot", "guide_duration_ms", "14000");
            CellRig.set(rt, "sim-robot", "guide_force_n", "60");

            CellRig.Trace<CellRig.Ref> oldOut = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> newOut = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> robotRef = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
            Path robotIn = cell.contains("tcp-correction") ? rt.segment("tcp-correction", "corrected")
                    : rt.segment("teach", "joint_ref");
            try (CellRig.Port op = new CellRig.Port(rt.segment("teach", "joint_ref"), CellRig.REF_SIZE);
                    CellRig.Port rp = new CellRig.Port(robotIn, CellRig.REF_SIZE);
                    CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(op, CellRig.Ref::of, CellRig.Ref::seq, oldOut::add);
                rec.add(rp, CellRig.Ref::of, CellRig.Ref::seq, robotRef::add);
                rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
                rec.start();
                // a recording in progress that no longer fits the state block's tail: the journal is needed
                rt.waitUntil("more than 300 waypoints recorded while the arm yields", T, () -> {
                    ByteBuffer s = state(rt, "teach");
                    return s != null && s.getInt(TS_REC_COUNT) > 300;
                });
                ByteBuffer before = state(rt, "teach");
                Path oldJournal = journal(rt, before);
                assertTrue(Files.exists(oldJournal), "the old half's journal " + oldJournal);
                assertEquals("rw-------", java.nio.file.attribute.PosixFilePermissions.toString(
                        Files.getPosixFilePermissions(oldJournal)), "the journal's mode");
                Map<String, Object> robot0 = ChangeSetIT.stats(rt, "sim-robot");
                int mark = oldOut.size();
                int robotMark = robotRef.size();
                int logMark = rt.logMark();
                long t0 = System.nanoTime();
                String pin = UpdateSetIT.sha256(jar);
                CompletableFuture<String> apply = CompletableFuture.supplyAsync(() -> rt.cmd(
                        "arflex:change apply update teach file:" + jar + " " + pin + " window 300"));
                CellRig.Port np = null;
                byte[] oldBytes = Files.readAllBytes(oldJournal); // during the apply: the old half records on
                try {
                    np = rec.recordRefsWhenItAppears(rt.segment("1-teach", "joint_ref"), apply, newOut::add);
                    String out = apply.get(T, java.util.concurrent.TimeUnit.MILLISECONDS);
                    long tookMs = (System.nanoTime() - t0) / 1_000_000;
                    List<String> log = rt.logSince(logMark);
                    System.out.println("TeachUpdateIT: apply (" + tookMs + " ms):\n" + out);
                    System.out.println("TeachUpdateIT: the runtime's log of the update:\n" + String.join("\n",
                            log.stream().filter(l -> l.contains("teach")).toList()));
                    assertTrue(out.contains("update teach: committed"), out + "\n" + String.join("\n", log));
                    assertTrue(log.stream().anyMatch(l -> l.contains("1-teach") && l.contains(
                            "adopted the state block arflex.TeachState 1.0 of /arflex." + rt.rid + ".teach.state")),
                            "the new half's adoption in the log");
                    assertTrue(log.stream().anyMatch(l -> l.contains("1-teach") && l.contains("the recording read from")),
                            "the new half read the journal at the ADOPT");
                    assertTrue(np != null, "the new version's segment was never seen");
                    int after = robotRef.size();
                    rt.waitUntil("1000 references after the apply", T, () -> robotRef.size() > after + 1000);
                    assertNull(rec.error, () -> "recorder: " + rec.error);

                    List<CellRig.Ref> o = oldOut.snapshot();
                    List<CellRig.Ref> n = newOut.snapshot();
                    assertTrue(n.size() > 100, "values of the new half: " + n.size());
                    // the same motion: the new half continues the old one's seq; under the same seq
                    // the two halves wrote (nearly) the same reference
                    Map<Long, CellRig.Ref> bySeq = new java.util.HashMap<>();
                    for (CellRig.Ref r : o) {
                        bySeq.put(r.seq(), r);
                    }
                    int same = 0;
                    double sameDiff = 0;
                    for (CellRig.Ref r : n) {
                        CellRig.Ref a = bySeq.get(r.seq());
                        if (a != null) {
                            same++;
                            sameDiff = Math.max(sameDiff, CellRig.maxDiff(a.q(), r.q()));
                        }
                    }
                    // the switch: the new half's first value against the old half's value of the seq before it
                    CellRig.Ref first = n.get(0);
                    // (the newest recorded before it: the recorder polls, and the old half, kept warm, writes on,
                    // so a poll late by a millisecond misses that seq; the step is per source cycle, whatever the gap)
                    CellRig.Ref prior = newestBefore(o, first.seq());
                    assertTrue(prior != null && first.seq() - prior.seq() <= 5, "the old half's value of seq " + (first.seq() - 1)
                            + " or up to 4 before it: " + prior);
                    double firstStep = ChangeSetIT.perSourceCycle(prior, first);
                    // the arm moving at the switch: over the old half's last 20 cycles or more before the new
                    // half's first value (the newest value recorded at seq first - 21 or before: the recorder
                    // polls, and a CI run missed exactly that seq)
                    CellRig.Ref back = newestBefore(o, first.seq() - 20);
                    assertTrue(back != null, "no value of the old half 20 cycles before the switch");
                    double atSwitch = CellRig.maxDiff(back.q(), prior.q());
                    double before0 = 0;
                    for (int i = Math.max(1, mark - 1000); i < mark; i++) {
                        before0 = Math.max(before0, ChangeSetIT.perSourceCycle(o.get(i - 1), o.get(i)));
                    }
                    double[] robotSteps = CellRig.stepsBeforeAndAfter(robotRef.snapshot(), robotMark);
                    double robotBefore = robotSteps[0];
                    double robotAfter = robotSteps[1];
                    List<CellRig.Safety> ss = safety.snapshot();
                    CellRig.Safety worst = CellRig.worst(ss);
                    CellRig.Safety tripped = CellRig.tripped(ss);
                    Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
                    System.out.printf(Locale.ROOT, "TeachUpdateIT: the new half's first seq %d, %.3f mrad per source "
                            + "cycle from the old half's value of seq %d (teach's own motion before the apply: up to "
                            + "%.3f; over its last 20 cycles before the switch %.3f mrad); %d values under the same seq, largest difference %.3g rad; the robot's reference "
                            + "from the apply on %.3f mrad per source cycle (%.3f before); bound %.3f; largest force "
                            + "%.1f N; sim-robot %d safe cycles; command %d ms%n", first.seq(), firstStep * 1e3,
                            prior.seq(), before0 * 1e3, atSwitch * 1e3, same, sameDiff, robotAfter * 1e3, robotBefore * 1e3,
                            ChangeSetIT.JUMP_BOUND * 1e3, worst.forceNorm(), ChangeSetIT.delta(robot0, robot1,
                            "safeCycles"), tookMs);
                    assertTrue(before0 > 1e-6, "the arm moved under teach before the apply: " + before0);
                    assertTrue(atSwitch > 20 * 1e-6, "the arm moving at the switch: " + atSwitch
                            + " rad over the old half's last " + (prior.seq() - back.seq()) + " cycles");
                    assertTrue(firstStep <= ChangeSetIT.JUMP_BOUND, "teach's reference stepped " + firstStep
                            + " rad per source cycle at the switch");
                    assertTrue(same > 100, "values under the same seq: " + same);
                    assertTrue(sameDiff <= ChangeSetIT.JUMP_BOUND, "the two halves differ by " + sameDiff
                            + " rad under the same seq");
                    assertTrue(robotAfter <= ChangeSetIT.JUMP_BOUND, "robot reference step " + robotAfter);
                    assertNull(tripped, "the guard left NORMAL: " + tripped);
                    assertEquals(0, ChangeSetIT.delta(robot0, robot1, "safeCycles"), "sim-robot ran safe cycles");
                    assertEquals(List.of(), CellRig.awaitingReset(rt));
                    assertEquals(robotPid, rt.pid("sim-robot"));
                    assertEquals(guardPid, rt.pid("force-guard"));
                } finally {
                    if (np != null) {
                        np.close();
                    }
                }

                // the recording whole: the new half's journal begins with the old half's waypoints
                rt.awaitState("ACTIVE", T, "teach", "sim-robot", "force-guard");
                assertNotEquals(oldPid, rt.pid("teach"), "the new version runs");
                assertEquals(0, ((Number) rt.instance("teach").get("restarts")).intValue());
                assertTrue(rt.cmd("arflex:info teach").contains("1.1.1"), rt.cmd("arflex:info teach"));
                ByteBuffer now = state(rt, "1-teach");
                assertTrue(now != null, "the new half's state block");
                assertEquals(before.getLong(TS_REC_KEY), now.getLong(TS_REC_KEY), "the chain goes on under the same key");
                assertEquals(before.getLong(TS_REC_NONCE), now.getLong(TS_REC_NONCE));
                Path newJournal = journal(rt, now);
                int oldCount = ByteBuffer.wrap(oldBytes, 20, 4).order(ByteOrder.LITTLE_ENDIAN).getInt();
                rt.waitUntil("the new half's journal written", T, () -> {
                    try {
                        return Files.exists(newJournal) && Files.size(newJournal) >= HEADER + 48L * oldCount;
                    } catch (IOException e) {
                        return false;
                    }
                });
                byte[] newBytes = Files.readAllBytes(newJournal);
                int newCount = ByteBuffer.wrap(newBytes, 20, 4).order(ByteOrder.LITTLE_ENDIAN).getInt();
                System.out.printf(Locale.ROOT, "TeachUpdateIT: the old half's journal had %d waypoints when read during "
                        + "the apply (%d when the apply began); the new half's journal %d, its state block %d%n", oldCount,
                        before.getInt(TS_REC_COUNT), newCount, now.getInt(TS_REC_COUNT));
                assertTrue(oldCount >= before.getInt(TS_REC_COUNT), "the old journal kept up: " + oldCount);
                assertTrue(newCount >= oldCount, "the new half's recording has " + newCount + " < " + oldCount);
                assertArrayEquals(java.util.Arrays.copyOfRange(oldBytes, HEADER, HEADER + 48 * oldCount),
                        java.util.Arrays.copyOfRange(newBytes, HEADER, HEADER + 48 * oldCount),
                        "the first " + oldCount + " waypoints of the new half's recording are the old half's");
                rt.waitUntil("the old half, its segments and its journal gone", T, () -> Runtime.rtProcesses(rt.rid)
                        .stream().noneMatch(p -> p.contains("--instance teach ")) && !Files.exists(oldJournal));
                rec.close();
            }

            // (b) a damaged journal: the next update is refused at its preparation, nothing changes
            CellRig.set(rt, "sim-robot", "guide_force_n", "0");
            // the arm at rest: no waypoint added over 500 of teach's cycles (a journal cut short
            // stays so only while the running half appends nothing)
            long[] seen = {-1, 0};
            rt.waitUntil("the recording at rest", T, () -> {
                ByteBuffer s = state(rt, "1-teach");
                if (s == null) {
                    return false;
                }
                long c = s.getInt(TS_REC_COUNT);
                long q = s.getLong(8);
                if (c != seen[0]) {
                    seen[0] = c;
                    seen[1] = q;
                }
                return q - seen[1] > 500;
            });
            ByteBuffer st = state(rt, "1-teach");
            int count = st.getInt(TS_REC_COUNT);
            assertTrue(st.getInt(TS_TAIL_FIRST) > 10, "the recording exceeds the tail: " + count);
            Path j = journal(rt, st);
            long pid = rt.pid("teach");
            Map<String, Object> robot0 = ChangeSetIT.stats(rt, "sim-robot");
            Path jar2 = version(dir, "1.1.2");
            String pin2 = UpdateSetIT.sha256(jar2);
            try (FileChannel ch = FileChannel.open(j, StandardOpenOption.READ, StandardOpenOption.WRITE)) {
                ByteBuffer b = ByteBuffer.allocate(8).order(ByteOrder.LITTLE_ENDIAN);
                ch.read(b, HEADER + 48L * 5 + 8);
                b.flip();
                double q = b.getDouble();
                b.clear();
                b.putDouble(q + 1e-6).flip(); // one joint of waypoint 5, 1 urad: a plausible forgery
                ch.write(b, HEADER + 48L * 5 + 8);
            }
            int logMark = rt.logMark();
            String forged = rt.cmd("arflex:change apply update teach file:" + jar2 + " " + pin2 + " window 300");
            List<String> log = rt.logSince(logMark);
            System.out.println("TeachUpdateIT: a forged waypoint in the journal:\n" + forged + "\n" + String.join("\n",
                    log.stream().filter(l -> l.contains("teach")).toList()));
            assertTrue(forged.contains("preparation failed, nothing changed") && forged.contains("its state block")
                    && forged.contains("(EBADMSG: what the old half hands over does not check"), forged);
            assertTrue(log.stream().anyMatch(l -> l.contains("cannot take over the recording of ")
                    && l.contains("does not match the state block's checksum over its first")), String.join("\n", log));

            try (FileChannel ch = FileChannel.open(j, StandardOpenOption.WRITE)) {
                ch.truncate(HEADER + 48L * (count / 2));
            }
            logMark = rt.logMark();
            String cut = rt.cmd("arflex:change apply update teach file:" + jar2 + " " + pin2 + " window 300");
            log = rt.logSince(logMark);
            System.out.println("TeachUpdateIT: the journal cut short:\n" + cut + "\n" + String.join("\n",
                    log.stream().filter(l -> l.contains("teach")).toList()));
            assertTrue(cut.contains("preparation failed, nothing changed"), cut);
            assertTrue(log.stream().anyMatch(l -> l.contains("cannot take over the recording of ")
                    && l.contains("truncated or padded")), String.join("\n", log));

            // the running half untouched, the arm never stopped
            Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
            assertEquals(pid, rt.pid("teach"), "the running teach half");
            assertTrue(rt.cmd("arflex:info teach").contains("1.1.1"), rt.cmd("arflex:info teach"));
            assertEquals(0, ChangeSetIT.delta(robot0, robot1, "safeCycles"), "sim-robot ran safe cycles");
            assertEquals(List.of(), CellRig.awaitingReset(rt));
            assertTrue(CellRig.armFollows(rt, "teach"), rt.cmd("arflex:bindings"));
            assertTrue(state(rt, "1-teach").getInt(TS_REC_COUNT) >= count, "the running half's recording");
            try (Stream<String> ps = Runtime.rtProcesses(rt.rid).stream()) {
                assertTrue(ps.noneMatch(p -> p.contains("--instance 2-teach ")), "no half of a refused set");
            }
        }
    }

    /** The value with the largest seq below {@code seq}, or null. */
    static CellRig.Ref newestBefore(List<CellRig.Ref> refs, long seq) {
        CellRig.Ref best = null;
        for (CellRig.Ref r : refs) {
            if (r.seq() < seq && (best == null || r.seq() > best.seq())) {
                best = r;
            }
        }
        return best;
    }
}
