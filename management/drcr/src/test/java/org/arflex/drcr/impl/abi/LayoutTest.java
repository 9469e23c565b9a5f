package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.fail;

import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * {@link Layout} is what rt-core's headers give now (LayoutGenerator). With
 * {@code -Darflex.layout.write=true} the test writes it instead (DECISIONS.md D22).
 */
class LayoutTest {

    /** A public numeric constant of impl.abi given by a literal, not by Layout. */
    private static final Pattern LITERAL_CONSTANT =
            Pattern.compile("public static final (?:int|long) (\\w+) = -?(?:0x)?[0-9][^;]*;");
    /** Public numeric constants of impl.abi that are no part of rt-core's layout. */
    private static final Set<String> NOT_LAYOUT = Set.of("DEFAULT_ORPHAN_HOLD_NS");

    @Test
    void generatedLayoutIsUpToDate() throws Exception {
        Map<Path, String> expected = LayoutGenerator.generate();
        boolean write = Boolean.getBoolean(LayoutGenerator.WRITE);
        List<String> differ = new ArrayList<>();
        for (Map.Entry<Path, String> e : expected.entrySet()) {
            Path p = e.getKey();
            if (Files.exists(p) && Files.readString(p, StandardCharsets.UTF_8).equals(e.getValue())) {
                continue;
            }
            if (write) {
                Files.writeString(p, e.getValue(), StandardCharsets.UTF_8);
                System.out.println("wrote " + p.toAbsolutePath().normalize());
            } else {
                differ.add(p.toString());
            }
        }
        if (!differ.isEmpty()) {
            fail("generated layout files differ from rt-core's headers: " + differ + "\nregenerate with:\n  "
                    + LayoutGenerator.COMMAND);
        }
    }

    /**
     * The Java side of the ABI declares no layout number by hand: every public numeric constant
     * of impl.abi other than Layout's comes from Layout. (A literal offset used inline, say
     * {@code getLong(256)}, is not found here; see D22.)
     */
    @Test
    void abiConstantsComeFromLayout() throws Exception {
        List<String> byHand = new ArrayList<>();
        try (Stream<Path> files = Files.list(LayoutGenerator.JAVA.getParent())) {
            for (Path f : (Iterable<Path>) files.filter(p -> p.toString().endsWith(".java"))::iterator) {
                if (f.getFileName().equals(LayoutGenerator.JAVA.getFileName())) {
                    continue;
                }
                Matcher m = LITERAL_CONSTANT.matcher(Files.readString(f, StandardCharsets.UTF_8));
                while (m.find()) {
                    if (!NOT_LAYOUT.contains(m.group(1))) {
                        byHand.add(f.getFileName() + ": " + m.group());
                    }
                }
            }
        }
        if (!byHand.isEmpty()) {
            fail("ABI numbers written by hand; take them from Layout (add the member to LayoutGenerator.SPEC):\n  "
                    + String.join("\n  ", byHand));
        }
    }
}
