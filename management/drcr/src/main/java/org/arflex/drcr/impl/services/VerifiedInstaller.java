package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.net.URI;
import java.util.function.Consumer;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;
import org.osgi.framework.Constants;

/**
 * Installs and updates bundles from the shell through the verified path: {@code deploy <url>
 * [<sha256>]} and {@code update <bundle-id> [<url> [<sha256>]]}. Every fetch goes through
 * {@link Fetch} (https/file only, timeouts, no redirects). A jar whose SHA-256 matches the pin
 * is recorded in the {@link CodeGate}. {@code deploy} without a pin installs only a jar signed
 * entirely by a key of the trust store (docs/DECISIONS.md D14), and refuses any other with the
 * reason; the gate checks the installed bundle's signature again before its RT halves run.
 * {@code update} without a pin installs as Felix would, and the gate then decides whether its
 * RT halves may run (a trusted signature, or the file in a trusted folder it came from).
 */
public final class VerifiedInstaller {

    private final BundleContext context;
    private final CodeGate gate;
    private final Consumer<String> log;

    public VerifiedInstaller(BundleContext context, CodeGate gate, Consumer<String> log) {
        this.context = context;
        this.gate = gate;
        this.log = log;
    }

    /** Fetches, checks the pin (when given) and records a verified jar. */
    byte[] fetch(String location, String sha256) {
        byte[] jar;
        try {
            jar = Fetch.read(URI.create(location));
        } catch (IOException | IllegalArgumentException e) {
            throw new IllegalStateException("cannot read " + location + ": " + e.getMessage());
        }
        if (sha256 == null) {
            return jar;
        }
        String got = Services.sha256(jar);
        if (!got.equalsIgnoreCase(sha256)) {
            throw new IllegalStateException("not installed: SHA-256 of " + location + " is " + got + ", pinned " + sha256);
        }
        try {
            gate.verified(jar, location + ", sha256 " + got);
        } catch (IOException e) {
            throw new IllegalStateException("not installed: " + location + " is not a jar: " + e.getMessage());
        }
        return jar;
    }

    /**
     * {@code deploy <url> [<sha256>]}: install (or update the bundle of that location) and start.
     * Without a pin the jar must be signed by a key of the trust store.
     */
    public String deploy(String location, String sha256) {
        if (sha256 != null && !sha256.matches("[0-9a-fA-F]{64}")) {
            throw new IllegalArgumentException("deploy needs the jar's SHA-256 (64 hex digits) after its URL, "
                    + "or none for a jar signed by a key of the trust store");
        }
        byte[] jar = fetch(location, sha256);
        String how = "sha256 verified";
        if (sha256 == null) {
            JarSignatures.Verdict v = gate.signature(location, jar);
            if (!v.accepted()) {
                throw new IllegalStateException("not installed: " + location
                        + " has no pinned SHA-256 and is not signed by a trusted key: " + v.reason()
                        + "; give its SHA-256 (deploy <url> <sha256>) or sign it with a key of the trust store "
                        + gate.trustStore());
            }
            how = v.describe();
        }
        try {
            Bundle b = context.getBundle(location);
            if (b == null) {
                b = context.installBundle(location, new ByteArrayInputStream(jar));
            } else {
                b.update(new ByteArrayInputStream(jar));
            }
            b.start();
            log.accept("arflex: deployed bundle " + b.getBundleId() + " from " + location + " (" + how + ")");
            return "Bundle ID: " + b.getBundleId() + " (" + how + ")";
        } catch (BundleException e) {
            throw new IllegalStateException("install of " + location + " failed: " + e.getMessage());
        }
    }

    /**
     * {@code update <bundle-id> [<url> [<sha256>]]}: Felix's update, through our fetch. Without a
     * URL it reads the bundle's {@code Bundle-UpdateLocation}, else its location, as Felix does.
     */
    public String update(long id, String location, String sha256) {
        Bundle b = context.getBundle(id);
        if (b == null) {
            throw new IllegalArgumentException("no bundle " + id);
        }
        String from = location;
        if (from == null) {
            from = b.getHeaders().get(Constants.BUNDLE_UPDATELOCATION);
        }
        if (from == null) {
            from = b.getLocation();
        }
        byte[] jar = fetch(from, sha256);
        try {
            b.update(new ByteArrayInputStream(jar));
        } catch (BundleException e) {
            throw new IllegalStateException("update of bundle " + id + " failed: " + e.getMessage());
        }
        log.accept("arflex: bundle " + id + " updated from " + from + " ("
                + (sha256 != null ? "sha256 verified" : "no pinned sha256: the code gate decides whether it runs, by its signature or its folder") + ")");
        return "";
    }
}
