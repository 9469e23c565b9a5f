package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermission;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Set;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * The runtime's part of the attack benchmark ({@code ./arflex bench attack}, issue 16): against
 * a runtime on this machine, every code door ({@link CodeDoors}, with the shell-blocking
 * servers), forged and flooded command queues and squatted names ({@link MailboxDoors}), and a
 * runtime started under umask 000 whose extracted executable an attacker then replaces. Prints
 * one line per attempt and {@code attack-part: runtime S/N attempts succeeded}; writes
 * target/bench/attack-runtime.json. The console's part is ConsoleAttackBench; the script sums
 * both. Not a test: run by the script only (failsafe runs *IT classes).
 */
class AttackBench {

    private final List<CodeDoors.Attempt> all = new ArrayList<>();

    private void print(List<CodeDoors.Attempt> l) {
        for (CodeDoors.Attempt a : l) {
            System.out.printf(Locale.ROOT, "attack: %-58s %s  %s%n", a.door(), a.succeeded() ? "SUCCEEDED" : "refused",
                    a.detail().length() > 200 ? a.detail().substring(0, 200) + "..." : a.detail());
        }
        all.addAll(l);
    }

    @Test
    void attack() throws Exception {
        Path work = Path.of(System.getProperty("arflex.it.work"));
        try (Runtime rt = new Runtime("attack", null, true, "bundle,cell,tools");
                CodeDoors doors = new CodeDoors(rt, work.resolve("attack-attacker"))) {
            doors.tryAll();
            doors.controls.forEach(c -> System.out.println("attack: control: " + c));
            if (!Boolean.getBoolean("arflex.bench.quick")) {
                doors.trySilentServer();
            }
            print(doors.attempts);

            MailboxDoors mb = new MailboxDoors(rt);
            Path counter = rt.dir.resolve("tools/counter.jar");
            long id = rt.installAndStart(counter);
            rt.awaitState("ACTIVE", CellIT.T, CodeDoors.COMPONENT);
            mb.tryForged();
            rt.cmd("uninstall " + id);
            rt.waitUntil(CodeDoors.COMPONENT + " gone", CellIT.T, () -> rt.instance(CodeDoors.COMPONENT) == null);
            mb.trySquat(counter);
            print(mb.attempts);
        }
        print(List.of(umask000(work)));

        long ok = all.stream().filter(CodeDoors.Attempt::succeeded).count();
        StringBuilder json = new StringBuilder("{\"part\":\"runtime\",\"attempts\":[");
        for (int k = 0; k < all.size(); k++) {
            CodeDoors.Attempt a = all.get(k);
            json.append(k == 0 ? "" : ",").append("{\"door\":\"").append(esc(a.door())).append("\",\"succeeded\":")
                    .append(a.succeeded()).append(",\"detail\":\"").append(esc(a.detail())).append("\"}");
        }
        json.append(String.format(Locale.ROOT, "],\"succeeded\":%d,\"total\":%d}%n", ok, all.size()));
        Path out = Path.of(System.getProperty("arflex.bench.out.dir", "target/bench"), "attack-runtime.json");
        Files.createDirectories(out.toAbsolutePath().getParent());
        Files.writeString(out, json);
        System.out.println("JSON: " + out.toAbsolutePath());
        System.out.printf(Locale.ROOT, "attack-part: runtime %d/%d attempts succeeded%n", ok, all.size());
        assertTrue(all.size() > 0);
    }

    /**
     * Finding 5: started under umask 000, is anything on the way to a native executable writable
     * by others, and does an executable replaced on disk run at the next restart?
     */
    private static CodeDoors.Attempt umask000(Path work) throws Exception {
        String door = "umask 000: writable cache, replaced RT executable";
        try (Runtime rt = new Runtime("attack-umask", null, true, "bundle,cell,tools", "000")) {
            Path jar = Files.copy(Path.of(System.getProperty("arflex.it.counter")),
                    Files.createDirectories(rt.dir.resolve("tools")).resolve("counter.jar"));
            long id = rt.installAndStart(jar);
            rt.awaitState("ACTIVE", CellIT.T, CodeDoors.COMPONENT);
            long pid = rt.pid(CodeDoors.COMPONENT);
            Path exe = Path.of("/proc/" + pid + "/exe").toRealPath();
            List<String> writable = new ArrayList<>();
            for (Path p = exe; p != null && p.startsWith(rt.dir); p = p.getParent()) {
                if (othersMayWrite(p)) {
                    writable.add(p.toString());
                }
            }
            try (Stream<Path> s = Files.walk(rt.dir.resolve("felix-cache"))) {
                s.filter(AttackBench::othersMayWriteQuietly).limit(5).forEach(p -> writable.add(p.toString()));
            }
            // The attacker (here with the rights to do so) replaces the executable, then the half dies.
            Path marker = work.resolve("attack-umask-pwned");
            Files.deleteIfExists(marker);
            // (a running executable cannot be written: it is replaced by a rename, as an attacker would)
            Path fake = exe.resolveSibling(exe.getFileName() + ".new");
            Files.writeString(fake, "#!/bin/sh\ntouch '" + marker + "'\nexec sleep 30\n", StandardCharsets.UTF_8);
            Files.setPosixFilePermissions(fake, Set.of(PosixFilePermission.OWNER_READ, PosixFilePermission.OWNER_WRITE,
                    PosixFilePermission.OWNER_EXECUTE));
            Files.move(fake, exe, java.nio.file.StandardCopyOption.REPLACE_EXISTING, java.nio.file.StandardCopyOption.ATOMIC_MOVE);
            FailSafeIT.kill9(pid);
            boolean back;
            try {
                rt.waitUntil("the counter restarted", CellIT.T, () -> rt.activeWithNewPid(CodeDoors.COMPONENT, pid));
                back = true;
            } catch (AssertionError e) {
                back = false;
            }
            boolean ran = Files.exists(marker);
            rt.cmd("uninstall " + id);
            rt.waitUntil(CodeDoors.COMPONENT + " gone", CellIT.T, () -> rt.instance(CodeDoors.COMPONENT) == null);
            Files.deleteIfExists(marker);
            return new CodeDoors.Attempt(door, ran || !writable.isEmpty(),
                    (writable.isEmpty() ? "nothing writable by others" : "writable by others: " + writable)
                            + (ran ? "; the replaced executable RAN" : "; the replaced executable did not run")
                            + (back ? ", the counter came back verified" : ", the counter did not come back"));
        }
    }

    private static boolean othersMayWrite(Path p) throws IOException {
        Set<PosixFilePermission> s = Files.getPosixFilePermissions(p, java.nio.file.LinkOption.NOFOLLOW_LINKS);
        return s.contains(PosixFilePermission.GROUP_WRITE) || s.contains(PosixFilePermission.OTHERS_WRITE);
    }

    private static boolean othersMayWriteQuietly(Path p) {
        try {
            return !Files.isSymbolicLink(p) && othersMayWrite(p);
        } catch (IOException e) {
            return false;
        }
    }

    static String esc(String s) {
        StringBuilder b = new StringBuilder();
        for (char c : s.toCharArray()) {
            if (c == '"' || c == '\\') {
                b.append('\\').append(c);
            } else if (c < 0x20) {
                b.append(String.format(Locale.ROOT, "\\u%04x", (int) c));
            } else {
                b.append(c);
            }
        }
        return b.toString();
    }
}
