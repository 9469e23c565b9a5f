package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.net.URI;
import java.net.URISyntaxException;
import java.util.ArrayList;
import java.util.HashSet;
import java.util.List;
import java.util.Locale;
import java.util.Set;
import java.util.regex.Pattern;
import javax.xml.XMLConstants;
import javax.xml.stream.Location;
import javax.xml.stream.XMLInputFactory;
import javax.xml.stream.XMLStreamConstants;
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
        Reader p = new Reader(label, source);
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

    /** One pass over the document. */
    private static final class Reader {
        private final String label;
        private final URI base;
        private XMLStreamReader r;

        Reader(String label, URI base) {
            this.label = label;
            this.base = base;
        }

        private IllegalArgumentException error(String element, String message) {
            Location l = r.getLocation();
            return new IllegalArgumentException(label + ":" + l.getLineNumber() + ":" + l.getColumnNumber() + ": <"
                    + element + ">: " + message);
        }

        DeploymentDescriptor document(XMLStreamReader reader) throws XMLStreamException {
            this.r = reader;
            String name = null;
            List<Entry> entries = new ArrayList<>();
            boolean root = false;
            while (r.hasNext()) {
                int ev = r.next();
                switch (ev) {
                    case XMLStreamConstants.DTD -> throw new IllegalArgumentException(label + ":"
                            + r.getLocation().getLineNumber() + ": (document): a DOCTYPE is not allowed");
                    case XMLStreamConstants.PROCESSING_INSTRUCTION -> throw new IllegalArgumentException(label + ":"
                            + r.getLocation().getLineNumber() + ": (document): processing instruction <?" + r.getPITarget()
                            + "?> is not allowed");
                    case XMLStreamConstants.ENTITY_REFERENCE -> throw new IllegalArgumentException(label + ":"
                            + r.getLocation().getLineNumber() + ": (document): entity reference &" + r.getLocalName()
                            + "; is not allowed");
                    case XMLStreamConstants.START_ELEMENT -> {
                        if (root) {
                            throw error(r.getLocalName(), "a second root element");
                        }
                        root = true;
                        element("deployment");
                        attributes("deployment", Set.of("name"));
                        name = r.getAttributeValue(null, "name");
                        if (name != null && !SET_NAME.matcher(name).matches()) {
                            throw error("deployment", "name '" + name + "' is not a set name ("
                                    + SET_NAME.pattern() + ")");
                        }
                        entries = children();
                    }
                    case XMLStreamConstants.CHARACTERS, XMLStreamConstants.SPACE -> text("(document)");
                    default -> {
                    }
                }
            }
            if (!root) {
                throw new IllegalArgumentException(label + ": (document): no <deployment> element");
            }
            if (entries.isEmpty()) {
                throw new IllegalArgumentException(label + ": <deployment>: names no action (an <install>, <update>, "
                        + "<uninstall> or <set> element)");
            }
            return new DeploymentDescriptor(name, base, entries);
        }

        /** The children of the root, up to its end tag. */
        private List<Entry> children() throws XMLStreamException {
            List<Entry> out = new ArrayList<>();
            Set<URI> jars = new HashSet<>();
            java.util.Map<String, Entry> named = new java.util.HashMap<>();
            Set<String> written = new HashSet<>();
            while (true) {
                int ev = r.next();
                if (ev == XMLStreamConstants.END_ELEMENT) {
                    return out;
                }
                if (ev == XMLStreamConstants.CHARACTERS || ev == XMLStreamConstants.SPACE) {
                    text("deployment");
                    continue;
                }
                if (ev != XMLStreamConstants.START_ELEMENT) {
                    other(ev, "deployment");
                    continue;
                }
                String el = r.getLocalName();
                if (!NAMESPACE.equals(r.getNamespaceURI()) || !List.of("install", "update", "uninstall", "set").contains(el)) {
                    throw error(el, "unknown element in <deployment> (expected <install>, <update>, <uninstall> or <set> "
                            + "in namespace " + NAMESPACE + ")");
                }
                if (out.size() == MAX_ENTRIES) {
                    throw error(el, "more than " + MAX_ENTRIES + " actions in one set");
                }
                Entry e = switch (el) {
                    case "install" -> install();
                    case "update" -> update();
                    case "uninstall" -> uninstall();
                    default -> write();
                };
                if (e.jar() != null && !jars.add(e.jar())) {
                    throw new IllegalArgumentException(label + ":" + e.line() + ": <" + el + ">: jar " + e.jar()
                            + " is named twice in the set");
                }
                if (e.kind() == Kind.SET) {
                    if (!written.add(e.component() + "." + e.parameter())) {
                        throw new IllegalArgumentException(label + ":" + e.line() + ": <set>: parameter " + e.component()
                                + "." + e.parameter() + " is written twice in the set");
                    }
                } else if (e.component() != null) {
                    Entry before = named.putIfAbsent(e.component(), e);
                    if (before != null) {
                        throw new IllegalArgumentException(label + ":" + e.line() + ": <" + el + ">: component '"
                                + e.component() + "' is named twice in the set (also <"
                                + before.kind().name().toLowerCase(Locale.ROOT) + "> on line " + before.line() + ")");
                    }
                }
                out.add(e);
            }
        }

        private Entry install() throws XMLStreamException {
            int line = r.getLocation().getLineNumber();
            attributes("install", Set.of("jar", "sha256", "signed"));
            URI jar = jar("install");
            String sha = gate("install");
            empty("install");
            return new Entry(Kind.INSTALL, line, jar, sha, null, null, null, List.of());
        }

        private Entry uninstall() throws XMLStreamException {
            int line = r.getLocation().getLineNumber();
            attributes("uninstall", Set.of("component"));
            String component = component("uninstall", "the running component it stops and removes");
            empty("uninstall");
            return new Entry(Kind.UNINSTALL, line, null, null, component, null, null, List.of());
        }

        /** {@code <set component parameter value>}: a parameter write, as {@code set c p v} in a change set. */
        private Entry write() throws XMLStreamException {
            int line = r.getLocation().getLineNumber();
            attributes("set", Set.of("component", "parameter", "value"));
            String component = component("set", "the component whose parameter it writes");
            String parameter = required("set", "parameter");
            if (!PARAMETER.matcher(parameter).matches()) {
                throw error("set", "parameter '" + parameter + "' is not a parameter name (" + PARAMETER.pattern() + ")");
            }
            String value = required("set", "value");
            if (!VALUE.matcher(value).matches()) {
                throw error("set", "value '" + value + "': 1 to 64 printable characters without blanks, ';' or ','");
            }
            empty("set");
            return new Entry(Kind.SET, line, null, null, component, null, null, List.of(), parameter, value);
        }

        private String component(String el, String what) {
            String component = r.getAttributeValue(null, "component");
            if (component == null) {
                throw error(el, "attribute 'component' is required (" + what + ")");
            }
            if (!COMPONENT.matcher(component).matches()) {
                throw error(el, "component '" + component + "' is not a component name (" + COMPONENT.pattern() + ")");
            }
            return component;
        }

        private Entry update() throws XMLStreamException {
            int line = r.getLocation().getLineNumber();
            attributes("update", Set.of("component", "jar", "sha256", "signed", "window", "shadow"));
            String component = component("update", "the running component it updates");
            URI jar = jar("update");
            String sha = gate("update");
            Long window = cycles("update", "window");
            Long shadow = cycles("update", "shadow");
            if (window != null && window == 0) {
                throw error("update", "window '0': a rollback window is at least 1 cycle");
            }
            List<String> options = new ArrayList<>();
            while (true) {
                int ev = r.next();
                if (ev == XMLStreamConstants.END_ELEMENT) {
                    break;
                }
                if (ev == XMLStreamConstants.CHARACTERS || ev == XMLStreamConstants.SPACE) {
                    text("update");
                    continue;
                }
                if (ev != XMLStreamConstants.START_ELEMENT) {
                    other(ev, "update");
                    continue;
                }
                String el = r.getLocalName();
                if (!NAMESPACE.equals(r.getNamespaceURI()) || !(el.equals("envelope") || el.equals("tolerance"))) {
                    throw error(el, "unknown element in <update> (expected <envelope> or <tolerance>)");
                }
                options.add(el.equals("envelope") ? envelope() : tolerance());
            }
            return new Entry(Kind.UPDATE, line, jar, sha, component, window, shadow, options);
        }

        private String envelope() throws XMLStreamException {
            attributes("envelope", Set.of("port", "field", "min", "max"));
            String pf = portField("envelope");
            double min = number("envelope", "min");
            double max = number("envelope", "max");
            if (min > max) {
                throw error("envelope", "min " + text(min) + " is above max " + text(max));
            }
            empty("envelope");
            return "envelope " + pf + " " + text(min) + " " + text(max);
        }

        private String tolerance() throws XMLStreamException {
            attributes("tolerance", Set.of("port", "field", "max"));
            String pf = portField("tolerance");
            double max = number("tolerance", "max");
            if (max < 0) {
                throw error("tolerance", "max " + text(max) + " is negative (a largest difference is >= 0)");
            }
            empty("tolerance");
            return "tolerance " + pf + " " + text(max);
        }

        private static String text(double d) {
            return d == Math.rint(d) && Math.abs(d) < 1e15 ? Long.toString((long) d) : Double.toString(d);
        }

        private String portField(String el) {
            String port = required(el, "port");
            String field = required(el, "field");
            if (!PORT_OR_FIELD.matcher(port).matches()) {
                throw error(el, "port '" + port + "' is not a port name (" + PORT_OR_FIELD.pattern() + ")");
            }
            if (!PORT_OR_FIELD.matcher(field).matches()) {
                throw error(el, "field '" + field + "' is not a field name (" + PORT_OR_FIELD.pattern() + ")");
            }
            return port + "." + field;
        }

        private double number(String el, String attr) {
            String v = required(el, attr);
            double d;
            try {
                d = Double.parseDouble(v);
            } catch (NumberFormatException e) {
                d = Double.NaN;
            }
            if (!Double.isFinite(d) || !v.matches("[-+]?[0-9.eE+-]+")) {
                throw error(el, attr + " '" + v + "' is not a finite decimal number");
            }
            return d;
        }

        private Long cycles(String el, String attr) {
            String v = r.getAttributeValue(null, attr);
            if (v == null) {
                return null;
            }
            if (!CYCLES.matcher(v).matches()) {
                throw error(el, attr + " '" + v + "' is not a number of cycles (0..999999999)");
            }
            return Long.parseLong(v);
        }

        private String required(String el, String attr) {
            String v = r.getAttributeValue(null, attr);
            if (v == null) {
                throw error(el, "attribute '" + attr + "' is required");
            }
            return v;
        }

        /** The jar attribute, resolved against the descriptor's URL, https or file only. */
        private URI jar(String el) {
            String v = required(el, "jar");
            if (v.isBlank() || v.chars().anyMatch(c -> c <= ' ' || c == ',' || c == ';')) {
                throw error(el, "jar '" + v + "': a URL without white space, ',' or ';'");
            }
            URI u;
            try {
                u = new URI(v);
            } catch (URISyntaxException e) {
                throw error(el, "jar '" + v + "' is not a URL: " + e.getReason());
            }
            URI resolved;
            try {
                resolved = u.isAbsolute() ? u : base.resolve(u);
            } catch (IllegalArgumentException e) {
                throw error(el, "jar '" + v + "' cannot be resolved against " + base + ": " + e.getMessage());
            }
            String why = Fetch.refusal(resolved);
            if (why != null) {
                throw error(el, "jar '" + v + "'" + (u.isAbsolute() ? "" : " (" + resolved + ")") + ": " + why);
            }
            if (resolved.getFragment() != null) {
                throw error(el, "jar '" + v + "': a fragment (#...) names no jar");
            }
            return resolved;
        }

        /** The pin, or null for signed="true"; exactly one of the two. */
        private String gate(String el) {
            String sha = r.getAttributeValue(null, "sha256");
            String signed = r.getAttributeValue(null, "signed");
            if (signed != null && !signed.equals("true")) {
                throw error(el, "signed '" + signed + "': only signed=\"true\" (or give sha256)");
            }
            if (sha != null && signed != null) {
                throw error(el, "both sha256 and signed: a jar is admitted by one of them");
            }
            if (sha == null && signed == null) {
                throw error(el, "neither sha256 nor signed=\"true\": every jar is pinned by its SHA-256 or signed by a "
                        + "key of the trust store");
            }
            if (sha != null && !SHA256.matcher(sha).matches()) {
                throw error(el, "sha256 '" + sha + "' is not a SHA-256 (64 hex digits)");
            }
            return sha == null ? null : sha.toLowerCase(Locale.ROOT);
        }

        private void element(String expected) {
            if (!NAMESPACE.equals(r.getNamespaceURI())) {
                throw error(r.getLocalName(), "not in namespace " + NAMESPACE + " (it is in "
                        + (r.getNamespaceURI() == null || r.getNamespaceURI().isEmpty() ? "no namespace" : r.getNamespaceURI())
                        + ")");
            }
            if (!r.getLocalName().equals(expected)) {
                throw error(r.getLocalName(), "the root element must be <" + expected + ">");
            }
        }

        private void attributes(String el, Set<String> allowed) {
            for (int i = 0; i < r.getAttributeCount(); i++) {
                String ns = r.getAttributeNamespace(i);
                String a = r.getAttributeLocalName(i);
                if ((ns != null && !ns.isEmpty()) || !allowed.contains(a)) {
                    throw error(el, "unknown attribute '" + (r.getAttributePrefix(i) == null || r.getAttributePrefix(i).isEmpty()
                            ? "" : r.getAttributePrefix(i) + ":") + a + "' (allowed: " + String.join(", ",
                            allowed.stream().sorted().toList()) + ")");
                }
            }
        }

        /** The element has no content: its end tag follows (white space allowed). */
        private void empty(String el) throws XMLStreamException {
            while (true) {
                int ev = r.next();
                if (ev == XMLStreamConstants.END_ELEMENT) {
                    return;
                }
                if (ev == XMLStreamConstants.CHARACTERS || ev == XMLStreamConstants.SPACE) {
                    text(el);
                } else if (ev == XMLStreamConstants.START_ELEMENT) {
                    throw error(r.getLocalName(), "<" + el + "> has no child elements");
                } else {
                    other(ev, el);
                }
            }
        }

        private void text(String el) {
            if (!r.isWhiteSpace()) {
                String t = r.getText().strip();
                throw error(el, "text '" + (t.length() > 40 ? t.substring(0, 40) + "..." : t) + "' is not allowed here");
            }
        }

        private void other(int ev, String el) {
            switch (ev) {
                case XMLStreamConstants.COMMENT -> {
                }
                case XMLStreamConstants.PROCESSING_INSTRUCTION -> throw error(el, "processing instruction <?"
                        + r.getPITarget() + "?> is not allowed");
                case XMLStreamConstants.ENTITY_REFERENCE -> throw error(el, "entity reference &" + r.getLocalName()
                        + "; is not allowed");
                case XMLStreamConstants.CDATA -> text(el);
                default -> throw error(el, "unexpected XML event " + ev);
            }
        }
    }
}
