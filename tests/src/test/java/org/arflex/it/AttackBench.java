package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
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
            try (ShmDoors shm = new ShmDoors()) {
                shm.tryAll(rt, counter);
                print(shm.attempts);
            }
            GateDoors gate = new GateDoors(rt, work.resolve("attack-gate"));
            gate.tryAll();
            print(gate.attempts);
        }
        print(List.of(CodeDoors.umask000(work)));
        print(EnvDoors.tryAll(work)); // trusted folders' owners and modes, the halves' environment (D80)

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
