package org.arflex.webconsole.impl;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.InputStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.jar.JarEntry;
import java.util.jar.JarInputStream;
import java.util.jar.JarOutputStream;
import java.util.jar.Manifest;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.arflex.contract.ContractParser;
import org.arflex.contract.Problem;

/**
 * The debug-monitor bundle as the console installs it: the shipped jar (contract + RT
 * executable, bundles/debug-monitor) with its contract's ports rewritten to watch the state
 * ports the engineer chose, one monitor slot {@code m<k>} per target, each with
 * {@code m<k>_last}, {@code _min}, {@code _max} and {@code _mean}. Everything else in the jar
 * (executable, manifest, timing, fault policy) is copied unchanged, and the generated contract
 * is checked with the DRCR's own validator before anything is staged.
 */
final class DebugMonitor {
    /** Framework or system property naming the jar. */
    static final String JAR_PROPERTY = "arflex.console.debugmonitor";
    /** Where the runtime assembly ships it, relative to the runtime's working directory. */
    static final String DEFAULT_DIR = "tools";
    static final String COMPONENT = "debug-monitor";
    static final String SYMBOLIC_NAME = "org.arflex.debug.monitor";
    /** Slots the RT half has (m0..m3). */
    static final int MAX_SLOTS = 4;
    private static final Pattern PORTS = Pattern.compile("(?s)<ports>.*?</ports>");
    private static final Pattern DESCRIPTION = Pattern.compile("(?s)<description>.*?</description>");
    private static final Pattern PORT = Pattern.compile("[a-z0-9_]{1,31}");
    private static final long MAX_JAR = 64L << 20;

    /** One watched port. */
    record Target(String component, String port) {
        @Override
        public String toString() {
            return component + "." + port;
        }
    }

    private DebugMonitor() {
    }

    /**
     * The jar: the property when set, else the newest {@code org.arflex.debug.monitor*.jar} in
     * {@code tools/} of the working directory (the runtime directory; scripts/run-cell.sh
     * starts Felix there).
     *
     * @throws HttpError 404 saying where it was looked for
     */
    static Path locate(String configured) throws HttpError, IOException {
        if (configured != null && !configured.isBlank()) {
            Path p = Path.of(configured).toAbsolutePath();
            if (!Files.isRegularFile(p)) {
                throw new HttpError(404, JAR_PROPERTY + "=" + configured + ": no such file");
            }
            return p;
        }
        Path dir = Path.of(System.getProperty("user.dir"), DEFAULT_DIR).toAbsolutePath();
        if (Files.isDirectory(dir)) {
            try (Stream<Path> s = Files.list(dir)) {
                List<Path> jars = s.filter(p -> p.getFileName().toString().startsWith(SYMBOLIC_NAME)
                        && p.getFileName().toString().endsWith(".jar")).sorted().toList();
                if (!jars.isEmpty()) {
                    return jars.get(jars.size() - 1);
                }
            }
        }
        throw new HttpError(404, "the debug-monitor bundle was not found: no " + SYMBOLIC_NAME + "*.jar in " + dir
                + " and the property " + JAR_PROPERTY + " is not set");
    }

    /** Parses {@code comp.port,comp.port} (1 to 4 targets). */
    static List<Target> targets(String text) throws HttpError {
        if (text == null || text.isBlank()) {
            throw new HttpError(400, "targets: choose at least one port to watch");
        }
        String[] parts = text.split(",");
        if (parts.length > MAX_SLOTS) {
            throw new HttpError(400, "targets: at most " + MAX_SLOTS + " ports (the monitor has slots m0..m3), got "
                    + parts.length);
        }
        List<Target> out = new java.util.ArrayList<>();
        for (String part : parts) {
            String t = part.trim();
            int dot = t.lastIndexOf('.');
            if (dot <= 0) {
                throw new HttpError(400, "targets: '" + t + "' is not component.port");
            }
            String c = t.substring(0, dot);
            String p = t.substring(dot + 1);
            Names.checkName(c);
            if (!PORT.matcher(p).matches()) {
                throw new HttpError(400, "targets: '" + p + "' is not a port name ([a-z0-9_]{1,31})");
            }
            Target tg = new Target(c, p);
            if (out.contains(tg)) {
                throw new HttpError(400, "targets: " + tg + " chosen twice");
            }
            out.add(tg);
        }
        return out;
    }

    /** The shipped contract with ports (and description) for {@code targets}. */
    static String contract(String shipped, List<Target> targets) throws HttpError {
        Matcher m = PORTS.matcher(shipped);
        if (!m.find()) {
            throw new HttpError(500, "the debug-monitor contract has no <ports> element");
        }
        StringBuilder ports = new StringBuilder("<ports>\n");
        for (int k = 0; k < targets.size(); k++) {
            Target t = targets.get(k);
            // Names are checked against [A-Za-z0-9._-] and [a-z0-9_]: nothing to escape.
            ports.append("    <in name=\"m").append(k).append("\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\" optional=\"true\">\n")
                    .append("      <bind component=\"").append(t.component()).append("\" port=\"").append(t.port()).append("\"/>\n")
                    .append("    </in>\n");
        }
        for (int k = 0; k < targets.size(); k++) {
            for (String s : new String[] {"last", "min", "max", "mean"}) {
                ports.append("    <out name=\"m").append(k).append('_').append(s)
                        .append("\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>\n");
            }
        }
        ports.append("  </ports>");
        String xml = shipped.substring(0, m.start()) + ports + shipped.substring(m.end());
        return DESCRIPTION.matcher(xml).replaceFirst(Matcher.quoteReplacement("<description>Remote debugging, installed"
                + " from the web console: watches " + String.join(", ", targets.stream().map(Target::toString).toList())
                + " read-only and republishes each as m&lt;k&gt;_last with min, max and mean over windows of `window`"
                + " values.</description>"));
    }

    /**
     * The jar to install: every entry of {@code shipped} copied, the contract named by the
     * manifest's ARFLEX-Contract header replaced by the one for {@code targets}.
     */
    static byte[] build(Path shipped, List<Target> targets, ContractParser parser) throws HttpError, IOException {
        if (Files.size(shipped) > MAX_JAR) {
            throw new HttpError(413, shipped + ": larger than 64 MiB");
        }
        ByteArrayOutputStream out = new ByteArrayOutputStream();
        try (JarInputStream in = new JarInputStream(Files.newInputStream(shipped))) {
            Manifest mf = in.getManifest();
            String bsn = mf == null ? null : mf.getMainAttributes().getValue("Bundle-SymbolicName");
            String contractPath = mf == null ? null : mf.getMainAttributes().getValue("ARFLEX-Contract");
            if (bsn == null || !bsn.split(";")[0].trim().equals(SYMBOLIC_NAME) || contractPath == null) {
                throw new HttpError(500, shipped + " is not the debug-monitor bundle (Bundle-SymbolicName " + bsn
                        + ", ARFLEX-Contract " + contractPath + ")");
            }
            contractPath = contractPath.split(",")[0].trim();
            boolean replaced = false;
            try (JarOutputStream jar = new JarOutputStream(out, mf)) {
                for (JarEntry e; (e = in.getNextJarEntry()) != null;) {
                    byte[] data = readBounded(in);
                    if (e.getName().equals(contractPath)) {
                        String xml = contract(new String(data, StandardCharsets.UTF_8), targets);
                        List<Problem> problems = parser.validate(xml, "debug-monitor (generated)");
                        if (!problems.isEmpty()) {
                            throw new HttpError(400, "the generated debug-monitor contract is not valid: "
                                    + problems.stream().map(Problem::toString).toList());
                        }
                        data = xml.getBytes(StandardCharsets.UTF_8);
                        replaced = true;
                    }
                    JarEntry copy = new JarEntry(e.getName());
                    copy.setTime(e.getTime());
                    jar.putNextEntry(copy);
                    jar.write(data);
                    jar.closeEntry();
                }
            }
            if (!replaced) {
                throw new HttpError(500, shipped + ": no entry " + contractPath + " (its ARFLEX-Contract)");
            }
        }
        return out.toByteArray();
    }

    private static byte[] readBounded(InputStream in) throws IOException, HttpError {
        byte[] b = in.readNBytes((int) MAX_JAR + 1);
        if (b.length > MAX_JAR) {
            throw new HttpError(413, "an entry of the debug-monitor jar is larger than 64 MiB");
        }
        return b;
    }
}
