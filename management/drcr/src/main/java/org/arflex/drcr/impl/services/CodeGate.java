package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.net.URI;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.KeyStore;
import java.util.List;
import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.function.Consumer;
import java.util.function.Supplier;
import org.osgi.framework.Bundle;

/**
 * One gate for code (issue 16 finding 3; docs/DECISIONS.md D12, D14). Felix installs and updates
 * bundles through paths we do not own ({@code install http://...}, {@code update <id>} from
 * {@code Bundle-UpdateLocation}, {@code felix:update <id> <url>}), and OSGi has no hook that
 * can veto an install. So the DRCR decides at the one place native code is made to run: it
 * admits a contract bundle (extracts and spawns its RT half) only when its content is
 * <ul>
 * <li>a jar the verifier checked against a pinned SHA-256 ({@code arflex:update},
 * {@code arflex:deploy}, {@code update <id> <url> <sha256>}, the console's Deploy page through
 * {@code UpdateService.verified}), recorded here by its
 * {@link ContentDigest}; or</li>
 * <li>exactly the file at its {@code file:} location, inside a trusted folder (the runtime's
 * {@code bundle/}, {@code cell/} and {@code tools/} by default; framework property
 * {@code arflex.code.trusted}), links resolved; or</li>
 * <li>signed, every entry, by a key whose certificate is in the {@link TrustStore} (framework
 * property {@code arflex.code.truststore}), checked by {@link JarSignatures} on the installed
 * bundle's own entries.</li>
 * </ul>
 * Anything else is refused with the bundle, its location and why. Thread-safe.
 */
public final class CodeGate {

    /** What the gate said, and why. */
    public record Decision(boolean admitted, String reason) {
    }

    private final List<Path> trusted;
    private final TrustStore store;
    private final Map<String, String> verified = new ConcurrentHashMap<>();
    private final Consumer<String> log;

    /** A gate that trusts no signature. @param trusted folders whose jars are trusted as they are */
    public CodeGate(List<Path> trusted, Consumer<String> log) {
        this(trusted, null, log);
    }

    /**
     * @param trusted folders whose jars are trusted as they are
     * @param trustStore the folder of trusted signing certificates; null: no signature is trusted
     */
    public CodeGate(List<Path> trusted, Path trustStore, Consumer<String> log) {
        this.trusted = trusted.stream().map(CodeGate::real).toList();
        this.store = new TrustStore(trustStore);
        this.log = log;
    }

    /** The trusted folders, as resolved. */
    public List<Path> trusted() {
        return trusted;
    }

    /** The trust store folder, or null when none is configured. */
    public Path trustStore() {
        return store.folder();
    }

    /** Records a jar whose SHA-256 the verifier checked (its content digest, and from where). */
    void verified(byte[] jar, String origin) throws IOException {
        String d = ContentDigest.of(ContentDigest.entries(origin, jar));
        verified.put(d, origin);
        log.accept("arflex: code gate: content " + d + " verified (" + origin + ")");
    }

    /** Whether a jar is signed entirely by a key of the trust store as it is now. */
    JarSignatures.Verdict signature(byte[] jar) {
        return signature("the jar", jar);
    }

    /** As {@link #signature(byte[])}, the jar named {@code name} (its location) when it is refused. */
    JarSignatures.Verdict signature(String name, byte[] jar) {
        try {
            return signature(ContentDigest.entries(name, jar));
        } catch (BoundedJar.Refused e) {
            return JarSignatures.Verdict.refused("refused: " + e.getMessage());
        } catch (IOException e) {
            return JarSignatures.Verdict.refused("unreadable jar: " + e.getMessage());
        }
    }

    /** Whether a jar's entries are signed entirely by a key of the trust store as it is now. */
    JarSignatures.Verdict signature(Map<String, byte[]> entries) {
        KeyStore ks = null;
        String problem = null;
        try {
            ks = store.load();
        } catch (IOException e) {
            problem = e.getMessage();
        }
        JarSignatures.Verdict v = JarSignatures.check(entries, ks);
        return v.accepted() || problem == null ? v : JarSignatures.Verdict.refused(v.reason() + " (" + problem + ")");
    }

    /** Null when the bundle may run its RT halves, else why not (for the cell's problems); logged. */
    public String refusal(Bundle b) {
        Decision d = judge(b);
        log.accept("arflex: code gate: bundle " + b.getBundleId() + " " + (d.admitted() ? "admitted: " : "refused: ")
                + d.reason());
        return d.admitted() ? null : "bundle " + b.getBundleId() + " (" + b.getSymbolicName() + ", location "
                + b.getLocation() + ") " + d.reason();
    }

    private Decision judge(Bundle b) {
        Map<String, byte[]> entries = null;
        String digest;
        try {
            entries = ContentDigest.entries(b);
            digest = ContentDigest.of(entries);
        } catch (BoundedJar.Refused e) {
            return new Decision(false, e.getMessage()); // a verdict: the same each time it is read
        } catch (IOException | RuntimeException e) {
            digest = "(unreadable: " + e.getMessage() + ")";
        }
        Map<String, byte[]> content = entries;
        String unreadable = digest; // "(unreadable: why)": CodeGateHook keeps no verdict that says so
        return decide(b.getLocation(), digest, () -> content == null
                ? JarSignatures.Verdict.refused("its content is " + unreadable) : signature(content));
    }

    /** The decision for a bundle installed from {@code location} whose content has {@code digest}, unsigned. */
    Decision decide(String location, String digest) {
        return decide(location, digest, () -> JarSignatures.Verdict.refused("unsigned"));
    }

    /**
     * The decision for a bundle installed from {@code location} whose content has {@code digest};
     * {@code signature} checks its signature, asked only when nothing else admits it.
     */
    Decision decide(String location, String digest, Supplier<JarSignatures.Verdict> signature) {
        String origin = verified.get(digest);
        if (origin != null) {
            return new Decision(true, "verified: " + origin);
        }
        Decision local = fromTrustedFolder(location, digest);
        if (local.admitted()) {
            return local;
        }
        JarSignatures.Verdict v = signature.get();
        if (v.accepted()) {
            return new Decision(true, v.describe() + " (trust store " + store.folder() + ")");
        }
        return new Decision(false, local.reason() + "; not signed by a trusted key: " + v.reason()
                + "; use arflex:deploy <https-url> <sha256> or arflex:update <component> (a pinned SHA-256), "
                + "sign it with a key of the trust store, or install it from a trusted folder " + trusted);
    }

    /** Admitted when the location is a file in a trusted folder whose content is still {@code digest}. */
    private Decision fromTrustedFolder(String location, String digest) {
        Path file = fileIn(location);
        if (file == null) {
            return new Decision(false, "not verified: installed from '" + location
                    + "', outside the verified path and the trusted folders");
        }
        Path dir = trusted.stream().filter(file::startsWith).findFirst().orElse(null);
        if (dir == null) {
            return new Decision(false, "not verified: " + file + " is outside the trusted folders");
        }
        String door = TrustedFolders.refusal(dir, file); // issue 30 finding 5 (D80)
        if (door != null) {
            return new Decision(false, "not trusted: " + door + "; chmod go-w and chown it to the runtime's user or root");
        }
        String onDisk;
        try {
            onDisk = ContentDigest.ofJar(file);
        } catch (IOException e) {
            return new Decision(false, "not verified: cannot read " + file + ": " + e.getMessage());
        }
        if (!onDisk.equals(digest)) {
            return new Decision(false, "not verified: its content (" + digest + ") is not that of " + file + " ("
                    + onDisk + "): it was updated from elsewhere (Bundle-UpdateLocation or update <id> <url>)");
        }
        return new Decision(true, "from the trusted folder " + dir);
    }

    /** The real path of a {@code file:} location, or null for any other location. */
    private static Path fileIn(String location) {
        try {
            URI u = URI.create(location);
            if (!"file".equalsIgnoreCase(u.getScheme()) || u.getPath() == null) {
                return null;
            }
            Path p = Path.of(u);
            return Files.exists(p) ? p.toRealPath() : null;
        } catch (IllegalArgumentException | IOException | java.nio.file.FileSystemNotFoundException e) {
            return null;
        }
    }

    private static Path real(Path p) {
        try {
            return p.toRealPath();
        } catch (IOException e) {
            return p.toAbsolutePath().normalize();
        }
    }
}
