package org.arflex.drcr.impl.services;

import java.util.Set;
import javax.xml.stream.Location;
import javax.xml.stream.XMLStreamConstants;
import javax.xml.stream.XMLStreamException;
import javax.xml.stream.XMLStreamReader;

/**
 * The strict form of a deployment set's descriptor (D45), element by element: in the namespace,
 * only known attributes, no text but white space, no processing instruction nor entity
 * reference; every error as {@code <document>:<line>:<column>: <element>: <what is wrong>}.
 */
final class DescriptorXml {
    private final String label;
    private final XMLStreamReader r;

    DescriptorXml(String label, XMLStreamReader r) {
        this.label = label;
        this.r = r;
    }

    IllegalArgumentException error(String element, String message) {
        Location l = r.getLocation();
        return new IllegalArgumentException(label + ":" + l.getLineNumber() + ":" + l.getColumnNumber() + ": <"
                + element + ">: " + message);
    }

    void element(String expected) {
        if (!DeploymentDescriptor.NAMESPACE.equals(r.getNamespaceURI())) {
            throw error(r.getLocalName(), "not in namespace " + DeploymentDescriptor.NAMESPACE + " (it is in "
                    + (r.getNamespaceURI() == null || r.getNamespaceURI().isEmpty() ? "no namespace" : r.getNamespaceURI())
                    + ")");
        }
        if (!r.getLocalName().equals(expected)) {
            throw error(r.getLocalName(), "the root element must be <" + expected + ">");
        }
    }

    void attributes(String el, Set<String> allowed) {
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
    void empty(String el) throws XMLStreamException {
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

    void text(String el) {
        if (!r.isWhiteSpace()) {
            String t = r.getText().strip();
            throw error(el, "text '" + (t.length() > 40 ? t.substring(0, 40) + "..." : t) + "' is not allowed here");
        }
    }

    void other(int ev, String el) {
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
