package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.BufferedReader;
import java.io.IOException;
import java.io.InputStreamReader;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.CopyOnWriteArrayList;
import java.util.concurrent.TimeUnit;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * A runtime without the demonstration cell (issue 31, D84): {@code ./arflex run --empty
 * --headless N} is {@code scripts/run-cell.sh <runtime> N} with {@code ARFLEX_CELL_GOSH=/dev/null}
 * after the build. The DRCR comes up, no component is installed ({@code arflex:list} answers
 * "no components", no cell summary), and the job stops after N seconds leaving no process, shared
 * object, queue or temporary file behind.
 */
class EmptyRunIT {

    static final Path ROOT = Components.root();

    @Test
    void theFrontScriptKnowsEmpty() throws Exception {
        // an unknown option after --empty is refused before anything is built or started
        Process p = new ProcessBuilder("bash", ROOT.resolve("arflex").toString(), "run", "--empty", "--no-such-option")
                .redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        assertTrue(p.waitFor(30, TimeUnit.SECONDS), "./arflex run did not end");
        assertEquals(2, p.exitValue(), out);
        assertTrue(out.contains("arflex run: unknown option '--no-such-option'"), out);
    }

    @Test
    void theRuntimeComesUpWithTheDrcrAndNoCellAndStopsLeavingNothing(@TempDir Path tmp) throws Exception {
        HeadlessRun run = HeadlessRun.copy("empty-assembly");
        Path copy = run.assembly();
        int seconds = 8;
        ProcessBuilder pb = run.command(seconds, tmp.resolve("home"));
        pb.environment().put("ARFLEX_CELL_GOSH", "/dev/null"); // what ./arflex run --empty sets
        List<String> out = new CopyOnWriteArrayList<>();
        Process p = pb.start();
        Thread reader = new Thread(() -> {
            try (BufferedReader r = new BufferedReader(new InputStreamReader(p.getInputStream(), StandardCharsets.UTF_8))) {
                for (String l; (l = r.readLine()) != null; ) {
                    out.add(l);
                }
            } catch (IOException ignored) {
                // the pipe closes when the job ends
            }
        }, "empty-run-output");
        reader.start();
        long pid = p.pid();
        List<ProcessHandle> tree;
        try {
            assertTrue(p.waitFor(seconds + 120, TimeUnit.SECONDS), "the headless job did not stop after " + seconds + " s");
            reader.join(10_000);
        } finally {
            tree = p.descendants().toList();
            if (p.isAlive()) {
                p.descendants().forEach(ProcessHandle::destroyForcibly);
                p.destroyForcibly();
                p.waitFor(30, TimeUnit.SECONDS);
            }
        }
        String text = String.join("\n", out);
        assertEquals(0, p.exitValue(), "exit status of job " + pid + ":\n" + text);
        assertTrue(out.stream().anyMatch(l -> l.contains("no cell (--empty)")), text);
        Matcher rm = Pattern.compile("DRCR started, runtime id ([a-z0-9-]+)").matcher(text);
        assertTrue(rm.find(), "the DRCR did not start:\n" + text);
        String rid = rm.group(1);
        // every arflex:list (the first, and one per 5 s) answers that there is no component
        long lists = out.stream().filter(l -> l.matches("(g! )*no components")).count();
        assertTrue(lists >= 2, "arflex:list did not answer 'no components' twice:\n" + text);
        assertTrue(out.stream().noneMatch(l -> l.matches(".*\\bNAME\\s+STATE\\s+PID.*")), "a component is listed:\n" + text);
        assertTrue(out.stream().noneMatch(l -> l.contains("arflex cell: ") || l.contains("installing the cell")), text);
        assertTrue(out.stream().noneMatch(l -> l.matches("(g! )*error: .*")), "a command failed:\n" + text);

        assertEquals(List.of(), tree.stream().filter(ProcessHandle::isAlive).toList(), "processes of the job left");
        String prefix = "arflex." + rid + ".";
        for (String dir : new String[] {"/dev/shm", "/dev/mqueue"}) {
            Path d = Path.of(dir);
            if (Files.isDirectory(d)) {
                try (var l = Files.list(d)) {
                    assertEquals(List.of(), l.map(x -> x.getFileName().toString()).filter(n -> n.startsWith(prefix)).toList(),
                            "left in " + dir);
                }
            }
        }
        try (var l = Files.list(tmp.resolve("home"))) {
            assertEquals(List.of("console.properties"), l.map(x -> x.getFileName().toString()).sorted().toList());
        }
        Runtime.deleteTree(copy);
    }
}
