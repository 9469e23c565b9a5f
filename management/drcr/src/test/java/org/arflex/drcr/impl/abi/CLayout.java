package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.TimeUnit;

/**
 * Compiles a small C program against rt-core's public headers that prints {@code key value}
 * lines (sizeof/offsetof/enum values), runs it and returns the map. The C headers are the one
 * declaration of the layout; the Java constants are checked against what the C compiler says.
 */
final class CLayout {

    private CLayout() {
    }

    static Path includeDir() {
        return Path.of("../../rt-core/include").toAbsolutePath().normalize();
    }

    static Map<String, Long> probe(String header, List<String> exprs) throws IOException, InterruptedException {
        return probe(List.of(header), exprs);
    }

    /** As {@link #probe(String, List)}, with every header of {@code headers} included. */
    static Map<String, Long> probe(List<String> headers, List<String> exprs) throws IOException, InterruptedException {
        Path inc = includeDir();
        StringBuilder c = new StringBuilder("#include <stdio.h>\n#include <stddef.h>\n");
        for (String header : headers) {
            // rt-core's headers are in this checkout: a missing one is an error, not a skip (D82)
            assertTrue(Files.isRegularFile(inc.resolve("arflex").resolve(header)), "header " + header + " not found in " + inc);
            c.append("#include \"arflex/").append(header).append("\"\n");
        }
        c.append("int main(void) {\n");
        Path dir = Files.createTempDirectory("arflex-layout");
        try {
            for (String e : exprs) {
                c.append("  printf(\"%s %lld\\n\", \"").append(e.replace("\"", "\\\"")).append("\", (long long)(")
                        .append(e).append("));\n");
            }
            c.append("  return 0;\n}\n");
            Path src = dir.resolve("probe.c");
            Files.writeString(src, c);
            Path exe = dir.resolve("probe");
            run(dir, "gcc", "-std=gnu11", "-I", inc.toString(), "-o", exe.toString(), src.toString());
            String out = run(dir, exe.toString());
            Map<String, Long> m = new HashMap<>();
            for (String line : out.split("\n")) {
                int sp = line.lastIndexOf(' ');
                if (sp > 0) {
                    m.put(line.substring(0, sp), Long.parseLong(line.substring(sp + 1).trim()));
                }
            }
            return m;
        } finally {
            try (var s = Files.walk(dir)) {
                s.sorted(java.util.Comparator.reverseOrder()).forEach(p -> p.toFile().delete());
            }
        }
    }

    private static String run(Path dir, String... cmd) throws IOException, InterruptedException {
        Process p = new ProcessBuilder(cmd).directory(dir.toFile()).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        if (!p.waitFor(60, TimeUnit.SECONDS) || p.exitValue() != 0) {
            throw new IOException(String.join(" ", cmd) + " failed:\n" + out);
        }
        return out;
    }
}
