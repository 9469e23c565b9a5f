package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.fail;

import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * {@link Layout} and scripts/layout.env are what rt-core's headers give now (LayoutGenerator).
 * With {@code -Darflex.layout.write=true} the test writes them instead (DECISIONS.md D22).
 */
class LayoutTest {

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
}
