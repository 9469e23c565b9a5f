package org.arflex.contract;

import com.code_intelligence.jazzer.junit.FuzzTest;
import java.io.ByteArrayInputStream;
import java.io.FileDescriptor;
import java.io.FileOutputStream;
import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.Arrays;
import java.util.Base64;
import java.util.HexFormat;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.AfterAll;

/**
 * Fuzz target for everything in this module that reads untrusted XML (issue 16): the contract
 * parser ({@code parse}, {@code validate}, {@code parseAll}) and the port type reader
 * ({@code PortTypes.parse}). Run by Jazzer's JUnit integration; see contracts/README.md,
 * "Fuzzing".
 *
 * <p>Its corpus is {@code src/test/resources/org/arflex/contract/ContractFuzzTestInputs/parsers/}:
 * {@code seed-*} files (the good, bad and hostile contracts, the bundles' contracts, the shipped
 * port types) and {@code finding-*} files (inputs that once broke the oracle, each named after
 * what it broke). Every file is replayed on every run of the test, fuzzing or not.
 *
 * <p>The Surefire execution {@code fuzz} in contracts/pom.xml runs this class in fuzzing mode
 * (system property {@code JAZZER_FUZZ=true}) for {@code arflex.fuzz.seconds}, after replaying
 * the corpus. An input that breaks the oracle fails the build and is written into the corpus
 * directory as {@code crash-<sha1>}: rename it {@code finding-<what>.xml} and fix the parser.
 *
 * <p>The oracle: the parser either returns a result or refuses the document with problems that
 * each carry the source, a line and a column (both &gt; 0 and inside the document), a section,
 * a field and a message; nothing else escapes (no unchecked exception, no {@link Error}); an
 * accepted contract survives a round trip through {@link ContractWriter}; {@code validate} and
 * {@code parseAll} agree. Runaway allocation is a finding through the fork's {@code -Xmx}
 * (OutOfMemoryError). A hang is one through libFuzzer's {@code -timeout} while fuzzing, which
 * saves the input as {@code timeout-<sha1>}; the watchdog here bounds each input in both modes
 * (JUnit's own timeout would also cut the fuzzing run, one long invocation): an input still
 * running {@code arflex.fuzz.timeout} + 5 seconds after it started stops the fork, as libFuzzer
 * does, after printing the input and the stack.
 */
class ContractFuzzTest {
    private static final String SOURCE = "fuzz.xml";
    private static final ContractParser PARSER = ContractParser.create();
    private static final ContractWriter WRITER = ContractWriter.create();

    /** Per-input deadline: libFuzzer's -timeout (contracts/pom.xml) plus a margin so that it fires first. */
    private static final long DEADLINE_NS = TimeUnit.SECONDS.toNanos(Long.getLong("arflex.fuzz.timeout", 10) + 5);
    /** When the input now running started (System.nanoTime), 0 when none is. */
    private static volatile long startedAt;
    private static volatile byte[] current;
    private static volatile Thread runner;

    /** Inputs run by this JVM, and when the first and the last of them started (System.nanoTime). */
    private static long inputs;
    private static long firstNs;
    private static long lastNs;

    static {
        Thread w = new Thread(ContractFuzzTest::watch, "ContractFuzzTest-watchdog");
        w.setDaemon(true);
        w.start();
    }

    /**
     * One input goes through both readers: each stops at the root element of the other's
     * documents, so the second costs little, and one target keeps one fuzzing fork.
     */
    @FuzzTest(maxDuration = "15s")
    void parsers(byte[] data) {
        runner = Thread.currentThread();
        current = data;
        startedAt = System.nanoTime();
        lastNs = startedAt;
        if (inputs++ == 0) {
            firstNs = startedAt;
        }
        try {
            contract(data);
            portType(data);
        } finally {
            startedAt = 0;
        }
    }

    /**
     * One line on the console however the output is redirected (libFuzzer runs quiet in the
     * suite): how many inputs ran, how fast.
     */
    @AfterAll
    static void summary() {
        double s = (lastNs - firstNs) / 1e9;
        stderr(String.format(Locale.ROOT, "ContractFuzzTest: %d inputs in %.1f s (%.0f a second)%n", inputs, s,
                s > 0 ? inputs / s : 0.0));
    }

    /** Contracts: {@code parse} on the raw bytes, {@code validate} and {@code parseAll} on them as text. */
    private static void contract(byte[] data) {
        Contract c;
        try {
            c = PARSER.parse(new ByteArrayInputStream(data), SOURCE);
        } catch (ContractException e) {
            c = null;
            checkLocated(e.problems(), data, null);
        }
        if (c != null) {
            roundTrip(c);
        }
        String text = new String(data, StandardCharsets.UTF_8);
        List<Problem> problems = PARSER.validate(text, SOURCE);
        if (!problems.isEmpty()) {
            checkLocated(problems, data, text);
        }
        List<ContractParser.Result> all = PARSER.parseAll(Map.of(SOURCE, text));
        if (all.size() != 1 || all.get(0).ok() != problems.isEmpty() || !all.get(0).problems().equals(problems)) {
            throw new AssertionError("parseAll disagrees with validate: " + all + " vs " + problems);
        }
    }

    /** Port type definitions, the other XML this module reads. */
    private static void portType(byte[] data) {
        try {
            PortType t = PortTypes.parse(new ByteArrayInputStream(data), SOURCE);
            if (t.size() <= 0) {
                throw new AssertionError("accepted a port type of size " + t.size());
            }
        } catch (ContractException e) {
            checkLocated(e.problems(), data, null);
        } catch (IOException e) {
            throw new AssertionError("reading a byte array cannot fail, yet: " + e, e);
        }
    }

    private static void roundTrip(Contract c) {
        String written = WRITER.write(c);
        Contract back;
        try {
            back = PARSER.parse(written, SOURCE);
        } catch (ContractException e) {
            throw new AssertionError("the writer's output of an accepted contract is refused:\n" + written, e);
        }
        if (!c.equals(back)) {
            throw new AssertionError("round trip changed the contract; written:\n" + written);
        }
    }

    /**
     * Every problem is complete and says where it is (issue 16: every parser failure has a line
     * and a column). When the document's text is known, the place must be inside it.
     */
    private static void checkLocated(List<Problem> problems, byte[] data, String text) {
        if (problems.isEmpty()) {
            throw new AssertionError("a refusal without problems");
        }
        for (Problem p : problems) {
            if (!SOURCE.equals(p.source()) || blank(p.section()) || blank(p.field()) || blank(p.message())) {
                throw new AssertionError("incomplete problem: " + p);
            }
            boolean sizeCap = p.message().startsWith("document is larger") && data.length > ContractParser.MAX_BYTES;
            if (!sizeCap && (p.line() <= 0 || p.column() <= 0)) {
                throw new AssertionError("problem without a line and column: " + p);
            }
            // columns count characters, but bytes inside the XML declaration (Woodstox reads it
            // before it knows the encoding): the UTF-8 length bounds both
            int length = text == null ? 0 : text.getBytes(StandardCharsets.UTF_8).length;
            if (text != null && (p.line() > lineBreaks(text) + 1 || p.column() > length + 1)) {
                throw new AssertionError("problem outside the document (" + (lineBreaks(text) + 1) + " lines, "
                        + length + " bytes): " + p);
            }
        }
    }

    /** Line breaks XML 1.0 or 1.1 may count (a CR LF pair counts twice: an upper bound). */
    private static int lineBreaks(String text) {
        int n = 0;
        for (int i = 0; i < text.length(); i++) {
            char ch = text.charAt(i);
            if (ch == '\n' || ch == '\r' || ch == '\u0085' || ch == '\u2028') {
                n++;
            }
        }
        return n;
    }

    private static void watch() {
        while (true) {
            try {
                Thread.sleep(200);
            } catch (InterruptedException e) {
                return;
            }
            long t = startedAt;
            if (t != 0 && System.nanoTime() - t > DEADLINE_NS) {
                byte[] d = current;
                StringBuilder b = new StringBuilder("ContractFuzzTest: an input ran longer than "
                        + TimeUnit.NANOSECONDS.toSeconds(DEADLINE_NS) + " s; stopping the fork (a hang is a finding)\n"
                        + "  input: " + d.length + " bytes, sha1 " + sha1(d) + ", base64 "
                        + Base64.getEncoder().encodeToString(Arrays.copyOf(d, Math.min(d.length, 4096))) + "\n");
                Thread r = runner;
                if (r != null) {
                    for (StackTraceElement e : r.getStackTrace()) {
                        b.append("    at ").append(e).append('\n');
                    }
                }
                stderr(b.toString());
                Runtime.getRuntime().halt(70);
            }
        }
    }

    /**
     * Straight to file descriptor 2, to the console: Surefire sends System.err to a file here,
     * and would not flush it before a halt.
     */
    private static void stderr(String text) {
        try {
            FileOutputStream err = new FileOutputStream(FileDescriptor.err);
            err.write(text.getBytes(StandardCharsets.UTF_8));
            err.flush();
        } catch (IOException e) {
            // nothing better to do
        }
    }

    private static String sha1(byte[] d) {
        try {
            return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-1").digest(d));
        } catch (NoSuchAlgorithmException e) {
            return "?";
        }
    }

    private static boolean blank(String s) {
        return s == null || s.isBlank();
    }
}
