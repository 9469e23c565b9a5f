package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayInputStream;
import java.io.OutputStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.jar.Attributes;
import java.util.jar.JarEntry;
import java.util.jar.JarInputStream;
import java.util.jar.JarOutputStream;
import java.util.jar.Manifest;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortSpec;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The debug-monitor bundle the console builds: the shipped contract rewritten for the chosen ports. */
class DebugMonitorTest {
    private static final Path SHIPPED_CONTRACT =
            Path.of("../bundles/debug-monitor/src/main/resources/OSGI-INF/arflex/debug-monitor.xml");
    private final ContractParser parser = ContractParser.create();

    private static Path shippedJar(Path dir, byte[] exe) throws Exception {
        Manifest mf = new Manifest();
        mf.getMainAttributes().put(Attributes.Name.MANIFEST_VERSION, "1.0");
        mf.getMainAttributes().putValue("Bundle-SymbolicName", "org.arflex.debug.monitor");
        mf.getMainAttributes().putValue("ARFLEX-Contract", "OSGI-INF/arflex/debug-monitor.xml");
        Path jar = dir.resolve("org.arflex.debug.monitor.jar");
        try (OutputStream o = Files.newOutputStream(jar); JarOutputStream j = new JarOutputStream(o, mf)) {
            j.putNextEntry(new JarEntry("native/linux-x86_64/debug-monitor"));
            j.write(exe);
            j.putNextEntry(new JarEntry("OSGI-INF/arflex/debug-monitor.xml"));
            j.write(Files.readAllBytes(SHIPPED_CONTRACT));
        }
        return jar;
    }

    @Test
    void theGeneratedBundleWatchesTheChosenPortsAndKeepsEverythingElse(@TempDir Path dir) throws Exception {
        byte[] exe = "\u007fELF-not-really".getBytes(StandardCharsets.ISO_8859_1);
        Path jar = shippedJar(dir, exe);
        List<DebugMonitor.Target> t = DebugMonitor.targets("sim-robot.speed, sample-counter.count,x-y.v_2");
        byte[] built = DebugMonitor.build(jar, t, parser);
        Map<String, byte[]> entries = new HashMap<>();
        Manifest mf;
        try (JarInputStream in = new JarInputStream(new ByteArrayInputStream(built))) {
            mf = in.getManifest();
            for (JarEntry e; (e = in.getNextJarEntry()) != null;) {
                entries.put(e.getName(), in.readAllBytes());
            }
        }
        assertEquals("org.arflex.debug.monitor", mf.getMainAttributes().getValue("Bundle-SymbolicName"));
        assertArrayEquals(exe, entries.get("native/linux-x86_64/debug-monitor"), "executable copied unchanged");
        Contract c = parser.parse(new String(entries.get("OSGI-INF/arflex/debug-monitor.xml"), StandardCharsets.UTF_8), "gen");
        assertEquals("debug-monitor", c.name());
        assertEquals(List.of("m0", "m1", "m2"), c.inputs().stream().map(PortSpec::name).toList());
        assertEquals(12, c.outputs().size());
        assertTrue(c.inputs().stream().allMatch(PortSpec::optional));
        assertEquals("sim-robot", c.inputs().get(0).binding().orElseThrow().component().orElseThrow());
        assertEquals("speed", c.inputs().get(0).binding().orElseThrow().port().orElseThrow());
        assertEquals("v_2", c.inputs().get(2).binding().orElseThrow().port().orElseThrow());
        assertEquals(20_000_000L, c.timing().periodNs(), "timing kept from the shipped contract");
    }

    @Test
    void badTargetsAreNamed() {
        assertTrue(assertThrows(HttpError.class, () -> DebugMonitor.targets("")).getMessage().contains("at least one"));
        assertTrue(assertThrows(HttpError.class, () -> DebugMonitor.targets("a.b,c.d,e.f,g.h,i.j")).getMessage()
                .contains("at most 4"));
        assertTrue(assertThrows(HttpError.class, () -> DebugMonitor.targets("nodot")).getMessage().contains("'nodot'"));
        assertTrue(assertThrows(HttpError.class, () -> DebugMonitor.targets("a.B\"x")).getMessage().contains("port name"));
        assertTrue(assertThrows(HttpError.class, () -> DebugMonitor.targets("<c>.p")).getMessage().contains("name"));
        assertTrue(assertThrows(HttpError.class, () -> DebugMonitor.targets("a.b,a.b")).getMessage().contains("twice"));
    }

    @Test
    void aJarThatIsNotTheMonitorIsRefused(@TempDir Path dir) throws Exception {
        Manifest mf = new Manifest();
        mf.getMainAttributes().put(Attributes.Name.MANIFEST_VERSION, "1.0");
        mf.getMainAttributes().putValue("Bundle-SymbolicName", "org.example.other");
        Path jar = dir.resolve("other.jar");
        try (OutputStream o = Files.newOutputStream(jar); JarOutputStream j = new JarOutputStream(o, mf)) {
            j.putNextEntry(new JarEntry("x"));
        }
        HttpError e = assertThrows(HttpError.class, () -> DebugMonitor.build(jar, DebugMonitor.targets("a.b"), parser));
        assertTrue(e.getMessage().contains("not the debug-monitor bundle"), e.getMessage());
        HttpError missing = assertThrows(HttpError.class, () -> DebugMonitor.locate(dir.resolve("nope.jar").toString()));
        assertTrue(missing.getMessage().contains("nope.jar"), missing.getMessage());
    }
}
