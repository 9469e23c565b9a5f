package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.concurrent.TimeUnit;

/**
 * The doors of issue 30 findings 5 and 8 and issue 32 (D80), each tried against a real runtime:
 * <ul>
 * <li>a trusted folder others may write ({@code tools/} 0777), into which a second local user
 * copies a jar whose executable writes a marker when it runs;</li>
 * <li>a trusted folder's jar that user owns, rewritten by that user and then {@code update <id>};</li>
 * <li>the console password (and any variable of the runtime) in every half's
 * {@code /proc/<pid>/environ};</li>
 * <li>stray fault variables in the runtime's environment (a unit file's), marker included, that
 * put a shipped half into a fault mode.</li>
 * </ul>
 * The second user is created for the attempts ({@code useradd --system}) and removed after it.
 * Used by EnvIT (each attempt must fail) and AttackBench (prints them).
 */
final class EnvDoors {

    static final String COMPONENT = CodeDoors.COMPONENT;
    static final String EXE = "native/linux-x86_64/sample-counter";
    /** What the runtime's environment holds in the finding 8 / issue 32 attempt. */
    static final String PASSWORD = "it-console-password-" + ProcessHandle.current().pid();

    private EnvDoors() {
    }

    /** Every attempt, one runtime each (two share one). */
    static List<CodeDoors.Attempt> tryAll(Path work) throws Exception {
        List<CodeDoors.Attempt> l = new ArrayList<>();
        try (LocalUser u = LocalUser.create()) {
            l.add(othersWritableTrustedFolder(work, u));
            l.add(jarOwnedByAnotherUserRewritten(work, u));
        }
        l.add(consolePasswordInHalves());
        l.add(strayFaultInRuntimeEnvironment());
        return l;
    }

    /** A second local user, created now and removed at close. */
    static final class LocalUser implements AutoCloseable {
        final String name;
        final int uid;
        final int gid;

        private LocalUser(String name, int uid, int gid) {
            this.name = name;
            this.uid = uid;
            this.gid = gid;
        }

        static LocalUser create() throws IOException, InterruptedException {
            String name = "arflexit" + ProcessHandle.current().pid();
            run(List.of("userdel", name), true); // what an earlier, killed run left
            run(List.of("useradd", "--system", "--no-create-home", "--shell", "/usr/sbin/nologin", name), false);
            int uid = Integer.parseInt(run(List.of("id", "-u", name), false).trim());
            int gid = Integer.parseInt(run(List.of("id", "-g", name), false).trim());
            return new LocalUser(name, uid, gid);
        }

        /** Runs {@code cmd} as this user (setpriv: its uid, its group, no other group). */
        String as(String... cmd) throws IOException, InterruptedException {
            List<String> c = new ArrayList<>(List.of("setpriv", "--reuid=" + uid, "--regid=" + gid, "--clear-groups", "--"));
            c.addAll(List.of(cmd));
            return run(c, false);
        }

        @Override
        public void close() throws IOException, InterruptedException {
            run(List.of("userdel", name), false);
        }
    }

    static String run(List<String> cmd, boolean mayFail) throws IOException, InterruptedException {
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        if (!p.waitFor(30, TimeUnit.SECONDS)) {
            p.destroyForcibly();
            throw new IOException(cmd + " did not end within 30 s");
        }
        if (!mayFail && p.exitValue() != 0) {
            throw new IOException(cmd + " exited with " + p.exitValue() + ": " + out);
        }
        return out;
    }

    /**
     * The counter, its executable a script that writes the uid it runs as into {@code marker}
     * and then runs the real one: what another user's jar would do, as root.
     */
    static Path payload(Path dir, Path marker) throws IOException {
        Path counter = Components.jar("sample-counter");
        String file = EXE.substring(EXE.lastIndexOf('/') + 1);
        Path real = dir.resolve(file);
        Files.write(real, UpdateSetIT.entry(counter, EXE));
        Files.setPosixFilePermissions(real, PosixFilePermissions.fromString("r-xr-xr-x"));
        byte[] script = ("#!/bin/sh\nid -u > " + marker + "\nexec " + real + " \"$@\"\n").getBytes(StandardCharsets.UTF_8);
        Path jar = BundleCopies.copy(dir, counter, "payload", Map.<String, java.util.function.UnaryOperator<byte[]>>of(EXE, b -> script));
        Files.setPosixFilePermissions(jar, PosixFilePermissions.fromString("rw-r--r--"));
        return jar;
    }

    /** A fresh folder for an attempt's files, readable by the second user. */
    private static Path folder(Path work, String name) throws IOException {
        Path d = work.resolve(name);
        Runtime.deleteTree(d);
        Files.createDirectories(d);
        Files.setPosixFilePermissions(d, PosixFilePermissions.fromString("rwxr-xr-x"));
        return d;
    }

    /**
     * Starts bundle {@code id} and waits until the counter is ACTIVE or FAILED, or the code gate
     * refused the bundle (its log line since {@code mark}, taken before the install or update:
     * the gate judges a revision once, at its first resolve, which another bundle's resolve may
     * start before this start); returns null when it went ACTIVE, else the gate's refusal or the
     * failure.
     */
    private static String startAndJudge(Runtime rt, long id, int mark) {
        rt.cmd("start " + id);
        String tag = "code gate: bundle " + id + " refused";
        String[] why = new String[1];
        rt.waitUntil(COMPONENT + " ACTIVE, FAILED or bundle " + id + " refused", CellIT.T, () -> {
            Map<String, Object> i = rt.instance(COMPONENT);
            String state = i == null ? null : (String) i.get("state");
            if ("ACTIVE".equals(state)) {
                why[0] = null;
                return true;
            }
            if ("FAILED".equals(state)) {
                why[0] = "FAILED: " + i.get("failureReason");
                return true;
            }
            why[0] = rt.logSince(mark).stream().filter(l -> l.contains(tag)).map(l -> l.substring(l.indexOf(tag)))
                    .findFirst().orElse(null);
            return why[0] != null;
        });
        return why[0];
    }

    private static String ranAs(Path marker) throws IOException {
        return Files.exists(marker) ? "the payload RAN as uid " + Files.readString(marker).trim() : "the payload did not run";
    }

    /** Finding 5, first half: {@code tools/} 0777, a jar the second user copied in. */
    static CodeDoors.Attempt othersWritableTrustedFolder(Path work, LocalUser u) throws Exception {
        Path dir = folder(work, "env-doors-0777");
        Path marker = dir.resolve("pwned");
        Path jar = payload(dir, marker);
        try (Runtime rt = new Runtime("env-0777", null, true, "bundle,cell,tools")) {
            Path tools = Files.createDirectories(rt.dir.resolve("tools"));
            Files.setPosixFilePermissions(tools, PosixFilePermissions.fromString("rwxrwxrwx"));
            Path dropped = tools.resolve("dropped.jar");
            u.as("cp", jar.toString(), dropped.toString());
            int mark = rt.logMark();
            long id = rt.install(dropped);
            String problem = startAndJudge(rt, id, mark);
            String ran = ranAs(marker);
            rt.cmd("uninstall " + id);
            rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
            return new CodeDoors.Attempt("trusted folder tools/ 0777, jar copied in by another user",
                    problem == null || Files.exists(marker), (problem == null ? "ACTIVE; " : problem + "; ") + ran);
        }
    }

    /** Finding 5, second half: {@code tools/} 0755, a jar the second user owns, rewritten by it, then update. */
    static CodeDoors.Attempt jarOwnedByAnotherUserRewritten(Path work, LocalUser u) throws Exception {
        Path dir = folder(work, "env-doors-owned");
        Path marker = dir.resolve("pwned");
        Path jar = payload(dir, marker);
        try (Runtime rt = new Runtime("env-owned", null, true, "bundle,cell,tools")) {
            Path tools = Files.createDirectories(rt.dir.resolve("tools"));
            Path theirs = Files.copy(Components.jar("sample-counter"), tools.resolve("theirs.jar"));
            Files.setPosixFilePermissions(theirs, PosixFilePermissions.fromString("rw-r--r--"));
            run(List.of("chown", u.uid + ":" + u.gid, theirs.toString()), false);
            int mark = rt.logMark();
            long id = rt.install(theirs);
            String first = startAndJudge(rt, id, mark);
            // the owner rewrites it in place (tools/ is 0755: no rename), then the operator updates
            u.as("cp", jar.toString(), theirs.toString());
            int updated = rt.logMark();
            rt.cmd("update " + id);
            String second = startAndJudge(rt, id, updated);
            String ran = ranAs(marker);
            rt.cmd("uninstall " + id);
            rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
            return new CodeDoors.Attempt("trusted folder's jar owned by another user, rewritten, update <id>",
                    first == null || second == null || Files.exists(marker),
                    "before: " + (first == null ? "ACTIVE" : first) + "; after the rewrite and update: "
                            + (second == null ? "ACTIVE" : second) + "; " + ran);
        }
    }

    /**
     * Finding 8: the runtime's environment holds the console password and a variable of its own;
     * are they in a half's {@code /proc/<pid>/environ}?
     */
    static CodeDoors.Attempt consolePasswordInHalves() throws Exception {
        Map<String, String> env = Map.of("ARFLEX_CONSOLE_PASSWORD", PASSWORD, "ARFLEX_IT_CANARY", "canary");
        try (Runtime rt = Runtime.withEnvironment("env-password", env)) {
            long id = rt.installAndStart(Components.jar("sample-counter"));
            rt.awaitState("ACTIVE", CellIT.T, COMPONENT);
            List<String> leaked = new ArrayList<>();
            List<String> halves = Runtime.rtProcesses(rt.rid);
            assertEquals(false, halves.isEmpty(), "no RT half of " + rt.rid + " found: " + rt.cmd("arflex:list"));
            for (String h : halves) {
                long pid = Long.parseLong(h.substring(0, h.indexOf(':')));
                String environ = new String(Files.readAllBytes(Path.of("/proc/" + pid + "/environ")), StandardCharsets.UTF_8);
                for (String v : environ.split("\0")) {
                    String name = v.contains("=") ? v.substring(0, v.indexOf('=')) : v;
                    if (env.containsKey(name) || v.contains(PASSWORD)) {
                        leaked.add("pid " + pid + ": " + name);
                    }
                }
            }
            rt.cmd("uninstall " + id);
            rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
            return new CodeDoors.Attempt("console password and runtime variables in the halves' environ", !leaked.isEmpty(),
                    leaked.isEmpty() ? "none of " + env.keySet() + " in " + halves.size() + " half/halves" : "found: " + leaked);
        }
    }

    /**
     * Issue 32: the runtime's environment holds a START fault and the test-hook marker (a unit
     * file's stray lines), its framework no {@code arflex.test.hooks}: does the counter refuse
     * its START?
     */
    static CodeDoors.Attempt strayFaultInRuntimeEnvironment() throws Exception {
        Map<String, String> env = Map.of("ARFLEX_TEST_HOOKS", "1", "ARFLEX_FAULT_START_ERRNO", "125");
        try (Runtime rt = Runtime.withEnvironment("env-stray", env, "arflex.test.hooks=false")) {
            int mark = rt.logMark();
            long id = rt.install(Components.jar("sample-counter"));
            String problem = startAndJudge(rt, id, mark);
            rt.cmd("uninstall " + id);
            rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
            return new CodeDoors.Attempt("stray ARFLEX_TEST_HOOKS + ARFLEX_FAULT_START_ERRNO in the runtime's environment",
                    problem != null, problem == null ? "the counter started: ACTIVE" : problem);
        }
    }
}
