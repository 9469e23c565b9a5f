package org.arflex.drcr.impl.services;

import static org.arflex.drcr.impl.services.DeploymentDescriptor.MAX_ENTRIES;
import static org.arflex.drcr.impl.services.DeploymentDescriptor.NAMESPACE;
import static org.arflex.drcr.impl.services.DeploymentDescriptor.PARAMETER;
import static org.arflex.drcr.impl.services.DeploymentDescriptor.SET_NAME;
import static org.arflex.drcr.impl.services.DeploymentDescriptor.VALUE;

import java.net.URI;
import java.util.ArrayList;
import java.util.HashSet;
import java.util.List;
import java.util.Locale;
import java.util.Set;
import javax.xml.stream.XMLStreamConstants;
import javax.xml.stream.XMLStreamException;
import javax.xml.stream.XMLStreamReader;
import org.arflex.drcr.impl.services.DeploymentDescriptor.Entry;
import org.arflex.drcr.impl.services.DeploymentDescriptor.Kind;

/**
 * One pass over a deployment set's descriptor (D45, D50): the root {@code <deployment>}, its
 * actions ({@code <install>}, {@code <update>} with its {@code <envelope>} and
 * {@code <tolerance>}, {@code <uninstall>}, {@code <set>}) in document order, at most
 * {@link DeploymentDescriptor#MAX_ENTRIES}, no jar, component or parameter named twice. The
 * form is checked by {@link DescriptorXml}, the values by {@link DescriptorValues}.
 */
final class DescriptorReader {
    private final String label;
    private final URI base;
    private XMLStreamReader r;
    private DescriptorXml x;
    private DescriptorValues v;

    DescriptorReader(String label, URI base) {
        this.label = label;
        this.base = base;
    }

    DeploymentDescriptor document(XMLStreamReader reader) throws XMLStreamException {
        this.r = reader;
        this.x = new DescriptorXml(label, reader);
        this.v = new DescriptorValues(reader, x, base);
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
                        throw x.error(r.getLocalName(), "a second root element");
                    }
                    root = true;
                    x.element("deployment");
                    x.attributes("deployment", Set.of("name"));
                    name = r.getAttributeValue(null, "name");
                    if (name != null && !SET_NAME.matcher(name).matches()) {
                        throw x.error("deployment", "name '" + name + "' is not a set name ("
                                + SET_NAME.pattern() + ")");
                    }
                    entries = children();
                }
                case XMLStreamConstants.CHARACTERS, XMLStreamConstants.SPACE -> x.text("(document)");
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
                x.text("deployment");
                continue;
            }
            if (ev != XMLStreamConstants.START_ELEMENT) {
                x.other(ev, "deployment");
                continue;
            }
            String el = r.getLocalName();
            if (!NAMESPACE.equals(r.getNamespaceURI()) || !List.of("install", "update", "uninstall", "set").contains(el)) {
                throw x.error(el, "unknown element in <deployment> (expected <install>, <update>, <uninstall> or <set> "
                        + "in namespace " + NAMESPACE + ")");
            }
            if (out.size() == MAX_ENTRIES) {
                throw x.error(el, "more than " + MAX_ENTRIES + " actions in one set");
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
        x.attributes("install", Set.of("jar", "sha256", "signed"));
        URI jar = v.jar("install");
        String sha = v.gate("install");
        x.empty("install");
        return new Entry(Kind.INSTALL, line, jar, sha, null, null, null, List.of());
    }

    private Entry uninstall() throws XMLStreamException {
        int line = r.getLocation().getLineNumber();
        x.attributes("uninstall", Set.of("component"));
        String component = v.component("uninstall", "the running component it stops and removes");
        x.empty("uninstall");
        return new Entry(Kind.UNINSTALL, line, null, null, component, null, null, List.of());
    }

    /** {@code <set component parameter value>}: a parameter write, as {@code set c p v} in a change set. */
    private Entry write() throws XMLStreamException {
        int line = r.getLocation().getLineNumber();
        x.attributes("set", Set.of("component", "parameter", "value"));
        String component = v.component("set", "the component whose parameter it writes");
        String parameter = v.required("set", "parameter");
        if (!PARAMETER.matcher(parameter).matches()) {
            throw x.error("set", "parameter '" + parameter + "' is not a parameter name (" + PARAMETER.pattern() + ")");
        }
        String value = v.required("set", "value");
        if (!VALUE.matcher(value).matches()) {
            throw x.error("set", "value '" + value + "': 1 to 64 printable characters without blanks, ';' or ','");
        }
        x.empty("set");
        return new Entry(Kind.SET, line, null, null, component, null, null, List.of(), parameter, value);
    }

    private Entry update() throws XMLStreamException {
        int line = r.getLocation().getLineNumber();
        x.attributes("update", Set.of("component", "jar", "sha256", "signed", "window", "shadow"));
        String component = v.component("update", "the running component it updates");
        URI jar = v.jar("update");
        String sha = v.gate("update");
        Long window = v.cycles("update", "window");
        Long shadow = v.cycles("update", "shadow");
        if (window != null && window == 0) {
            throw x.error("update", "window '0': a rollback window is at least 1 cycle");
        }
        List<String> options = new ArrayList<>();
        while (true) {
            int ev = r.next();
            if (ev == XMLStreamConstants.END_ELEMENT) {
                break;
            }
            if (ev == XMLStreamConstants.CHARACTERS || ev == XMLStreamConstants.SPACE) {
                x.text("update");
                continue;
            }
            if (ev != XMLStreamConstants.START_ELEMENT) {
                x.other(ev, "update");
                continue;
            }
            String el = r.getLocalName();
            if (!NAMESPACE.equals(r.getNamespaceURI()) || !(el.equals("envelope") || el.equals("tolerance"))) {
                throw x.error(el, "unknown element in <update> (expected <envelope> or <tolerance>)");
            }
            options.add(el.equals("envelope") ? envelope() : tolerance());
        }
        return new Entry(Kind.UPDATE, line, jar, sha, component, window, shadow, options);
    }

    private String envelope() throws XMLStreamException {
        x.attributes("envelope", Set.of("port", "field", "min", "max"));
        String pf = v.portField("envelope");
        double min = v.number("envelope", "min");
        double max = v.number("envelope", "max");
        if (min > max) {
            throw x.error("envelope", "min " + DescriptorValues.text(min) + " is above max " + DescriptorValues.text(max));
        }
        x.empty("envelope");
        return "envelope " + pf + " " + DescriptorValues.text(min) + " " + DescriptorValues.text(max);
    }

    private String tolerance() throws XMLStreamException {
        x.attributes("tolerance", Set.of("port", "field", "max"));
        String pf = v.portField("tolerance");
        double max = v.number("tolerance", "max");
        if (max < 0) {
            throw x.error("tolerance", "max " + DescriptorValues.text(max) + " is negative (a largest difference is >= 0)");
        }
        x.empty("tolerance");
        return "tolerance " + pf + " " + DescriptorValues.text(max);
    }
}
