package org.arflex.apicheck;

import java.io.IOException;
import java.io.InputStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.SortedMap;
import java.util.TreeMap;
import java.util.jar.Manifest;

/** The packages a bundle exports and their versions, from the manifest bnd wrote. */
final class Exports {

    private Exports() {
    }

    static SortedMap<String, String> of(Path manifest) throws IOException {
        String header;
        try (InputStream in = Files.newInputStream(manifest)) {
            header = new Manifest(in).getMainAttributes().getValue("Export-Package");
        }
        return parse(header);
    }

    /** {@code a;version="1.0.0";uses:="b,c",d;version="0.1.0"} -> {a=1.0.0, d=0.1.0}. */
    static SortedMap<String, String> parse(String header) {
        SortedMap<String, String> out = new TreeMap<>();
        if (header == null || header.isBlank()) {
            return out;
        }
        for (String clause : split(header, ',')) {
            List<String> parts = split(clause, ';');
            String version = "0.0.0";
            for (String p : parts.subList(1, parts.size())) {
                String t = p.trim();
                if (t.startsWith("version=")) {
                    version = t.substring("version=".length()).replace("\"", "");
                }
            }
            out.put(parts.get(0).trim(), version);
        }
        return out;
    }

    /** Splits at {@code sep} outside double quotes. */
    private static List<String> split(String s, char sep) {
        List<String> out = new ArrayList<>();
        StringBuilder cur = new StringBuilder();
        boolean quoted = false;
        for (char c : s.toCharArray()) {
            if (c == '"') {
                quoted = !quoted;
            }
            if (c == sep && !quoted) {
                out.add(cur.toString());
                cur.setLength(0);
            } else {
                cur.append(c);
            }
        }
        out.add(cur.toString());
        return out;
    }
}
