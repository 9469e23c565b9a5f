package org.arflex.planner;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * The planner is pure Java (no class but package-info refers to OSGi), and the exported API
 * never shows the engine: no public or protected signature of an API type names an impl type.
 */
class LayeringTest {

    private static final Path CLASSES = Path.of("target/classes/org/arflex/planner");

    @Test
    void noOsgi() throws IOException {
        List<String> bad = new ArrayList<>();
        try (Stream<Path> files = Files.walk(CLASSES)) {
            for (Path f : files.filter(p -> p.toString().endsWith(".class")).toList()) {
                String text = new String(Files.readAllBytes(f), StandardCharsets.ISO_8859_1);
                String name = CLASSES.relativize(f).toString();
                if (!name.equals("package-info.class") && text.contains("org/osgi/")) {
                    bad.add(name + " refers to OSGi");
                }
            }
        }
        assertEquals(List.of(), bad);
    }

    @Test
    void apiSignaturesNameNoImplType() throws Exception {
        List<Class<?>> api = new ArrayList<>();
        try (Stream<Path> files = Files.list(CLASSES)) {
            for (Path f : files.filter(p -> p.toString().endsWith(".class")).toList()) {
                String simple = f.getFileName().toString().replace(".class", "");
                if (!simple.equals("package-info")) {
                    api.add(Class.forName("org.arflex.planner." + simple));
                }
            }
        }
        assertTrue(api.contains(Planner.class), "found the API classes");
        assertEquals(List.of(), ApiSurface.leaks(api, "org.arflex.planner.impl"));
    }

    @Test
    void theCheckSeesALeak() {
        assertEquals(List.of("org.arflex.planner.LayeringTest$Leaky: method engine() returns or takes "
                + "java.util.List<org.arflex.planner.impl.Resolver>"), ApiSurface.leaks(List.of(Leaky.class),
                        "org.arflex.planner.impl"));
    }

    /** An API-shaped class that shows an engine type. */
    public static final class Leaky {
        public java.util.List<org.arflex.planner.impl.Resolver> engine() {
            return List.of();
        }

        java.util.List<org.arflex.planner.impl.Resolver> hidden() {
            return List.of();
        }
    }
}
