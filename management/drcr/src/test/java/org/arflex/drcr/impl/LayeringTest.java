package org.arflex.drcr.impl;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.DataInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeSet;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * Reads the compiled classes and fails on imports across forbidden package boundaries. Every
 * class reference in a class file (superclass, fields, descriptors, calls) is in its constant
 * pool, so scanning the pool's UTF-8 entries finds every package a class uses.
 */
class LayeringTest {

    private static final String BASE = "org/arflex/drcr/";
    private static final Pattern REF = Pattern.compile("org/arflex/drcr/((?:[a-z]+/)*)[A-Z]");

    /** Package (relative to org.arflex.drcr, "" for the API) -> packages it must not use. */
    private static final Map<String, Set<String>> FORBIDDEN = Map.of(
            "dto", Set.of("", "impl", "impl/lifecycle", "impl/supervisor", "impl/abi", "impl/extender",
                    "impl/services", "impl/shell", "impl/runtime"),
            "", Set.of("impl", "impl/lifecycle", "impl/supervisor", "impl/abi", "impl/extender",
                    "impl/services", "impl/shell", "impl/runtime"),
            "impl/abi", Set.of("impl/lifecycle", "impl/supervisor", "impl/extender", "impl/services",
                    "impl/shell", "impl/runtime", "impl"),
            "impl/lifecycle", Set.of("impl/abi", "impl/supervisor", "impl/extender", "impl/services",
                    "impl/shell", "impl/runtime", "impl"),
            "impl/supervisor", Set.of("impl/extender", "impl/services", "impl/shell", "impl/runtime", "impl"),
            "impl/shell", Set.of("impl/abi", "impl/lifecycle", "impl/supervisor", "impl/extender",
                    "impl/services", "impl/runtime", "impl"),
            "impl/extender", Set.of("impl/services", "impl/shell", "impl", "impl/supervisor", "impl/abi"),
            "impl/services", Set.of("impl/shell", "impl/extender", "impl/abi", "impl"),
            "impl/runtime", Set.of("impl/shell", "impl/extender", "impl/services", "impl"));

    @Test
    void packagesRespectTheLayering() throws IOException {
        Path classes = Path.of("target/classes/org/arflex/drcr");
        assertTrue(Files.isDirectory(classes), "compiled classes not found at " + classes.toAbsolutePath());
        List<String> violations = new ArrayList<>();
        int checked = 0;
        try (Stream<Path> files = Files.walk(classes)) {
            for (Path f : (Iterable<Path>) files.filter(p -> p.toString().endsWith(".class"))::iterator) {
                String rel = classes.relativize(f.getParent()).toString().replace('\\', '/');
                Set<String> forbidden = FORBIDDEN.get(rel);
                checked++;
                if (forbidden == null) {
                    continue;
                }
                for (String used : referencedPackages(f)) {
                    if (forbidden.contains(used)) {
                        violations.add(f.getFileName() + " in '" + rel + "' uses '" + used + "'");
                    }
                }
                if (rel.equals("dto")) {
                    for (String utf : utf8(f)) {
                        if (utf.contains("org/osgi/framework") || utf.contains("com/sun/jna")) {
                            violations.add(f.getFileName() + " in dto uses " + utf);
                        }
                    }
                }
            }
        }
        assertTrue(checked > 20, "too few classes checked: " + checked);
        assertTrue(violations.isEmpty(), String.join("\n", violations));
    }

    private static Set<String> referencedPackages(Path classFile) throws IOException {
        Set<String> out = new TreeSet<>();
        for (String s : utf8(classFile)) {
            Matcher m = REF.matcher(s);
            while (m.find()) {
                String pkg = m.group(1);
                out.add(pkg.isEmpty() ? "" : pkg.substring(0, pkg.length() - 1));
            }
        }
        return out;
    }

    /** The UTF-8 constants of a class file (JVMS 4.4). */
    static List<String> utf8(Path classFile) throws IOException {
        List<String> out = new ArrayList<>();
        try (InputStream in = Files.newInputStream(classFile); DataInputStream d = new DataInputStream(in)) {
            if (d.readInt() != 0xCAFEBABE) {
                throw new IOException("not a class file: " + classFile);
            }
            d.readUnsignedShort();
            d.readUnsignedShort();
            int count = d.readUnsignedShort();
            for (int i = 1; i < count; i++) {
                int tag = d.readUnsignedByte();
                switch (tag) {
                    case 1 -> out.add(d.readUTF());
                    case 3, 4 -> d.readInt();
                    case 5, 6 -> {
                        d.readLong();
                        i++;
                    }
                    case 7, 8, 16, 19, 20 -> d.readUnsignedShort();
                    case 9, 10, 11, 12, 17, 18 -> d.readInt();
                    case 15 -> {
                        d.readUnsignedByte();
                        d.readUnsignedShort();
                    }
                    default -> throw new IOException("bad constant tag " + tag + " in " + classFile);
                }
            }
        }
        return out;
    }
}
