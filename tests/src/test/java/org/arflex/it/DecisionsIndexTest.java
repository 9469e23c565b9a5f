package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.TimeUnit;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * docs/DECISIONS.md is the index of the records in docs/decisions/: {@code scripts/decisions-index.py
 * --check} passes on this tree, and on a copy of it fails, naming the entry, when a record has no
 * status line or the table says something the records do not (a record missing from it, a row
 * without a record, a title changed); the script without {@code --check} then rewrites the table.
 */
class DecisionsIndexTest {

    static final Path SCRIPT = Components.root().resolve("scripts/decisions-index.py");

    record Run(int exit, String out) {
    }

    @Test
    void theIndexOfThisTreeIsCurrent() throws Exception {
        Run r = run(Components.root(), "--check");
        assertEquals(0, r.exit(), r.out());
        assertTrue(r.out().contains("the index is current"), r.out());
    }

    @Test
    void aRecordWithoutAStatusLineFailsTheCheckNamingIt(@TempDir Path dir) throws Exception {
        copyDocs(dir);
        Path d05 = record(dir, "D05");
        List<String> lines = new ArrayList<>(Files.readAllLines(d05));
        assertTrue(lines.removeIf(l -> l.startsWith("Status:")), "D05 has a Status line to remove");
        Files.write(d05, lines);

        Run r = run(dir, "--check");
        assertEquals(1, r.exit(), r.out());
        assertTrue(r.out().contains("docs/decisions/" + d05.getFileName()) && r.out().contains("no 'Status:' line"),
                r.out());
        Run write = run(dir);
        assertEquals(1, write.exit(), write.out());
        assertTrue(write.out().contains("nothing written"), write.out());
    }

    @Test
    void aStaleTableFailsTheCheckNamingEachEntryAndTheScriptRewritesIt(@TempDir Path dir) throws Exception {
        copyDocs(dir);
        Path index = dir.resolve("docs/DECISIONS.md");
        Files.writeString(dir.resolve("docs/decisions/D99-a-new-record.md"),
                "# D99: A new record\nStatus: partial (what is missing is named)\n\n**Context.** ...\n");
        Path d06 = record(dir, "D06");
        Files.writeString(d06, Files.readString(d06).replaceFirst("(?m)^# D06: .*$", "# D06: A title changed"));
        Path d02 = record(dir, "D02");
        Files.delete(d02);

        Run r = run(dir, "--check");
        assertEquals(1, r.exit(), r.out());
        assertTrue(r.out().contains("D99: missing from the index (docs/decisions/D99-a-new-record.md)"), r.out());
        assertTrue(r.out().contains("D06: mismatched") && r.out().contains("A title changed"), r.out());
        assertTrue(r.out().contains("D02: extra in the index"), r.out());
        assertEquals(3, r.out().lines().filter(l -> l.matches("  D\\d\\d: .*")).count(), r.out());

        Run write = run(dir);
        assertEquals(0, write.exit(), write.out());
        String table = Files.readString(index);
        assertTrue(table.contains(
                "| [D99](decisions/D99-a-new-record.md) | A new record | partial (what is missing is named) |"), table);
        assertTrue(table.contains("| A title changed |"), table);
        assertFalse(table.contains("[D02]"), table);
        Run again = run(dir, "--check");
        assertEquals(0, again.exit(), again.out());
        assertEquals("D100", run(dir, "--next").out().strip());
    }

    /**
     * docs/DECISIONS.md and docs/decisions/ of this tree, copied under {@code dir/docs}, the copy's
     * index rewritten so that the case starts from a current one whatever this tree's is.
     */
    static void copyDocs(Path dir) throws IOException, InterruptedException {
        Path docs = Components.root().resolve("docs");
        Files.createDirectories(dir.resolve("docs"));
        Files.copy(docs.resolve("DECISIONS.md"), dir.resolve("docs/DECISIONS.md"));
        try (Stream<Path> s = Files.walk(docs.resolve("decisions"))) {
            for (Path p : s.toList()) {
                Path to = dir.resolve("docs").resolve(docs.relativize(p).toString());
                if (Files.isDirectory(p)) {
                    Files.createDirectories(to);
                } else {
                    Files.copy(p, to);
                }
            }
        }
        Run r = run(dir);
        assertEquals(0, r.exit(), r.out());
    }

    static Path record(Path dir, String number) throws IOException {
        try (Stream<Path> s = Files.list(dir.resolve("docs/decisions"))) {
            List<Path> found = s.filter(p -> p.getFileName().toString().startsWith(number + "-")).toList();
            assertEquals(1, found.size(), "one record " + number + " in " + found);
            return found.get(0);
        }
    }

    static Run run(Path root, String... args) throws IOException, InterruptedException {
        List<String> cmd = new ArrayList<>(List.of("python3", SCRIPT.toString(), "--root", root.toString()));
        cmd.addAll(List.of(args));
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        assertTrue(p.waitFor(60, TimeUnit.SECONDS), "decisions-index.py did not end");
        return new Run(p.exitValue(), out);
    }
}
