package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertThrows;

import java.io.ByteArrayInputStream;
import java.nio.file.Files;
import java.nio.file.Path;
import javax.xml.XMLConstants;
import javax.xml.transform.stream.StreamSource;
import javax.xml.validation.Validator;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.ValueSource;
import org.xml.sax.SAXException;

/** The XSD also refuses what it can express (single-field rules); the validator stays the authority. */
class SchemaTest {
    private static final Path BAD = Path.of("src/test/resources/bad").toAbsolutePath();

    @ParameterizedTest
    @ValueSource(strings = {"priority-out-of-range", "update-http", "update-short-hash", "bad-task", "unknown-element",
        "stream-depth-huge", "missing-fault", "bad-name", "bad-version", "bad-duration-unit", "bad-memory-unit",
        "criticality-out-of-range", "bad-restart", "bad-method", "wrong-namespace"})
    void schemaRejects(String name) throws Exception {
        Validator v = ContractParser.loadSchema().newValidator();
        v.setFeature(XMLConstants.FEATURE_SECURE_PROCESSING, true);
        v.setProperty(XMLConstants.ACCESS_EXTERNAL_DTD, "");
        v.setProperty(XMLConstants.ACCESS_EXTERNAL_SCHEMA, "");
        byte[] data = Files.readAllBytes(BAD.resolve(name + ".xml"));
        assertThrows(SAXException.class, () -> v.validate(new StreamSource(new ByteArrayInputStream(data))));
    }
}
