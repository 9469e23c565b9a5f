package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.net.URI;
import java.util.List;
import java.util.regex.Pattern;
import javax.xml.XMLConstants;
import javax.xml.stream.Location;
import javax.xml.stream.XMLInputFactory;
import javax.xml.stream.XMLStreamException;
import javax.xml.stream.XMLStreamReader;

/**
 * A deployment set's descriptor (docs/DECISIONS.md D45, D50, docs/deployment-sets.md): one XML
 * document at one URL naming several bundles, each a new component to install or the update of a
 * running one, each jar pinned by its SHA-256 or declared signed by a key of the trust store; and
 * the change-set actions without a jar, uninstalls of running components and parameter writes.
 *
 * <pre>{@code
 * <deployment xmlns="urn:arflex:deployment:1" name="cell-2026-11">
 *   <install jar="tool-gripper-1.0.0.jar" sha256="<64 hex>"/>
 *   <update component="tcp-correction" jar="https://repo/tcp-correction-1.0.1.jar" signed="true"
 *           window="500" shadow="200">
 *     <envelope port="corrected" field="q" min="-3.2" max="3.2"/>
 *     <tolerance port="corrected" field="q" max="0.001"/>
 *   </update>
 *   <uninstall component="teach-pendant"/>
 *   <set component="tcp-correction" parameter="gain" value="0.5"/>
 * </deployment>
 * }</pre>
 *
 * Read strictly: the document is at most {@link #MAX_BYTES}, has no DOCTYPE (so no entity is
 * ever declared) nor processing instruction, every element is in the namespace and known, every
 * attribute known and well formed, no text but white space. A jar URL is resolved against the
 * descriptor's own URL and must then be {@code https:} or {@code file:}. Every error names the
 * document, the line and column, the element and what is wrong; the first one is reported.
 * Immutable.
 */
public record DeploymentDescriptor(String name, URI source, List<Entry> entries) {

    /** The namespace of descriptors. */
    public static final String NAMESPACE = "urn:arflex:deployment:1";
    /** Largest descriptor accepted, bytes. */
    public static final int MAX_BYTES = 1 << 20;
    /** Most bundles in one set. */
    public static final int MAX_ENTRIES = 64;

    static final Pattern SET_NAME = Pattern.compile("[A-Za-z0-9][A-Za-z0-9._-]{0,63}");
    static final Pattern COMPONENT = Pattern.compile("[a-z][a-z0-9-]{0,47}");
    static final Pattern PORT_OR_FIELD = Pattern.compile("[a-z][a-z0-9_]{0,31}");
    static final Pattern SHA256 = Pattern.compile("[0-9a-fA-F]{64}");
    static final Pattern PARAMETER = Pattern.compile("[a-z][a-z0-9_.]{0,30}");
    /** A parameter's value as one change-set word: printable ASCII without blanks, ';' or ','. */
    static final Pattern VALUE = Pattern.compile("[\\x21-\\x7e&&[^;,]]{1,64}");
    static final Pattern CYCLES = Pattern.compile("0|[1-9][0-9]{0,8}");

    /** What an action of the set is: a bundle (install, update) or a change without a jar. */
    public enum Kind { INSTALL, UPDATE, UNINSTALL, SET }

    /**
     * One action of the set: a bundle, or (without jar) an uninstall or a parameter write.
     *
     * @param line      the line of its element in the descriptor
     * @param jar       its jar, resolved against the descriptor's URL; null for an uninstall or a write
     * @param sha256    its pinned SHA-256 (lower case), or null: signed by a key of the trust store
     * @param component the running component an update replaces, an uninstall stops or a write
     *                  sets; null for an install
     * @param window    an update's rollback window in cycles, or null (the default)
     * @param shadow    an update's shadow run in cycles, or null (none, or its contract's)
     * @param options   an update's {@code envelope <port>.<field> <min> <max>} and
     *                  {@code tolerance <port>.<field> <max>}, as change-set options
     * @param parameter a write's parameter, else null
     * @param value     a write's value, else null
     */
    public record Entry(Kind kind, int line, URI jar, String sha256, String component, Long window, Long shadow,
                        List<String> options, String parameter, String value) {

        public Entry {
            options = List.copyOf(options);
        }

        public Entry(Kind kind, int line, URI jar, String sha256, String component, Long window, Long shadow,
                     List<String> options) {
            this(kind, line, jar, sha256, component, window, shadow, options, null, null);
        }

        /** The change-set action of an uninstall or a write ({@code uninstall c}, {@code set c p v}). */
        public String action() {
            return switch (kind) {
                case UNINSTALL -> "uninstall " + component;
                case SET -> "set " + component + " " + parameter + " " + value;
                case UPDATE -> updateAction();
                case INSTALL -> "install " + jar;
            };
        }

        /** True for an install or an update: an entry with a jar. */
        public boolean bundle() {
            return jar != null;
        }

        /** How its code is admitted: the pin, or a trusted signature. */
        public String gate() {
            return sha256 != null ? "sha256 " + sha256 : "signed by a key of the trust store";
        }

        /** {@code install <jar>}, {@code update <component> <jar>} or the action, for messages. */
        public String describe() {
            return switch (kind) {
                case INSTALL -> "install " + jar;
                case UPDATE -> "update " + component + " from " + jar;
                default -> action();
            };
        }

        /** The change-set action of an update (ChangeSets' syntax, D38, D42). */
        public String updateAction() {
            StringBuilder sb = new StringBuilder("update ").append(component).append(' ').append(jar);
            if (sha256 != null) {
                sb.append(' ').append(sha256);
            }
            if (window != null) {
                sb.append(" window ").append(window);
            }
            if (shadow != null) {
                sb.append(" shadow ").append(shadow);
            }
            for (String o : options) {
                sb.append(' ').append(o);
            }
            return sb.toString();
        }
    }

    public DeploymentDescriptor {
        entries = List.copyOf(entries);
    }

    /** The installs of the set, in document order. */
    public List<Entry> installs() {
        return entries.stream().filter(e -> e.kind() == Kind.INSTALL).toList();
    }

    /** The updates of the set, in document order. */
    public List<Entry> updates() {
        return entries.stream().filter(e -> e.kind() == Kind.UPDATE).toList();
    }

    /** The entries with a jar (installs and updates), in document order. */
    public List<Entry> bundles() {
        return entries.stream().filter(Entry::bundle).toList();
    }

    /** The uninstalls and parameter writes, in document order. */
    public List<Entry> changes() {
        return entries.stream().filter(e -> !e.bundle()).toList();
    }

    /**
     * Parses a descriptor read from {@code source}.
     *
     * @throws IllegalArgumentException {@code <source>:<line>:<column>: <element>: <what is wrong>}
     */
    public static DeploymentDescriptor parse(byte[] xml, URI source) {
        String label = source.toString();
        if (xml.length > MAX_BYTES) {
            throw new IllegalArgumentException(label + ": (document): larger than " + MAX_BYTES
                    + " bytes; refused before parsing");
        }
        XMLInputFactory f = XMLInputFactory.newDefaultFactory(); // the JDK's own, whatever OSGi offers
        f.setProperty(XMLInputFactory.SUPPORT_DTD, Boolean.FALSE);
        f.setProperty(XMLInputFactory.IS_SUPPORTING_EXTERNAL_ENTITIES, Boolean.FALSE);
        f.setProperty(XMLInputFactory.IS_NAMESPACE_AWARE, Boolean.TRUE);
        f.setProperty(XMLInputFactory.IS_COALESCING, Boolean.TRUE);
        f.setProperty(XMLConstants.ACCESS_EXTERNAL_DTD, "");
        f.setXMLResolver((publicId, systemId, baseUri, ns) -> {
            throw new XMLStreamException("external resource refused: " + systemId);
        });
        DescriptorReader p = new DescriptorReader(label, source);
        XMLStreamReader r = null;
        try {
            r = f.createXMLStreamReader(new ByteArrayInputStream(xml));
            return p.document(r);
        } catch (XMLStreamException e) {
            Location l = e.getLocation();
            String msg = e.getMessage() == null ? e.toString() : e.getMessage();
            // the JDK prefixes "ParseError at [row,col]:[l,c]\nMessage: "
            int m = msg.indexOf("Message: ");
            throw new IllegalArgumentException(label + ":" + (l == null ? 0 : l.getLineNumber()) + ":"
                    + (l == null ? 0 : l.getColumnNumber()) + ": (document): not well-formed XML: "
                    + (m >= 0 ? msg.substring(m + 9) : msg).strip());
        } finally {
            if (r != null) {
                try {
                    r.close();
                } catch (XMLStreamException ignored) {
                    // nothing held beyond the byte array
                }
            }
        }
    }
}
