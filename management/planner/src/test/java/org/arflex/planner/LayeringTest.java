package org.arflex.planner;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/** The planner is pure Java: no class but package-info refers to OSGi, and impl never uses the API. */
class LayeringTest {

    @Test
    void noOsgiAndImplBelowApi() throws IOException {
        Path classes = Path.of("target/classes/org/arflex/planner");
        List<String> bad = new ArrayList<>();
        try (Stream<Path> files = Files.walk(classes)) {
            for (Path f : files.filter(p -> p.toString().endsWith(".class")).toList()) {
                String text = new String(Files.readAllBytes(f), StandardCharsets.ISO_8859_1);
                String name = classes.relativize(f).toString();
                if (!name.equals("package-info.class") && text.contains("org/osgi/")) {
                    bad.add(name + " refers to OSGi");
                }
                if (name.startsWith("impl/") && text.matches("(?s).*org/arflex/planner/[A-Z].*")) {
                    bad.add(name + " uses the API package");
                }
            }
        }
        assertEquals(List.of(), bad);
    }
}
