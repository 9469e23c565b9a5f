package org.arflex.it;

import java.io.IOException;
import java.io.UncheckedIOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;

/**
 * The component bundles of this tree, found from {@code bundles/} itself (docs/DECISIONS.md
 * D34): a component is a folder {@code bundles/<folder>} with a {@code pom.xml}; its jar is
 * {@code bundles/<folder>/target/<artifactId>-<version>.jar}, the artifactId read from that pom.
 * No test names a jar path or a system property per bundle, so adding a component needs no
 * line in tests/pom.xml.
 *
 * <p>{@code arflex.root} (the checkout) and {@code arflex.version} (the project version) come
 * from tests/pom.xml; without them, the checkout found from the working directory and the
 * version of its root pom.
 */
public final class Components {

    private static final Pattern ARTIFACT_ID = Pattern.compile("<artifactId>([^<]+)</artifactId>");
    private static final Pattern VERSION = Pattern.compile("<version>([^<]+)</version>");

    private Components() {
    }

    /** The checkout this test runs in: {@code arflex.root}, else the first directory up from the
     *  working directory that holds {@code bundles/pom.xml} (tests/ under surefire, the checkout
     *  under {@code mvn exec:java}). */
    public static Path root() {
        String r = System.getProperty("arflex.root");
        if (r != null && !r.isBlank()) {
            return Path.of(r).toAbsolutePath().normalize();
        }
        Path start = Path.of(System.getProperty("user.dir")).toAbsolutePath().normalize();
        for (Path d = start; d != null; d = d.getParent()) {
            if (Files.isRegularFile(d.resolve("bundles/pom.xml"))) {
                return d;
            }
        }
        throw new IllegalStateException("no checkout (bundles/pom.xml) at or above " + start + "; set -Darflex.root");
    }

    /** The project version the jars carry. */
    public static String version() {
        String v = System.getProperty("arflex.version");
        if (v != null && !v.isBlank()) {
            return v;
        }
        Matcher m = VERSION.matcher(afterParent(read(root().resolve("pom.xml"))));
        if (!m.find()) {
            throw new IllegalStateException("no <version> in " + root().resolve("pom.xml"));
        }
        return m.group(1);
    }

    /** Every component folder of {@code bundles/} (one holding a pom.xml), sorted. */
    public static List<String> folders() {
        try (Stream<Path> s = Files.list(root().resolve("bundles"))) {
            return s.filter(d -> Files.isRegularFile(d.resolve("pom.xml")))
                    .map(d -> d.getFileName().toString()).sorted().toList();
        } catch (IOException e) {
            throw new UncheckedIOException(e);
        }
    }

    /** The artifactId (= bundle symbolic name) of the component in {@code bundles/<folder>}. */
    public static String artifactId(String folder) {
        Path pom = root().resolve("bundles").resolve(folder).resolve("pom.xml");
        Matcher m = ARTIFACT_ID.matcher(afterParent(read(pom)));
        if (!m.find()) {
            throw new IllegalStateException("no <artifactId> of its own in " + pom);
        }
        return m.group(1);
    }

    /** The built jar of the component in {@code bundles/<folder>}; it need not exist yet. */
    public static Path jar(String folder) {
        if (!Files.isRegularFile(root().resolve("bundles").resolve(folder).resolve("pom.xml"))) {
            throw new IllegalArgumentException("no component bundles/" + folder + " (with a pom.xml) in " + root()
                    + "; there are " + folders());
        }
        return root().resolve("bundles").resolve(folder).resolve("target")
                .resolve(artifactId(folder) + "-" + version() + ".jar");
    }

    /** The values of every {@code <tag>} in {@code xml}, in order. */
    static List<String> all(String xml, String tag) {
        List<String> out = new ArrayList<>();
        Matcher m = Pattern.compile("<" + tag + ">([^<]+)</" + tag + ">").matcher(xml);
        while (m.find()) {
            out.add(m.group(1).trim());
        }
        return out;
    }

    static String read(Path p) {
        try {
            return Files.readString(p);
        } catch (IOException e) {
            throw new UncheckedIOException(e);
        }
    }

    /** The pom without its comments and its {@code <parent>} element (whose ids are the parent's). */
    static String afterParent(String pom) {
        String s = pom.replaceAll("(?s)<!--.*?-->", "");
        int end = s.indexOf("</parent>");
        return end < 0 ? s : s.substring(end + "</parent>".length());
    }
}
