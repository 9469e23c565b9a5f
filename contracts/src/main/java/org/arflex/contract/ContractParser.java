package org.arflex.contract;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.io.UncheckedIOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collection;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import javax.xml.XMLConstants;
import javax.xml.stream.XMLInputFactory;
import javax.xml.transform.stream.StreamSource;
import javax.xml.validation.Schema;
import javax.xml.validation.SchemaFactory;
import javax.xml.validation.Validator;
import org.arflex.contract.internal.Binder;
import org.arflex.contract.internal.ContractXml;
import org.arflex.contract.internal.SecureXml;
import org.xml.sax.ErrorHandler;
import org.xml.sax.SAXException;
import org.xml.sax.SAXParseException;

/**
 * Reads contracts (spec: contracts/SPEC.md). The pipeline: bounded read (§2.1) → hardened
 * StAX prescan (§2.1-2.4: no DTD, no entities, limits, root and namespace) → Jackson XML
 * binding into a mutable model → validation of every rule, collecting all problems → frozen
 * {@link Contract} → XSD check (§14) as a cross-check of the schema against the validator.
 *
 * <p>Instances are immutable and thread-safe; make one and share it. A failure never throws
 * anything but {@link ContractException} (for {@code parse}) and never affects another
 * document: {@link #parseAll(Map)} reads each document on its own.
 */
public final class ContractParser {
    /** Namespace of contract documents. */
    public static final String NAMESPACE = "urn:arflex:contract:1";
    /** Resource path of the contract schema in this bundle. */
    public static final String SCHEMA_RESOURCE = "/arflex/schema/arflex-contract-1.xsd";
    /** Largest contract accepted, bytes. */
    public static final int MAX_BYTES = SecureXml.MAX_BYTES;

    private final XMLInputFactory inputFactory;
    private final Binder binder;
    private final ContractValidator validator;
    private final Schema schema;

    private ContractParser(PortTypes types, Schema schema) {
        this.inputFactory = SecureXml.newInputFactory();
        this.binder = new Binder(inputFactory);
        this.validator = new ContractValidator(types);
        this.schema = schema;
    }

    /** A parser that knows the port types shipped with this bundle and checks the XSD too. */
    public static ContractParser create() {
        return new ContractParser(PortTypes.builtin(), loadSchema());
    }

    /** A parser that knows the given port types (and checks the XSD too). */
    public static ContractParser create(PortTypes types) {
        return new ContractParser(types, loadSchema());
    }

    /** Parses and validates one contract; throws with every problem found. */
    public Contract parse(InputStream in, String source) throws ContractException {
        List<Problem> problems = new ArrayList<>();
        byte[] data;
        try {
            data = SecureXml.readBounded(in, source, problems);
        } catch (IOException e) {
            problems.add(new Problem(source, 0, 0, "2.1", "(document)", "cannot read: " + e.getMessage()));
            data = null;
        }
        Contract c = data == null ? null : run(data, source, problems);
        if (c == null || !problems.isEmpty()) {
            throw new ContractException(problems);
        }
        return c;
    }

    /** Parses and validates one contract given as text (read as UTF-8); throws with every problem. */
    public Contract parse(String xml, String source) throws ContractException {
        return parse(new ByteArrayInputStream(xml.getBytes(StandardCharsets.UTF_8)), source);
    }

    /** Every problem of a contract given as text; empty when it is valid. Never throws on bad input. */
    public List<Problem> validate(String xml, String source) {
        try {
            parse(xml == null ? "" : xml, source);
            return List.of();
        } catch (ContractException e) {
            return e.problems();
        }
    }

    /**
     * Parses each document on its own (keys are sources, in the map's iteration order); one bad
     * document yields its problems and disturbs no other.
     */
    public List<Result> parseAll(Map<String, String> documents) {
        List<Result> results = new ArrayList<>();
        documents.forEach((source, xml) -> results.add(result(source, () -> parse(xml, source))));
        return results;
    }

    /** Parses each file on its own, as {@link #parseAll(Map)}; the source is the file's path. */
    public List<Result> parseFiles(Collection<Path> files) {
        List<Result> results = new ArrayList<>();
        for (Path f : files) {
            String source = f.toString();
            results.add(result(source, () -> {
                try (InputStream in = Files.newInputStream(f)) {
                    return parse(in, source);
                } catch (IOException e) {
                    throw new UncheckedIOException(e);
                }
            }));
        }
        return results;
    }

    /**
     * The outcome for one document.
     *
     * @param source   the document's source
     * @param contract the contract, when valid
     * @param problems every problem, empty when valid
     */
    public record Result(String source, Optional<Contract> contract, List<Problem> problems) {
        public Result {
            problems = List.copyOf(problems);
        }

        /** True when the document gave a contract. */
        public boolean ok() {
            return contract.isPresent();
        }
    }

    private interface Step {
        Contract run() throws ContractException;
    }

    private static Result result(String source, Step step) {
        try {
            return new Result(source, Optional.of(step.run()), List.of());
        } catch (ContractException e) {
            return new Result(source, Optional.empty(), e.problems());
        } catch (UncheckedIOException e) {
            return new Result(source, Optional.empty(),
                    List.of(new Problem(source, 0, 0, "2.1", "(document)", "cannot read: " + e.getCause().getMessage())));
        }
    }

    private Contract run(byte[] data, String source, List<Problem> problems) {
        if (!SecureXml.prescan(inputFactory, data, source, NAMESPACE, "component", "2.3", problems)) {
            return null;
        }
        ContractXml x = binder.bind(data, ContractXml.class, source, problems);
        if (x == null) {
            return null;
        }
        Contract c = validator.freeze(x, source, problems);
        if (c == null || !problems.isEmpty()) {
            return null;
        }
        if (schema != null) {
            checkSchema(data, source, problems);
        }
        return problems.isEmpty() ? c : null;
    }

    /** §14: the XSD must accept whatever the validator accepted; a disagreement is reported. */
    private void checkSchema(byte[] data, String source, List<Problem> problems) {
        try {
            Validator v = schema.newValidator();
            v.setFeature(XMLConstants.FEATURE_SECURE_PROCESSING, true);
            v.setProperty(XMLConstants.ACCESS_EXTERNAL_DTD, "");
            v.setProperty(XMLConstants.ACCESS_EXTERNAL_SCHEMA, "");
            v.setErrorHandler(new ErrorHandler() {
                @Override
                public void warning(SAXParseException e) {
                    // warnings are not problems
                }

                @Override
                public void error(SAXParseException e) {
                    problems.add(new Problem(source, Math.max(e.getLineNumber(), 1), Math.max(e.getColumnNumber(), 1), "14", "(schema)",
                            "rejected by arflex-contract-1.xsd: " + e.getMessage()));
                }

                @Override
                public void fatalError(SAXParseException e) {
                    error(e);
                }
            });
            v.validate(new StreamSource(new ByteArrayInputStream(data), source));
        } catch (SAXException | IOException e) {
            // the JDK's parser failed before it could say where (a SAXParseException went to the
            // handler above): that is while it sets up decoding, at the document's start. The
            // prescan refuses what it knows to fail here (SecureXml.encodingProblem); this is
            // the last line (issue 16: every problem has a line and a column)
            if (problems.isEmpty()) {
                problems.add(new Problem(source, 1, 1, "14", "(schema)", "schema check failed: " + e.getMessage()));
            }
        }
    }

    private static volatile Schema cachedSchema;

    /** The contract XSD, compiled once with secure processing and no external access. */
    public static Schema loadSchema() {
        Schema s = cachedSchema;
        if (s != null) {
            return s;
        }
        try (InputStream in = ContractParser.class.getResourceAsStream(SCHEMA_RESOURCE)) {
            if (in == null) {
                throw new IllegalStateException("resource " + SCHEMA_RESOURCE + " missing from the bundle");
            }
            SchemaFactory f = SchemaFactory.newDefaultInstance();
            f.setFeature(XMLConstants.FEATURE_SECURE_PROCESSING, true);
            f.setProperty(XMLConstants.ACCESS_EXTERNAL_DTD, "");
            f.setProperty(XMLConstants.ACCESS_EXTERNAL_SCHEMA, "");
            s = f.newSchema(new StreamSource(in, "arflex-contract-1.xsd"));
            cachedSchema = s;
            return s;
        } catch (IOException | SAXException e) {
            throw new IllegalStateException("shipped contract schema is broken: " + e.getMessage(), e);
        }
    }
}
