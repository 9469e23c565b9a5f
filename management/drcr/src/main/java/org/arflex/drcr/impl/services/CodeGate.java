package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.net.URI;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.function.Consumer;
import org.osgi.framework.Bundle;

/**
 * One gate for code (issue 16 finding 3; docs/DECISIONS.md D12). Felix installs and updates
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
 * {@code arflex.code.trusted}), links resolved.</li>
 * </ul>
 * Anything else is refused with the bundle, its location and why. Thread-safe.
 */
public final class CodeGate {

    /** What the gate said, and why. */
    public record Decision(boolean admitted, String reason) {
    }

    private final List<Path> trusted;
    private final Map<String, String> verified = new ConcurrentHashMap<>();
    private final Consumer<String> log;

    /** @param trusted folders whose jars are trusted as they are */
    public CodeGate(List<Path> trusted, Consumer<String> log) {
        this.trusted = trusted.stream().map(CodeGate::real).toList();
        this.log = log;
    }

    /** The trusted folders, as resolved. */
    public List<Path> trusted() {
        return trusted;
    }

    /** Records a jar whose SHA-256 the verifier checked (its content digest, and from where). */
    void verified(byte[] jar, String origin) throws IOException {
        String d = ContentDigest.ofJar(jar);
        verified.put(d, origin);
        log.accept("arflex: code gate: content " + d + " verified (" + origin + ")");
    }

    /** Null when the bundle may run its RT halves, else why not (for the cell's problems). */
    public String refusal(Bundle b) {
        String digest;
        try {
            digest = ContentDigest.ofBundle(b);
        } catch (IOException | RuntimeException e) {
            digest = "(unreadable: " + e.getMessage() + ")";
        }
        Decision d = decide(b.getLocation(), digest);
        log.accept("arflex: code gate: bundle " + b.getBundleId() + " " + (d.admitted() ? "admitted: " : "refused: ")
                + d.reason());
        return d.admitted() ? null : "bundle " + b.getBundleId() + " (" + b.getSymbolicName() + ", location "
                + b.getLocation() + ") " + d.reason();
    }

    /** The decision for a bundle installed from {@code location} whose content has {@code digest}. */
    Decision decide(String location, String digest) {
        String origin = verified.get(digest);
        if (origin != null) {
            return new Decision(true, "verified: " + origin);
        }
        Path file = fileIn(location);
        String how = "; use arflex:deploy <https-url> <sha256> or arflex:update <component> (a pinned SHA-256), or "
                + "install it from a trusted folder " + trusted;
        if (file == null) {
            return new Decision(false, "not verified: installed from '" + location
                    + "', outside the verified path and the trusted folders" + how);
        }
        Path dir = trusted.stream().filter(file::startsWith).findFirst().orElse(null);
        if (dir == null) {
            return new Decision(false, "not verified: " + file + " is outside the trusted folders" + how);
        }
        String onDisk;
        try {
            onDisk = ContentDigest.ofJar(file);
        } catch (IOException e) {
            return new Decision(false, "not verified: cannot read " + file + ": " + e.getMessage() + how);
        }
        if (!onDisk.equals(digest)) {
            return new Decision(false, "not verified: its content (" + digest + ") is not that of " + file + " ("
                    + onDisk + "): it was updated from elsewhere (Bundle-UpdateLocation or update <id> <url>)" + how);
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
