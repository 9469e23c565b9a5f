package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.nio.file.Path;
import java.util.Map;
import java.util.jar.Manifest;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.runtime.ContractReader;
import org.arflex.drcr.impl.supervisor.VerifiedExecutables;

/**
 * The new versions of change-set updates (D38): the jar is fetched as every verified install is
 * ({@link Fetch}: https/file, timeouts, no redirects) and admitted by the same code gate as
 * {@code arflex:deploy}: its SHA-256 matches the pin given, or, without a pin, every entry is
 * signed by a key of the trust store. Its contract is read by the contract reader (the same
 * checks as a bundle's), and its executable is extracted by {@link VerifiedExecutables} (0700
 * folder, 0500 file, hashed again before every spawn). The jar is installed into Felix only once
 * the update is committed ({@link UpdatedBundles}, D43).
 */
public final class UpdateJars implements ChangeSets.Versions {

    private final VerifiedInstaller installer;
    private final CodeGate gate;
    private final ContractReader reader;
    private final VerifiedExecutables executables;
    private final Path dir;

    /** @param dir where the executables of new versions are extracted, one folder per component and jar */
    public UpdateJars(VerifiedInstaller installer, CodeGate gate, ContractReader reader, VerifiedExecutables executables,
                      Path dir) {
        this.installer = installer;
        this.gate = gate;
        this.reader = reader;
        this.executables = executables;
        this.dir = dir;
    }

    @Override
    public ChangeSets.Version read(String component, String location, String sha256) throws IOException {
        byte[] jar;
        try {
            jar = installer.fetch(location, sha256);
        } catch (IllegalStateException e) {
            throw new IOException(e.getMessage());
        }
        String how;
        if (sha256 != null) {
            how = "sha256 verified";
        } else {
            JarSignatures.Verdict v = gate.signature(location, jar);
            if (!v.accepted()) {
                throw new IOException(location + " has no pinned SHA-256 and is not signed by a trusted key: " + v.reason()
                        + "; give its SHA-256 after the URL or sign it with a key of the trust store");
            }
            how = v.describe();
        }
        // the names, and the bytes of everything but native code (an executable of tens of MB is
        // streamed from the jar only when it is extracted); every entry within the bounded reader's limits
        BoundedJar bounded = new BoundedJar(location);
        Map<String, byte[]> entries = bounded.entries(jar, n -> !n.startsWith("native/"));
        Manifest m = BoundedJar.manifest(entries);
        String header = m == null ? null : m.getMainAttributes().getValue(ContractReader.HEADER);
        if (header == null) {
            throw new IOException(location + " has no " + ContractReader.HEADER + " header");
        }
        ContractReader.Result r = reader.read(location, header, path -> {
            byte[] b = entries.get(path);
            return b == null ? null : new ByteArrayInputStream(b);
        });
        if (!r.problems().isEmpty()) {
            throw new IOException(String.join("; ", r.problems()));
        }
        Contract c = r.contracts().stream().filter(x -> x.name().equals(component)).findFirst()
                .orElseThrow(() -> new IOException(location + " carries no contract of '" + component + "' (it has "
                        + r.contracts().stream().map(Contract::name).toList() + ")"));
        String exe = ContractReader.NATIVE_DIR + c.executable();
        String digest = Services.sha256(jar);
        Path into = dir.resolve(component + "-" + digest.substring(0, 16).toLowerCase(java.util.Locale.ROOT));
        return new ChangeSets.Version(c, location, how, () -> executables.extract(into, c.executable(), () -> bounded.open(jar, exe)),
                jar);
    }
}
