package org.arflex.webconsole.impl;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.stream.Stream;
import org.arflex.contract.ContractParser;
import org.arflex.contract.Problem;

/**
 * The Contract editor's endpoints: validate XML with the DRCR's own {@link ContractParser}, and
 * save, list and load contracts in the contracts folder ({@code $ARFLEX_HOME/contracts} or
 * {@code arflex.contracts.dir}).
 */
final class ContractBackend {
    private final Path contractsDir;
    private final ContractParser parser;

    ContractBackend(Path contractsDir, ContractParser parser) {
        this.contractsDir = contractsDir;
        this.parser = parser;
    }

    Routes routes() {
        return new Routes()
                .get("contracts", call -> Map.of("saved", savedContracts()))
                .get("contract", call -> Map.of("name", call.name(), "xml", loadContract(call.name())))
                .post("validate", call -> Map.of("problems", validate(call.text(), "editor.xml")))
                .post("save", call -> saveContract(call.name(), call.text()));
    }

    List<Problem> validate(String xml, String source) {
        return parser.validate(xml, source);
    }

    Map<String, Object> saveContract(String name, String xml) throws HttpError, IOException {
        Names.checkName(name);
        List<Problem> problems = validate(xml, name + ".xml");
        if (!problems.isEmpty()) {
            Map<String, Object> m = new LinkedHashMap<>();
            m.put("saved", false);
            m.put("problems", problems);
            return m;
        }
        Path dir = Files.createDirectories(contractsDir);
        Path tmp = Files.createTempFile(dir, name, ".tmp");
        Files.writeString(tmp, xml, StandardCharsets.UTF_8);
        Path target = dir.resolve(name + ".xml");
        Files.move(tmp, target, StandardCopyOption.REPLACE_EXISTING, StandardCopyOption.ATOMIC_MOVE);
        return Map.of("saved", true, "path", target.toString(), "problems", List.of());
    }

    List<String> savedContracts() throws IOException {
        if (!Files.isDirectory(contractsDir)) {
            return List.of();
        }
        List<String> names = new ArrayList<>();
        try (Stream<Path> s = Files.list(contractsDir)) {
            s.map(p -> p.getFileName().toString()).filter(f -> f.endsWith(".xml")).sorted()
                    .forEach(f -> names.add(f.substring(0, f.length() - 4)));
        }
        return names;
    }

    String loadContract(String name) throws HttpError, IOException {
        Names.checkName(name);
        Path p = contractsDir.resolve(name + ".xml");
        if (!Files.isRegularFile(p)) {
            throw new HttpError(404, "no saved contract named '" + name + "'");
        }
        return Files.readString(p, StandardCharsets.UTF_8);
    }
}
