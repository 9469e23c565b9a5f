package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * Issue #19's "deployment sets from an update URL" (docs/DECISIONS.md D45) through the real
 * runtime, on the moving arm (FailSafeIT's looping program; trajectory -> tcp-correction ->
 * sim-robot, the guard): one descriptor names the gripper, a new component, and tcp-correction
 * 1.0.1, an update of the running one, each jar pinned by its SHA-256, the jars beside the
 * descriptor (relative URLs). {@code arflex:deploy set <url> [plan]}.
 *
 * <p>Asserted: a set with one jar whose pin is wrong is refused whole, naming that jar and both
 * hashes, and a set whose update changes the method of the output sim-robot reads is refused
 * naming the component, the port, the peer and both formats; after either nothing is installed
 * (no bundle, the gripper unknown to the cell, no process, no shm segment or queue of it or of a
 * second tcp-correction half) and the cell runs as before. A set whose new gripper's executable
 * exits before READY is torn down by the change set after the gripper's bundle was installed for
 * it: that bundle is uninstalled again, and nothing is left either. The good set's dry run installs
 * nothing; applied, the gripper runs with trajectory's tool input bound to it and tcp-correction
 * runs 1.0.1 (committed after its window), in one change set. Throughout: the guard never leaves
 * NORMAL, sim-robot runs no safe cycle, nothing waits for a reset or a fresh command, sim-robot,
 * the guard and trajectory keep their pids.
 *
 * <p>D50: a gripper signed by an unknown key is refused naming the jar; a set whose faulty update
 * is rejected in its shadow run leaves no bundle; a set whose faulty update is rolled back after
 * its switch is taken back whole (its gripper, signed by a trusted key, uninstalled from the cell
 * and from Felix, the guard's limit it wrote written back); a set of changes only uninstalls the
 * gripper and writes the guard's limit, a value out of range refused naming its line.
 */
class DeploymentSetIT {

    static final long T = CellRig.T;

    /** The set's folder: the gripper's jar, tcp-correction 1.0.1 and a variant, and descriptors. */
    private static Path folder(Runtime rt) throws IOException {
        Path dir = Files.createDirectories(rt.dir.resolve("sets"));
        Files.copy(CellRig.GRIPPER, dir.resolve("tool-gripper.jar"));
        UpdateSetIT.version(dir, "1.0.1", null);
        // 1.0.2: its output 'corrected' becomes a stream, while sim-robot reads a state
        Jars.withContract(UpdateSetIT.version(dir, "1.0.2", null), dir.resolve("tcp-correction-1.0.2-stream.jar"),
                xml -> {
                    String s = xml.replace("<out name=\"corrected\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"state\"/>",
                            "<out name=\"corrected\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"stream\" depth=\"8\"/>");
                    assertFalse(s.equals(xml), "tcp-correction's contract declares 'corrected' as expected");
                    return s;
                });
        // a gripper whose executable exits at once: its half never gets READY, the set is torn down
        try (java.util.zip.ZipFile in = new java.util.zip.ZipFile(CellRig.GRIPPER.toFile());
                java.util.zip.ZipOutputStream zo = new java.util.zip.ZipOutputStream(
                        Files.newOutputStream(dir.resolve("tool-gripper-broken.jar")))) {
            boolean found = false;
            for (java.util.zip.ZipEntry e : java.util.Collections.list(in.entries())) {
                byte[] b = in.getInputStream(e).readAllBytes();
                if (e.getName().equals("native/linux-x86_64/tool-gripper")) {
                    b = "#!/bin/sh\n# DeploymentSetIT's broken gripper: exits before READY\nexit 3\n"
                            .getBytes(java.nio.charset.StandardCharsets.UTF_8);
                    found = true;
                }
                zo.putNextEntry(new java.util.zip.ZipEntry(e.getName()));
                zo.write(b);
                zo.closeEntry();
            }
            assertTrue(found, "the gripper's executable in " + CellRig.GRIPPER);
        }
        return dir;
    }

    private static Path descriptor(Path dir, String name, String gripperPin, String update, String updatePin)
            throws IOException {
        return Files.writeString(dir.resolve(name + ".xml"), "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                + "<deployment xmlns=\"urn:arflex:deployment:1\" name=\"" + name + "\">\n"
                + "  <install jar=\"tool-gripper.jar\" sha256=\"" + gripperPin + "\"/>\n"
                + "  <update component=\"tcp-correction\" jar=\"" + update + "\" sha256=\"" + updatePin + "\" window=\"300\"/>\n"
                + "</deployment>\n");
    }

    /**
     * A copy of {@code jar} signed by a new EC key (CN {@code cn}) with the JDK's jarsigner; when
     * {@code trusted}, the key's certificate is put into the runtime's trust store ({@code trust}
     * of its working directory, D14), readable by all, writable by the owner only.
     */
    static Path signed(Runtime rt, Path jar, String name, String cn, boolean trusted) throws Exception {
        Path keys = Files.createDirectories(rt.dir.resolve("keys"));
        Path ks = keys.resolve(name + ".p12");
        jdk("keytool", "-genkeypair", "-alias", "k", "-keyalg", "EC", "-groupname", "secp256r1", "-validity", "30",
                "-dname", "CN=" + cn, "-keystore", ks.toString(), "-storetype", "PKCS12", "-storepass", "changeit-test");
        Path out = Files.copy(jar, jar.resolveSibling(name + ".jar"));
        jdk("jarsigner", "-keystore", ks.toString(), "-storetype", "PKCS12", "-storepass", "changeit-test",
                "-digestalg", "SHA-256", out.toString(), "k");
        if (trusted) {
            Path trust = Files.createDirectories(rt.dir.resolve("trust"));
            Files.setPosixFilePermissions(trust, java.nio.file.attribute.PosixFilePermissions.fromString("rwxr-xr-x"));
            Path crt = trust.resolve(name + ".crt");
            jdk("keytool", "-exportcert", "-rfc", "-alias", "k", "-keystore", ks.toString(), "-storetype", "PKCS12",
                    "-storepass", "changeit-test", "-file", crt.toString());
            Files.setPosixFilePermissions(crt, java.nio.file.attribute.PosixFilePermissions.fromString("rw-r--r--"));
        }
        return out;
    }

    private static void jdk(String tool, String... args) throws Exception {
        List<String> cmd = new ArrayList<>(List.of(Path.of(System.getProperty("java.home"), "bin", tool).toString()));
        cmd.addAll(List.of(args));
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), java.nio.charset.StandardCharsets.UTF_8);
        assertEquals(0, p.waitFor(), () -> tool + " failed: " + out);
    }

    /** A jar named in a descriptor, as the DRCR resolves it (URI.resolve: {@code file:/...}). */
    static String at(Path descriptor, String jar) {
        return descriptor.toUri().resolve(jar).toString();
    }

    /** shm segments and message queues of this runtime whose instance is {@code inst}. */
    static List<String> objects(Runtime rt, String inst) throws IOException {
        List<String> out = new ArrayList<>();
        for (String d : new String[] {"/dev/shm", "/dev/mqueue"}) {
            if (!Files.isDirectory(Path.of(d))) {
                continue;
            }
            try (Stream<Path> s = Files.list(Path.of(d))) {
                s.map(p -> p.getFileName().toString()).filter(n -> n.startsWith("arflex." + rt.rid + "." + inst + "."))
                        .forEach(n -> out.add(d + "/" + n));
            }
        }
        return out;
    }

    /**
     * Nothing of the set is in Felix, the cell, the process table or /dev/shm and /dev/mqueue
     * (a torn-down half's exit and its objects' removal are waited for, with a deadline).
     */
    private static void nothingInstalled(Runtime rt, long tcpPid) throws IOException {
        String lb = rt.cmd("lb -l");
        String sets = rt.dir.resolve("sets") + "/";
        assertTrue(lb.lines().noneMatch(l -> l.contains(sets)), "no bundle of the set's folder " + sets + ":\n" + lb);
        assertNull(rt.instance("tool-gripper"), "the gripper is unknown to the cell");
        rt.waitUntil("no process, segment or queue of the set's halves", T, () -> Runtime.rtProcesses(rt.rid).stream()
                .noneMatch(p -> p.contains("--instance tool-gripper ") || p.contains("--instance 1-tcp-correction "))
                && objects(rt, "tool-gripper").isEmpty() && objects(rt, "1-tcp-correction").isEmpty());
        assertEquals(tcpPid, rt.pid("tcp-correction"), "the running tcp-correction untouched");
        assertTrue(rt.cmd("arflex:info tcp-correction").startsWith("tcp-correction 1.1.0 "), rt.cmd("arflex:info tcp-correction"));
    }

    /** The arm's record over a span: the guard's modes, sim-robot's stats before and after. */
    private static final class Watch implements AutoCloseable {
        final CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
        final CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
        final CellRig.Port jp;
        final CellRig.Port sp;
        final CellRig.Recorder rec = new CellRig.Recorder();
        final Map<String, Object> robot0;
        final long robotPid;
        final long guardPid;
        final long trajPid;
        final Runtime rt;

        Watch(Runtime rt) throws Exception {
            this.rt = rt;
            jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
            sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
            rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
            rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
            rec.start();
            rt.waitUntil("the arm moving", T, () -> FailSafeIT.moving(js) && js.size() > 500);
            assertTrue(CellRig.awaitingReset(rt).isEmpty(), "before: " + CellRig.awaitingReset(rt));
            robot0 = ChangeSetIT.stats(rt, "sim-robot");
            robotPid = rt.pid("sim-robot");
            guardPid = rt.pid("force-guard");
            trajPid = rt.pid("trajectory");
        }

        /** The arm kept moving unharmed: no safe cycle, the guard NORMAL, no reset, the same halves. */
        void unharmed(String what) throws Exception {
            int n = js.size();
            rt.waitUntil("1000 more states of the arm", T, () -> js.size() > n + 1000);
            assertNull(rec.error, () -> "recorder: " + rec.error);
            Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
            long safe = ChangeSetIT.delta(robot0, robot1, "safeCycles");
            double force = safety.snapshot().stream().mapToDouble(CellRig.Safety::forceNorm).max().orElseThrow();
            System.out.printf(Locale.ROOT, "DeploymentSetIT: %s: sim-robot %d cycles, %d overruns, %d safe cycles; "
                    + "largest force %.1f N%n", what, ChangeSetIT.delta(robot0, robot1, "cycles"),
                    ChangeSetIT.delta(robot0, robot1, "overruns"), safe, force);
            assertEquals(0, safe, what + ": sim-robot ran safe cycles");
            assertNull(safety.snapshot().stream().filter(s -> s.mode() != CellRig.Safety.NORMAL).findFirst().orElse(null),
                    what + ": the guard left NORMAL");
            // the looping program passes its waypoints at rest: the arm moves again soon after any instant
            rt.waitUntil(what + ": the arm moves", 5_000, () -> FailSafeIT.moving(js));
            assertEquals(List.of(), CellRig.awaitingReset(rt));
            assertEquals(List.of(), CellRig.awaitingCommand(rt));
            assertNull(FailSafeIT.holding(rt, "sim-robot"));
            assertEquals(robotPid, rt.pid("sim-robot"));
            assertEquals(guardPid, rt.pid("force-guard"));
            assertEquals(trajPid, rt.pid("trajectory"));
        }

        @Override
        public void close() throws Exception {
            rec.close();
            jp.close();
            sp.close();
        }
    }

    @Test
    void aSetWithABadPinOrAnIncompatiblePortFormatIsRefusedWholeOnTheMovingArm() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION,
                CellRig.GRIPPER);
        try (Runtime rt = new Runtime("deploy-refused")) {
            FailSafeIT.movingCell(rt);
            Path dir = folder(rt);
            String gripperPin = Jars.sha256(dir.resolve("tool-gripper.jar"));
            String goodPin = Jars.sha256(dir.resolve("tcp-correction-1.0.1.jar"));
            String wrongPin = Jars.sha256(dir.resolve("tcp-correction-1.0.2.jar"));
            long tcpPid = rt.pid("tcp-correction");
            try (Watch w = new Watch(rt)) {
                // (2) the gripper's pin is another jar's: the whole set is refused, naming that jar
                Path bad = descriptor(dir, "bad-pin", wrongPin, "tcp-correction-1.0.1.jar", goodPin);
                String out = rt.cmd("arflex:deploy set " + bad.toUri());
                System.out.println("DeploymentSetIT: a wrong pin:\n" + out);
                assertTrue(out.startsWith("error: "), out);
                assertTrue(out.contains("REFUSED jar " + at(bad, "tool-gripper.jar") + " (line 3, install): "
                        + "not installed: SHA-256 of " + at(bad, "tool-gripper.jar") + " is " + gripperPin
                        + ", pinned " + wrongPin), out);
                assertTrue(out.contains("update tcp-correction -> 1.0.1 from " + at(bad, "tcp-correction-1.0.1.jar")
                        + " (sha256 verified)"), "the other jar passed the gate: " + out);
                assertTrue(out.strip().endsWith("; nothing installed"), out);
                String dry = rt.cmd("arflex:deploy set " + bad.toUri() + " plan");
                assertTrue(dry.startsWith("error: ") && dry.contains("REFUSED jar "), dry);
                nothingInstalled(rt, tcpPid);

                // signed="true", but by a key the trust store does not hold: refused, naming the jar and why
                Path stranger = signed(rt, dir.resolve("tool-gripper.jar"), "tool-gripper-stranger", "Somebody else", false);
                Path unknown = Files.writeString(dir.resolve("unknown-key.xml"), Files.readString(bad).replace(
                        "tool-gripper.jar\" sha256=\"" + wrongPin + "\"", stranger.getFileName() + "\" signed=\"true\""));
                out = rt.cmd("arflex:deploy set " + unknown.toUri());
                System.out.println("DeploymentSetIT: a jar signed by an unknown key:\n" + out);
                assertTrue(out.startsWith("error: ") && out.contains("REFUSED jar " + at(unknown, stranger.getFileName().toString())
                        + " (line 3, install): not signed by a trusted key: "), out);
                nothingInstalled(rt, tcpPid);

                // (3) tcp-correction 1.0.2 writes 'corrected' as a stream, sim-robot reads a state
                Path incompatible = descriptor(dir, "stream", gripperPin, "tcp-correction-1.0.2-stream.jar",
                        Jars.sha256(dir.resolve("tcp-correction-1.0.2-stream.jar")));
                int mark = rt.logMark();
                out = rt.cmd("arflex:deploy set " + incompatible.toUri());
                System.out.println("DeploymentSetIT: an incompatible port format:\n" + out);
                assertTrue(out.startsWith("error: "), out);
                assertTrue(out.contains("refused: port formats: update tcp-correction 1.0.2: output 'corrected' changes to "
                        + "arflex.JointRef 1.0 stream, but its peer sim-robot.joint_ref (running) reads arflex.JointRef 1.0 "
                        + "state (method stream is not state); nothing installed"), out);
                assertTrue(rt.logSince(mark).stream().noneMatch(l -> l.contains("1-tcp-correction") || l.contains("installed from")
                        || l.contains("tool-gripper ACTIVE") || l.contains("contracts read")),
                        "nothing spawned or installed:\n" + String.join("\n", rt.logSince(mark)));
                nothingInstalled(rt, tcpPid);

                // a set the change set tears down after the gripper's bundle was installed for it:
                // the bundle is uninstalled again, the prepared tcp-correction half stopped
                Path broken = Files.writeString(dir.resolve("broken.xml"), Files.readString(bad)
                        .replace("tool-gripper.jar\" sha256=\"" + wrongPin, "tool-gripper-broken.jar\" sha256=\""
                                + Jars.sha256(dir.resolve("tool-gripper-broken.jar"))));
                out = rt.cmd("arflex:deploy set " + broken.toUri());
                System.out.println("DeploymentSetIT: a set torn down:\n" + out);
                assertTrue(out.startsWith("error: "), out);
                assertTrue(out.contains("\nuninstalled again: bundle "), out);
                assertTrue(out.contains("tool-gripper"), out);
                nothingInstalled(rt, tcpPid);

                // D50: rejected in its shadow run (D42): the faulty version crashes while it shadows the
                // running one; nothing was switched, and the gripper's bundle installed for the set goes again
                Path faulty = UpdateSetIT.version(dir, "1.0.2-faulty", FaultyVersions.crashingAfterCycles(dir,
                        CellRig.TCP_CORRECTION, UpdateSetIT.EXE, 50, "DeploymentSetIT"));
                Path shadowed = Files.writeString(dir.resolve("shadowed.xml"), "<deployment xmlns=\"urn:arflex:deployment:1\">\n"
                        + "  <install jar=\"tool-gripper.jar\" sha256=\"" + gripperPin + "\"/>\n"
                        + "  <update component=\"tcp-correction\" jar=\"" + faulty.getFileName() + "\" sha256=\""
                        + Jars.sha256(faulty) + "\" shadow=\"5000\" window=\"300\"/>\n</deployment>\n");
                out = rt.cmd("arflex:deploy set " + shadowed.toUri());
                System.out.println("DeploymentSetIT: a set rejected in shadow:\n" + out);
                assertTrue(out.startsWith("error: ") && out.contains("update tcp-correction: rejected in shadow after "), out);
                assertTrue(out.contains("\nuninstalled again: bundle ") && out.contains(at(shadowed, "tool-gripper.jar")), out);
                nothingInstalled(rt, tcpPid);
                w.unharmed("after five refused sets");
            }
        }
    }

    @Test
    void aNewComponentAndAnUpdateAreDeployedAsOneSetOnTheMovingArm() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION,
                CellRig.GRIPPER);
        try (Runtime rt = new Runtime("deploy-set")) {
            FailSafeIT.movingCell(rt);
            Path dir = folder(rt);
            Path set = descriptor(dir, "gripper-and-correction", Jars.sha256(dir.resolve("tool-gripper.jar")),
                    "tcp-correction-1.0.1.jar", Jars.sha256(dir.resolve("tcp-correction-1.0.1.jar")));
            long tcpPid = rt.pid("tcp-correction");
            String dry = rt.cmd("arflex:deploy set " + set.toUri() + " plan");
            System.out.println("DeploymentSetIT: dry run:\n" + dry);
            assertTrue(dry.contains("admitted (dry run: nothing installed, nothing changed)"), dry);
            assertTrue(dry.contains("install tool-gripper 1.0.0 from " + at(set, "tool-gripper.jar")
                    + " (sha256 verified)") && dry.contains("update tcp-correction -> 1.0.1 from "), dry);
            assertTrue(dry.contains("START    tool-gripper") && dry.contains("RESTART  tcp-correction")
                    && dry.contains("REBIND   trajectory"), dry);
            nothingInstalled(rt, tcpPid);

            try (Watch w = new Watch(rt)) {
                long t0 = System.nanoTime();
                String out = rt.cmd("arflex:deploy set " + set.toUri());
                System.out.printf(Locale.ROOT, "DeploymentSetIT: apply (%.0f ms):%n%s%n", (System.nanoTime() - t0) / 1e6, out);
                assertFalse(out.startsWith("error: "), out);
                assertTrue(out.contains("\napplied: "), out);
                assertTrue(out.contains("update tcp-correction: committed"), out);
                rt.awaitState("ACTIVE", T, "tool-gripper", "tcp-correction", "trajectory", "sim-robot", "force-guard");
                w.unharmed("the set applied");
            }
            String b = rt.cmd("arflex:bindings");
            assertTrue(b.contains("trajectory.tool <- tool-gripper.tool") && b.contains("tool-gripper.safety <- force-guard.safety")
                    && b.contains("sim-robot.joint_ref <- tcp-correction.corrected"), b);
            assertTrue(rt.cmd("arflex:info tcp-correction").startsWith("tcp-correction 1.0.1 "), rt.cmd("arflex:info tcp-correction"));
            String lb = rt.cmd("lb -l");
            String gripperAt = dir.resolve("tool-gripper.jar").toString();
            assertTrue(lb.lines().anyMatch(l -> l.contains("|Active") && l.contains(gripperAt)), lb);
            assertTrue(CellRig.armFollows(rt, "trajectory"), b);
            rt.waitUntil("the old tcp-correction half's process gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance tcp-correction ")));
            // the same set again: the gripper is in the cell now, so it is refused and changes nothing
            String again = rt.cmd("arflex:deploy set " + set.toUri());
            assertTrue(again.startsWith("error: ") && again.contains("already installed as bundle"), again);
            rt.awaitState("ACTIVE", T, "tool-gripper", "tcp-correction");

            // D50: a set of changes only, the gripper uninstalled and the guard's limit written; first
            // with a value out of range: refused naming its line, nothing changed
            String head = "<deployment xmlns=\"urn:arflex:deployment:1\" name=\"changes\">\n"
                    + "  <uninstall component=\"tool-gripper\"/>\n";
            Path outOfRange = Files.writeString(dir.resolve("changes-bad.xml"), head
                    + "  <set component=\"force-guard\" parameter=\"force_limit_n\" value=\"0.5\"/>\n</deployment>\n");
            String refused = rt.cmd("arflex:deploy set " + outOfRange.toUri());
            assertTrue(refused.startsWith("error: ") && refused.contains("refused: line 3, set force-guard force_limit_n 0.5: "
                    + "force-guard.force_limit_n: 0.5 is out of range [1.0, 10000.0] N; nothing installed"), refused);
            rt.awaitState("ACTIVE", T, "tool-gripper");
            long trajPid = rt.pid("trajectory");
            Path changes = Files.writeString(dir.resolve("changes.xml"), head
                    + "  <set component=\"force-guard\" parameter=\"force_limit_n\" value=\"145\"/>\n</deployment>\n");
            String applied = rt.cmd("arflex:deploy set " + changes.toUri());
            System.out.println("DeploymentSetIT: a set of changes only:\n" + applied);
            assertFalse(applied.startsWith("error: "), applied);
            assertTrue(applied.contains("STOP     tool-gripper") && applied.contains("REBIND   trajectory"), applied);
            rt.awaitState("INSTALLED", T, "tool-gripper");
            assertTrue(rt.cmd("arflex:get force-guard force_limit_n").strip().startsWith("145"),
                    rt.cmd("arflex:get force-guard force_limit_n"));
            assertFalse(rt.cmd("arflex:bindings").contains("tool-gripper"), rt.cmd("arflex:bindings"));
            assertEquals(trajPid, rt.pid("trajectory"));
            rt.awaitState("ACTIVE", T, "tcp-correction", "trajectory", "sim-robot", "force-guard");
        }
    }

    /**
     * D50: a set whose update is rolled back after its switch (the faulty 1.0.2, killed by SIGSEGV
     * in its 500th update after its START, the switch's; window 5000 cycles) is taken back whole: the gripper it installed
     * is uninstalled from the cell and from Felix, the guard's limit it wrote is written back, and
     * the arm runs as before, tcp-correction 1.0.0 with the pid it had.
     */
    @Test
    void aSetWhoseUpdateIsRolledBackAfterItsSwitchIsTakenBackOnTheMovingArm() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION,
                CellRig.GRIPPER);
        try (Runtime rt = new Runtime("deploy-rollback")) {
            FailSafeIT.movingCell(rt);
            Path dir = folder(rt);
            // killed in its 500th update after the switch (D68), within the window
            Path faulty = UpdateSetIT.version(dir, "1.0.2-faulty", FaultyVersions.crashingAfterCycles(dir, CellRig.TCP_CORRECTION,
                    UpdateSetIT.EXE, 500, "DeploymentSetIT"));
            Path gripper = signed(rt, dir.resolve("tool-gripper.jar"), "tool-gripper-signed", "DeploymentSetIT integrator", true);
            String limit = rt.cmd("arflex:get force-guard force_limit_n").strip();
            Path set = Files.writeString(dir.resolve("rolled-back.xml"), "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                    + "<deployment xmlns=\"urn:arflex:deployment:1\" name=\"rolled-back\">\n"
                    + "  <install jar=\"" + gripper.getFileName() + "\" signed=\"true\"/>\n"
                    + "  <update component=\"tcp-correction\" jar=\"" + faulty.getFileName() + "\" sha256=\""
                    + Jars.sha256(faulty) + "\" window=\"5000\" shadow=\"0\"/>\n"
                    + "  <set component=\"force-guard\" parameter=\"force_limit_n\" value=\"140\"/>\n"
                    + "</deployment>\n");
            long tcpPid = rt.pid("tcp-correction");
            try (Watch w = new Watch(rt)) {
                String out = rt.cmd("arflex:deploy set " + set.toUri());
                System.out.println("DeploymentSetIT: a set rolled back after its switch:\n" + out);
                assertTrue(out.startsWith("error: "), out);
                assertTrue(out.contains("install tool-gripper 1.0.0 from " + at(set, gripper.getFileName().toString())
                        + " (signed by CN=DeploymentSetIT integrator, sha256 "), "admitted by its signature: " + out);
                assertTrue(out.contains("\napplied: "), "the set was switched: " + out);
                assertTrue(out.contains("update tcp-correction: rolled back after ") && out.contains("killed by signal 11"), out);
                assertTrue(out.contains("taking the set back (update tcp-correction rolled back after the switch): "
                        + "uninstall tool-gripper; set force-guard force_limit_n " + limit + "\n"), out);
                assertTrue(out.contains("\nuninstalled again: bundle ") && out.contains(at(set, gripper.getFileName().toString())),
                        out);
                assertTrue(out.strip().endsWith("refused: update tcp-correction rolled back after the switch; the set was "
                        + "taken back"), out);
                assertEquals(limit, rt.cmd("arflex:get force-guard force_limit_n").strip(), "the guard's limit written back");
                nothingInstalled(rt, tcpPid);
                String b = rt.cmd("arflex:bindings");
                assertTrue(b.contains("sim-robot.joint_ref <- tcp-correction.corrected") && !b.contains("tool-gripper"), b);
                w.unharmed("a set taken back");
            }
        }
    }
}
