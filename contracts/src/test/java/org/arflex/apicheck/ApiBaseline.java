package org.arflex.apicheck;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.SortedMap;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;

/**
 * A committed record of the packages a bundle exports: each package's version and public
 * signatures ({@link ApiSignatures}), compared with the build by the module's
 * {@code ApiBaselineTest} (docs/DECISIONS.md D18). A change must raise the package version
 * above the recorded one as semantic versioning says: a removed or changed signature, or an
 * abstract method added to a type clients may implement, needs the next major version; any
 * other addition the next minor one. The file is re-recorded, only when the check passes, by
 * running the test with {@code -Darflex.api.baseline.write=true} (at a release).
 */
public final class ApiBaseline {

    /** The system property that records the file instead of checking it. */
    public static final String WRITE = "arflex.api.baseline.write";

    private ApiBaseline() {
    }

    /** One package: its version and its signature lines. */
    public record Api(String version, SortedSet<String> signatures) {
        public Api {
            signatures = Collections.unmodifiableSortedSet(new TreeSet<>(signatures));
        }
    }

    /** The bump a change needs. */
    public enum Bump {
        NONE, MINOR, MAJOR
    }

    /** Checks the build against {@code file}, or records it there when {@link #WRITE} is set. */
    public static void verify(Path classes, Path file) throws IOException, ClassNotFoundException {
        verify(classes, classes.resolve("META-INF/MANIFEST.MF"), file);
    }

    /** As {@link #verify(Path, Path)} with the manifest elsewhere. */
    public static void verify(Path classes, Path manifest, Path file) throws IOException, ClassNotFoundException {
        SortedMap<String, String> exports = Exports.of(manifest);
        SortedMap<String, Api> current = new TreeMap<>();
        for (var e : exports.entrySet()) {
            current.put(e.getKey(), new Api(e.getValue(),
                    ApiSignatures.of(classes, e.getKey(), ApiBaseline.class.getClassLoader())));
        }
        SortedMap<String, Api> recorded = Files.exists(file)
                ? parse(Files.readAllLines(file, StandardCharsets.UTF_8)) : new TreeMap<>();
        List<String> problems = problems(recorded, current);
        if (Boolean.getBoolean(WRITE) && problems.stream().allMatch(p -> p.contains(NOT_RECORDED))) {
            Files.write(file, format(current), StandardCharsets.UTF_8);
            return;
        }
        if (!problems.isEmpty()) {
            throw new AssertionError(file + ":\n  " + String.join("\n  ", problems));
        }
    }

    private static final String NOT_RECORDED = "is not recorded";

    /** What is wrong with {@code current} against {@code recorded}; empty when nothing is. */
    public static List<String> problems(SortedMap<String, Api> recorded, SortedMap<String, Api> current) {
        List<String> out = new ArrayList<>();
        for (String pkg : recorded.keySet()) {
            if (!current.containsKey(pkg)) {
                out.add(pkg + " " + recorded.get(pkg).version() + " is no longer exported (a break for every importer)");
            }
        }
        for (var e : current.entrySet()) {
            Api was = recorded.get(e.getKey());
            if (was == null) {
                out.add(e.getKey() + " " + e.getValue().version() + " " + NOT_RECORDED + " (record it with -D" + WRITE
                        + "=true)");
                continue;
            }
            String why = check(e.getKey(), was, e.getValue());
            if (why != null) {
                out.add(why);
            }
        }
        return out;
    }

    /** Null when {@code now} is versioned right against {@code was}, else why not. */
    static String check(String pkg, Api was, Api now) {
        int[] a = Versions.parse(was.version());
        int[] b = Versions.parse(now.version());
        if (Versions.compare(b, a) < 0) {
            return pkg + ": version " + now.version() + " is below the recorded " + was.version();
        }
        List<String> why = new ArrayList<>();
        Bump need = bump(was.signatures(), now.signatures(), why);
        boolean ok = switch (need) {
            case NONE -> true;
            case MINOR -> b[0] > a[0] || (b[0] == a[0] && b[1] > a[1]);
            case MAJOR -> b[0] > a[0];
        };
        if (ok) {
            return null;
        }
        String wanted = need == Bump.MAJOR ? (a[0] + 1) + ".0.0" : a[0] + "." + (a[1] + 1) + ".0";
        return pkg + ": a " + need.name().toLowerCase() + " change needs version " + wanted + " or above (recorded "
                + was.version() + ", now " + now.version() + "):\n    " + String.join("\n    ", why);
    }

    /** The bump from {@code was} to {@code now}; the lines that call for it go to {@code why}. */
    static Bump bump(SortedSet<String> was, SortedSet<String> now, List<String> why) {
        Bump need = Bump.NONE;
        for (String s : was) {
            if (!now.contains(s)) {
                why.add("removed or changed: " + s);
                need = Bump.MAJOR;
            }
        }
        for (String s : now) {
            if (was.contains(s)) {
                continue;
            }
            if (s.startsWith("M ") && s.contains(" abstract ") && consumerType(was, owner(s))) {
                why.add("abstract method added to a type clients may implement: " + s);
                need = Bump.MAJOR;
            } else {
                why.add("added: " + s);
                if (need == Bump.NONE) {
                    need = Bump.MINOR;
                }
            }
        }
        return need;
    }

    private static String owner(String memberLine) {
        return memberLine.substring(2, memberLine.indexOf(' ', 2));
    }

    private static boolean consumerType(SortedSet<String> lines, String type) {
        for (String s : lines.tailSet("T " + type + " ")) {
            if (!s.startsWith("T " + type + " ")) {
                break;
            }
            return s.contains(" " + ApiSignatures.CONSUMER);
        }
        return false; // a new type: whatever it declares is an addition
    }

    /** Parses a baseline file. */
    public static SortedMap<String, Api> parse(List<String> lines) {
        SortedMap<String, Api> out = new TreeMap<>();
        String pkg = null;
        String version = null;
        SortedSet<String> sigs = new TreeSet<>();
        for (String l : lines) {
            if (l.isBlank() || l.startsWith("#")) {
                continue;
            }
            if (l.startsWith("package ")) {
                if (pkg != null) {
                    out.put(pkg, new Api(version, sigs));
                }
                String[] f = l.trim().split(" ");
                pkg = f[1];
                version = f[2];
                sigs = new TreeSet<>();
            } else if (pkg != null && l.startsWith("  ")) {
                sigs.add(l.substring(2));
            } else {
                throw new IllegalArgumentException("baseline line not understood: " + l);
            }
        }
        if (pkg != null) {
            out.put(pkg, new Api(version, sigs));
        }
        return out;
    }

    /** The file text of a baseline. */
    public static List<String> format(SortedMap<String, Api> apis) {
        List<String> out = new ArrayList<>();
        out.add("# Exported packages of this bundle: version and public signatures (docs/DECISIONS.md D18).");
        out.add("# Checked by ApiBaselineTest; re-record at a release with -D" + WRITE + "=true.");
        for (var e : apis.entrySet()) {
            out.add("package " + e.getKey() + " " + e.getValue().version());
            for (String s : e.getValue().signatures()) {
                out.add("  " + s);
            }
        }
        return out;
    }
}
