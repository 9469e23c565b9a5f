package org.arflex.contract.internal;

import com.ctc.wstx.api.WstxInputProperties;
import com.ctc.wstx.api.WstxOutputProperties;
import com.ctc.wstx.stax.WstxInputFactory;
import com.ctc.wstx.stax.WstxOutputFactory;
import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.nio.charset.Charset;
import java.nio.charset.StandardCharsets;
import java.util.List;
import javax.xml.stream.Location;
import javax.xml.stream.XMLInputFactory;
import javax.xml.stream.XMLOutputFactory;
import javax.xml.stream.XMLStreamConstants;
import javax.xml.stream.XMLStreamException;
import javax.xml.stream.XMLStreamReader;
import org.arflex.contract.Problem;

/**
 * The one place that makes XML readers. Every document the contracts module reads (contracts
 * and port type definitions) goes through a Woodstox factory configured here, never through
 * {@code XMLInputFactory.newFactory()} (which in OSGi may find another parser with other
 * defaults).
 *
 * <p>Defences (spec §2.1, §2.2): input size capped before parsing; DTDs refused (a DOCTYPE is
 * an error, so no entity is ever declared, let alone expanded); external entities and DTD
 * loading disabled and an XMLResolver that refuses everything as a second line; entity
 * expansion bounded in Woodstox as a third line; element depth, element count, attributes per
 * element, attribute and text length bounded.
 */
public final class SecureXml {
    /** Largest document accepted, bytes (§2.1). */
    public static final int MAX_BYTES = 1 << 20;
    /** Deepest element nesting accepted (§2.1). */
    public static final int MAX_DEPTH = 16;
    /** Most elements in one document (§2.1). */
    public static final int MAX_ELEMENTS = 10_000;
    /** Most attributes on one element (§2.1). */
    public static final int MAX_ATTRIBUTES = 32;
    /** Longest attribute value, characters (§2.1). */
    public static final int MAX_ATTRIBUTE_LENGTH = 4096;
    /** Longest text node, characters (§2.1). */
    public static final int MAX_TEXT_LENGTH = 64 * 1024;

    private SecureXml() {
    }

    /** A new hardened input factory (factories are thread-safe once configured; we make one per parser). */
    public static XMLInputFactory newInputFactory() {
        WstxInputFactory f = new WstxInputFactory();
        f.setProperty(XMLInputFactory.SUPPORT_DTD, Boolean.FALSE);
        f.setProperty(XMLInputFactory.IS_SUPPORTING_EXTERNAL_ENTITIES, Boolean.FALSE);
        f.setProperty(XMLInputFactory.IS_REPLACING_ENTITY_REFERENCES, Boolean.FALSE);
        f.setProperty(XMLInputFactory.IS_NAMESPACE_AWARE, Boolean.TRUE);
        f.setProperty(XMLInputFactory.IS_COALESCING, Boolean.TRUE);
        f.setXMLResolver((publicId, systemId, baseUri, ns) -> {
            throw new XMLStreamException("external resource refused: " + systemId);
        });
        f.setProperty(WstxInputProperties.P_MAX_ELEMENT_DEPTH, MAX_DEPTH);
        f.setProperty(WstxInputProperties.P_MAX_ELEMENT_COUNT, (long) MAX_ELEMENTS);
        f.setProperty(WstxInputProperties.P_MAX_ATTRIBUTES_PER_ELEMENT, MAX_ATTRIBUTES);
        f.setProperty(WstxInputProperties.P_MAX_ATTRIBUTE_SIZE, MAX_ATTRIBUTE_LENGTH);
        f.setProperty(WstxInputProperties.P_MAX_TEXT_LENGTH, MAX_TEXT_LENGTH);
        f.setProperty(WstxInputProperties.P_MAX_CHARACTERS, (long) MAX_BYTES);
        f.setProperty(WstxInputProperties.P_MAX_ENTITY_DEPTH, 1);
        f.setProperty(WstxInputProperties.P_MAX_ENTITY_COUNT, 1L);
        return f;
    }

    /** A new output factory (Woodstox, namespace repairing off: the writers declare what they use). */
    public static XMLOutputFactory newOutputFactory() {
        WstxOutputFactory f = new WstxOutputFactory();
        f.setProperty(WstxOutputProperties.P_OUTPUT_VALIDATE_STRUCTURE, Boolean.TRUE);
        return f;
    }

    /**
     * Reads at most {@link #MAX_BYTES} from {@code in}; returns null and adds a §2.1 problem when
     * the input is larger.
     */
    public static byte[] readBounded(InputStream in, String source, List<Problem> problems) throws IOException {
        byte[] data = in.readNBytes(MAX_BYTES + 1);
        if (data.length > MAX_BYTES) {
            problems.add(new Problem(source, 0, 0, "2.1", "(document)",
                    "document is larger than " + MAX_BYTES + " bytes; refused before parsing"));
            return null;
        }
        return data;
    }

    /**
     * First pass over a document with the hardened reader: well-formedness, limits, no DOCTYPE,
     * no entity reference, no processing instruction, the expected root element and namespace,
     * every element in that namespace and every attribute unqualified. Returns true when the
     * document may go on to data binding; otherwise problems were added.
     */
    public static boolean prescan(XMLInputFactory factory, byte[] data, String source, String namespace,
            String root, String section, List<Problem> problems) {
        int before = problems.size();
        XMLStreamReader r = null;
        try {
            r = factory.createXMLStreamReader(new ByteArrayInputStream(data));
            String encodingProblem = encodingProblem(r.getCharacterEncodingScheme(), data);
            if (encodingProblem != null) {
                add(problems, source, DOCUMENT_START, "2.1", "(document)", encodingProblem);
                return false;
            }
            boolean seenRoot = false;
            while (r.hasNext()) {
                int ev = r.next();
                switch (ev) {
                    case XMLStreamConstants.DTD -> {
                        add(problems, source, r.getLocation(), "2.2", "(document)",
                                "DOCTYPE declarations are not allowed (no DTDs, no entities)");
                        return false;
                    }
                    case XMLStreamConstants.ENTITY_REFERENCE -> {
                        add(problems, source, r.getLocation(), "2.2", "(document)",
                                "entity reference &" + r.getLocalName() + "; is not allowed");
                        return false;
                    }
                    case XMLStreamConstants.PROCESSING_INSTRUCTION -> {
                        add(problems, source, r.getLocation(), "2.2", "(document)",
                                "processing instruction <?" + r.getPITarget() + "?> is not allowed");
                        return false;
                    }
                    case XMLStreamConstants.CHARACTERS, XMLStreamConstants.CDATA, XMLStreamConstants.SPACE -> {
                        if (r.getTextLength() > MAX_TEXT_LENGTH) {
                            add(problems, source, r.getLocation(), "2.1", "(document)",
                                    "document exceeds a parser limit: a text node is longer than " + MAX_TEXT_LENGTH
                                            + " characters");
                            return false;
                        }
                    }
                    case XMLStreamConstants.START_ELEMENT -> {
                        String ns = r.getNamespaceURI() == null ? "" : r.getNamespaceURI();
                        if (!seenRoot) {
                            seenRoot = true;
                            if (!root.equals(r.getLocalName()) || !namespace.equals(ns)) {
                                add(problems, source, r.getLocation(), section, "(root)",
                                        "root element must be <" + root + " xmlns=\"" + namespace + "\">, found <"
                                                + r.getLocalName() + (ns.isEmpty() ? "" : " xmlns=\"" + ns + "\"")
                                                + ">");
                                return false;
                            }
                        } else if (!namespace.equals(ns)) {
                            add(problems, source, r.getLocation(), "2.4", r.getLocalName(),
                                    "element <" + r.getLocalName() + "> is in namespace '" + ns
                                            + "'; only " + namespace + " is allowed");
                        }
                        for (int i = 0; i < r.getAttributeCount(); i++) {
                            String ans = r.getAttributeNamespace(i);
                            if (ans != null && !ans.isEmpty()) {
                                add(problems, source, r.getLocation(), "2.4",
                                        r.getLocalName() + "/@" + r.getAttributeLocalName(i),
                                        "qualified attribute (namespace '" + ans + "') is not allowed");
                            }
                        }
                    }
                    default -> {
                    }
                }
            }
            if (!seenRoot) {
                problems.add(new Problem(source, 1, 1, "2.3", "(root)", "document has no root element"));
            }
        } catch (XMLStreamException | RuntimeException e) {
            // RuntimeException: Woodstox reports an error found while reading text lazily (a
            // text node past the limit) as an unchecked WstxLazyException, and a limit may throw
            // IllegalArgumentException; all of them are problems of this document (issue 16).
            // no reader yet: creating it failed in the XML declaration or the encoding detection
            // (an unsupported or inconsistent encoding), which Woodstox reports without a
            // location; both are at the document's start (issue 16, fuzzing)
            problems.add(XmlFailure.problem(e, source, r == null ? DOCUMENT_START : locationOf(r)));
        } finally {
            if (r != null) {
                try {
                    r.close();
                } catch (XMLStreamException ignored) {
                    // closing a reader over a byte array frees nothing that matters
                }
            }
        }
        return problems.size() == before;
    }

    /**
     * What is wrong with the encoding the XML declaration names ({@code declared}, null when
     * there is none), or null. Woodstox matches encoding names loosely ("UT-F-8" and "utf_8"
     * read as UTF-8) and lets a declaration override a UTF-8 byte order mark; the JDK's parser
     * behind the XSD check does neither, so such a document was accepted by the validator and
     * then refused by the schema check with no location (issue 16, found by fuzzing). XML 1.0
     * §4.3.3 makes both a fatal error; §2.1 refuses them here, before anything reads the text.
     */
    static String encodingProblem(String declared, byte[] data) {
        if (declared == null) {
            return null;
        }
        Charset named;
        try {
            named = Charset.forName(declared);
        } catch (IllegalArgumentException e) {
            // IllegalCharsetNameException and UnsupportedCharsetException are both IllegalArgumentExceptions
            return "malformed XML: the XML declaration names encoding '" + declared + "', which is not supported";
        }
        Charset bom = byteOrderMark(data);
        if (bom != null && !bom.equals(named) && !(bom.name().startsWith("UTF-16") && named.name().startsWith("UTF-16"))) {
            return "malformed XML: the byte order mark says " + bom.name() + " but the XML declaration names encoding '"
                    + declared + "'";
        }
        return null;
    }

    private static Charset byteOrderMark(byte[] d) {
        if (d.length >= 3 && (d[0] & 0xFF) == 0xEF && (d[1] & 0xFF) == 0xBB && (d[2] & 0xFF) == 0xBF) {
            return StandardCharsets.UTF_8;
        }
        if (d.length >= 2 && (d[0] & 0xFF) == 0xFE && (d[1] & 0xFF) == 0xFF) {
            return StandardCharsets.UTF_16BE;
        }
        if (d.length >= 2 && (d[0] & 0xFF) == 0xFF && (d[1] & 0xFF) == 0xFE) {
            return StandardCharsets.UTF_16LE;
        }
        return null;
    }

    /** The parser's message without Woodstox's location prefix (the Problem carries it). */
    public static String describe(Exception e) {
        return describe(e.getMessage() == null ? e.getClass().getSimpleName() : e.getMessage());
    }

    /** A parser's message {@code m} without Woodstox's location prefix. */
    static String describe(String message) {
        String m = message.replaceFirst("(?s)^ParseError at \\[row,col\\]:\\[\\d+,\\d+\\]\\s*Message:\\s*", "");
        int at = m.indexOf("\n at [");
        if (at > 0) {
            m = m.substring(0, at);
        }
        if (m.contains("Maximum") || m.contains("limit")) {
            m = "document exceeds a parser limit: " + m;
        }
        return "malformed XML: " + m.replace('\n', ' ').trim();
    }

    /** Line 1, column 1: where the XML declaration and the encoding detection are. */
    private static final Location DOCUMENT_START = new Location() {
        @Override
        public int getLineNumber() {
            return 1;
        }

        @Override
        public int getColumnNumber() {
            return 1;
        }

        @Override
        public int getCharacterOffset() {
            return 0;
        }

        @Override
        public String getPublicId() {
            return null;
        }

        @Override
        public String getSystemId() {
            return null;
        }
    };

    private static Location locationOf(XMLStreamReader r) {
        try {
            return r.getLocation();
        } catch (RuntimeException e) {
            return null;
        }
    }

    private static void add(List<Problem> problems, String source, Location loc, String section, String field,
            String message) {
        int line = loc == null ? 0 : Math.max(loc.getLineNumber(), 0);
        int col = line <= 0 ? 0 : Math.max(loc.getColumnNumber(), 1);
        problems.add(new Problem(source, line, col, section, field, message));
    }
}
