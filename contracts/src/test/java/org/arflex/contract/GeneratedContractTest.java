package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * The contract {@code ./arflex new component} writes (scripts/new-component.sh, template in
 * rt-core/template/component) is valid as generated: the generator is run into a temporary
 * directory, never into bundles/, and its contract parsed and validated like any bundle's.
 * The ctest tools.new_component checks the rest of the generated folder (it builds, its test
 * passes).
 */
class GeneratedContractTest {

    @Test
    void generatedContractIsValid(@TempDir Path dir) throws Exception {
        Path script = Path.of("..", "scripts", "new-component.sh").toAbsolutePath().normalize();
        assertTrue(Files.isRegularFile(script), "no generator at " + script);
        String name = "gen-probe";
        Process p = new ProcessBuilder("bash", script.toString(), name, "--dest", dir.toString())
                .redirectErrorStream(true).start();
        assertTrue(p.waitFor(60, TimeUnit.SECONDS), "generator did not finish");
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        assertEquals(0, p.exitValue(), out);

        Path xml = dir.resolve(name).resolve("src/main/resources/OSGI-INF/arflex/" + name + ".xml");
        Contract c;
        try {
            c = ContractParser.create().parse(Files.readString(xml), xml.toString());
        } catch (ContractException e) {
            throw new AssertionError("generated contract refused: " + e.problems(), e);
        }
        assertEquals(name, c.name());
        assertEquals(name, c.executable());
        assertTrue(c.port("in").isPresent() && c.port("out").isPresent(), "ports in/out");
        assertTrue(c.property("gain").isPresent(), "parameter gain");
        // It round-trips like every good contract.
        assertEquals(c, ContractParser.create().parse(ContractWriter.create().write(c), xml.toString()));
    }
}
