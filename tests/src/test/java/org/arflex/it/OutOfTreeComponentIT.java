package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.TimeUnit;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * A component kept out of the tree, as an integrator keeps it (issue 31, D84): {@code ./arflex new
 * component NAME --dest DIR} with DIR outside the repository makes a project of its own, which
 * builds with Maven and CMake against the installed SDK only ({@code cmake --install
 * target/native --prefix SDK}: rt-core, the port-type headers, the test kit) and passes its own
 * generated test (ctest rt.NAME.cycle, run by {@code mvn verify}); no generated file and no
 * build setting names the source tree.
 */
class OutOfTreeComponentIT {

    static final Path ROOT = Components.root().toAbsolutePath().normalize();
    static final String NAME = "oot-probe";

    record Run(int exit, String out) {
    }

    static Run run(Path dir, long timeoutS, String... cmd) throws IOException, InterruptedException {
        Path log = Files.createTempFile("oot-run", ".log");
        try {
            Process p = new ProcessBuilder(cmd).directory(dir.toFile()).redirectErrorStream(true)
                    .redirectOutput(log.toFile()).start();
            if (!p.waitFor(timeoutS, TimeUnit.SECONDS)) {
                p.descendants().forEach(ProcessHandle::destroyForcibly);
                p.destroyForcibly();
                p.waitFor(30, TimeUnit.SECONDS);
                throw new AssertionError(String.join(" ", cmd) + " did not end in " + timeoutS + " s:\n" + Files.readString(log));
            }
            return new Run(p.exitValue(), Files.readString(log, StandardCharsets.UTF_8));
        } finally {
            Files.deleteIfExists(log);
        }
    }

    /**
     * Every file below {@code dir} whose text names the source tree. Executables and objects
     * (ELF) are not read: the debug information of the SDK's static library names the folder it
     * was compiled in, which the build never opens.
     */
    static List<String> namingTheTree(Path dir) throws IOException {
        List<String> hits = new ArrayList<>();
        try (Stream<Path> s = Files.walk(dir)) {
            for (Path f : s.filter(Files::isRegularFile).toList()) {
                byte[] data = Files.readAllBytes(f);
                boolean elf = data.length >= 4 && data[0] == 0x7f && data[1] == 'E' && data[2] == 'L' && data[3] == 'F';
                String text = new String(data, StandardCharsets.ISO_8859_1);
                if (!elf && text.contains(ROOT + "/")) {
                    hits.add(dir.relativize(f).toString());
                }
            }
        }
        return hits;
    }

    @Test
    void aComponentGeneratedOutOfTreeBuildsWithMavenAndCMakeAgainstTheInstalledSdk(@TempDir Path tmp) throws Exception {
        Path work = tmp.toRealPath();
        assertFalse(work.startsWith(ROOT), work + " is inside the tree");
        Path dest = Files.createDirectories(work.resolve("integrator"));
        Path sdk = work.resolve("sdk");
        Path project = dest.resolve(NAME);

        Run gen = run(work, 60, ROOT.resolve("arflex").toString(), "new", "component", NAME, "--dest", dest.toString());
        assertEquals(0, gen.exit(), gen.out());
        assertTrue(gen.out().contains("out of the tree"), gen.out());
        String pom = Files.readString(project.resolve("pom.xml"));
        assertFalse(pom.contains("<relativePath>") || pom.contains("../"), "the pom points into a tree:\n" + pom);
        assertEquals(List.of(), namingTheTree(project), "generated files that name the source tree");
        assertFalse(Files.exists(dest.resolve("pom.xml")), "a pom was made or edited beside the component");

        Run install = run(work, 120, "cmake", "--install", ROOT.resolve("target/native").toString(), "--prefix", sdk.toString());
        assertEquals(0, install.exit(), install.out());

        Run mvn = run(project, 600, "mvn", "-B", "-o", "-Dmaven.repo.local=" + System.getProperty("arflex.it.m2"),
                "-Darflex.sdk=" + sdk, "verify");
        assertEquals(0, mvn.exit(), mvn.out());
        assertTrue(mvn.out().contains("rt." + NAME + ".cycle") && mvn.out().contains("100% tests passed, 0 tests failed out of 1"),
                "its generated test did not run:\n" + mvn.out());

        // CMake found the SDK in the prefix, and nothing of the build names the source tree.
        Path cache = project.resolve("target/native/CMakeCache.txt");
        String arflexDir = Files.readAllLines(cache).stream().filter(l -> l.startsWith("arflex_DIR:")).findFirst().orElse("");
        assertTrue(arflexDir.startsWith("arflex_DIR:PATH=" + sdk + "/"), arflexDir);
        assertEquals(List.of(), namingTheTree(project.resolve("target/native")), "build files that name the source tree");

        // The bundle: the contract and the executable where the DRCR reads them.
        Path jar = project.resolve("target/org.arflex.cell." + NAME + "-0.1.0-SNAPSHOT.jar");
        assertTrue(Files.isRegularFile(jar), jar + " not built");
        try (java.util.jar.JarFile j = new java.util.jar.JarFile(jar.toFile())) {
            assertEquals("OSGI-INF/arflex/" + NAME + ".xml", j.getManifest().getMainAttributes().getValue("ARFLEX-Contract"));
            assertTrue(j.getEntry("OSGI-INF/arflex/" + NAME + ".xml") != null, "no contract in the jar");
            assertTrue(j.getEntry("native/linux-x86_64/" + NAME) != null, "no executable in the jar");
        }
    }
}
