package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.lang.reflect.Proxy;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;
import org.osgi.framework.Bundle;
import org.osgi.framework.hooks.resolver.ResolverHook;
import org.osgi.framework.wiring.BundleRevision;

/**
 * Issue 16: an unverified bundle's Java code does not run either: the gate keeps its revision
 * from resolving. A verified one (pinned, trusted folder, trusted signature) resolves.
 */
class CodeGateHookTest {

    private final List<String> log = new ArrayList<>();

    private static BundleRevision revision(Bundle b) {
        return (BundleRevision) Proxy.newProxyInstance(BundleRevision.class.getClassLoader(),
                new Class<?>[] {BundleRevision.class}, (proxy, m, args) -> switch (m.getName()) {
                    case "getBundle" -> b;
                    case "hashCode" -> System.identityHashCode(proxy);
                    case "equals" -> proxy == args[0];
                    default -> throw new UnsupportedOperationException(m.getName());
                });
    }

    @Test
    void anUnverifiedBundleDoesNotResolveAVerifiedOneDoes(@TempDir Path dir) throws Exception {
        Path cell = Files.createDirectories(dir.resolve("cell"));
        CodeGate gate = new CodeGate(List.of(cell), null, log::add);
        CodeGateHook hook = new CodeGateHook(gate);
        byte[] jar = CodeGateTest.jar("good", false);
        Path trusted = Files.write(cell.resolve("good.jar"), jar);
        BundleRevision fromCell = revision(SignedCodeGateTest.installed(trusted.toUri().toString(), jar));
        BundleRevision fromWeb = revision(SignedCodeGateTest.installed("http://evil.example/x.jar",
                CodeGateTest.jar("evil", false)));
        List<BundleRevision> candidates = new ArrayList<>(List.of(fromCell, fromWeb));
        ResolverHook h = hook.begin(List.of());
        h.filterResolvable(candidates);
        h.end();
        assertEquals(List.of(fromCell), candidates, String.join("\n", log));
        assertNotNull(hook.refusal(fromWeb));
        assertTrue(hook.refusal(fromWeb).contains("not verified: installed from 'http://evil.example/x.jar'"),
                hook.refusal(fromWeb));
        assertNull(hook.refusal(fromCell));
        // judged once per revision: one log line each, however often the resolver asks
        long lines = log.stream().filter(l -> l.contains("code gate: bundle")).count();
        hook.begin(List.of()).filterResolvable(new ArrayList<>(List.of(fromCell, fromWeb)));
        assertEquals(lines, log.stream().filter(l -> l.contains("code gate: bundle")).count());
    }

    /**
     * A bundle judged while its install is still under way cannot be read yet: that verdict is
     * not kept for its revision (the resolve that follows judges the readable content). It was
     * kept: the refusal's text did not carry the marker the hook looks for, and a verified
     * bundle stayed unresolvable ("Resolver hook prevented resolution").
     */
    @Test
    void aVerdictOnContentNotYetReadableIsNotKept(@TempDir Path dir) throws Exception {
        Path cell = Files.createDirectories(dir.resolve("cell"));
        CodeGate gate = new CodeGate(List.of(cell), null, log::add);
        CodeGateHook hook = new CodeGateHook(gate);
        byte[] jar = CodeGateTest.jar("good", false);
        gate.verified(jar, "a console upload, sha256 pinned"); // installed from outside the trusted folders
        Bundle readable = SignedCodeGateTest.installed(dir.resolve("felix-cache/upload.jar").toUri().toString(), jar);
        int[] reads = {0};
        Bundle settling = (Bundle) Proxy.newProxyInstance(Bundle.class.getClassLoader(), new Class<?>[] {Bundle.class},
                (proxy, m, args) -> {
                    if (m.getName().equals("getEntryPaths") && reads[0]++ == 0) {
                        throw new IllegalStateException("No bundle associated with resource");
                    }
                    return m.invoke(readable, args);
                });
        BundleRevision r = revision(settling);
        assertNull(hook.refusal(r), String.join("\n", log));
        assertTrue(log.stream().anyMatch(l -> l.contains("refused") && l.contains("(unreadable: No bundle associated")),
                "the first verdict names why it refused: " + log);
    }
}
