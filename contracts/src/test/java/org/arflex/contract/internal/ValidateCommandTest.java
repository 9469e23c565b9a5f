package org.arflex.contract.internal;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayOutputStream;
import java.io.PrintStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** {@code arflex validate FILE...} (D84): exit status and what it says, on good and bad contracts. */
class ValidateCommandTest {

    /** The contract `./arflex new component` generates, named "probe". */
    static final Path TEMPLATE = Path.of("../rt-core/template/component/src/main/resources/OSGI-INF/arflex/NAME.xml");

    @TempDir
    Path dir;

    final ByteArrayOutputStream out = new ByteArrayOutputStream();
    final ByteArrayOutputStream err = new ByteArrayOutputStream();

    int validate(String... args) {
        return ValidateCommand.run(List.of(args), new PrintStream(out, true, StandardCharsets.UTF_8),
                new PrintStream(err, true, StandardCharsets.UTF_8));
    }

    Path contract(String file, String from, String to) throws Exception {
        String xml = Files.readString(TEMPLATE).replace("@NAME@", "probe");
        assertTrue(from.isEmpty() || xml.contains(from), from);
        Path f = dir.resolve(file);
        Files.writeString(f, from.isEmpty() ? xml : xml.replace(from, to));
        return f;
    }

    @Test
    void aGoodContractPassesWithExitZero() throws Exception {
        Path f = contract("good.xml", "", "");
        assertEquals(0, validate(f.toString()), err.toString());
        assertEquals(f + ": ok (component probe)\n", out.toString());
        assertEquals("", err.toString());
    }

    @Test
    void aRuleBrokenIsNamedWithFileLineAndElement() throws Exception {
        // line 17: a deadline longer than the period
        Path f = contract("late.xml", "deadline=\"10ms\"", "deadline=\"20ms\"");
        assertEquals(1, validate(f.toString()));
        String e = err.toString();
        assertTrue(e.startsWith(f + ":17:"), e);
        assertTrue(e.contains("timing") && e.contains("deadline"), e);
        assertEquals("", out.toString());
    }

    @Test
    void anUnknownPortTypeIsNamedOnItsLine() throws Exception {
        Path f = contract("type.xml", "<out name=\"out\" type=\"arflex.Sample\"", "<out name=\"out\" type=\"arflex.NoSuchType\"");
        assertEquals(1, validate(f.toString()));
        String e = err.toString();
        assertTrue(e.startsWith(f + ":12:") && e.contains("arflex.NoSuchType"), e);
    }

    @Test
    void brokenXmlIsNamedWithItsLine() throws Exception {
        Path f = contract("broken.xml", "</ports>", "</port>");
        assertEquals(1, validate(f.toString()));
        assertTrue(err.toString().startsWith(f + ":13:"), err.toString());
    }

    @Test
    void everyFileIsCheckedAndOneBadOneFailsTheRun() throws Exception {
        Path good = contract("good.xml", "", "");
        Path bad = contract("late.xml", "deadline=\"10ms\"", "deadline=\"20ms\"");
        assertEquals(1, validate(bad.toString(), good.toString(), dir.resolve("missing.xml").toString()));
        assertTrue(out.toString().contains(good + ": ok"), out.toString());
        assertTrue(err.toString().contains(bad + ":17:"), err.toString());
        assertTrue(err.toString().contains(dir.resolve("missing.xml") + ":0:0: (document): no such file"), err.toString());
    }

    @Test
    void noFileOrAnOptionIsAUsageError() {
        assertEquals(2, validate());
        assertEquals(2, validate("--strict"));
        assertTrue(err.toString().contains("usage: arflex validate"), err.toString());
    }
}
