package org.arflex.drcr.impl.services;

import static org.arflex.drcr.impl.services.DeploymentDescriptor.COMPONENT;
import static org.arflex.drcr.impl.services.DeploymentDescriptor.CYCLES;
import static org.arflex.drcr.impl.services.DeploymentDescriptor.PORT_OR_FIELD;
import static org.arflex.drcr.impl.services.DeploymentDescriptor.SHA256;

import java.net.URI;
import java.net.URISyntaxException;
import java.util.Locale;
import javax.xml.stream.XMLStreamReader;

/**
 * The attribute values of a deployment set's descriptor (D45), each checked where it is read:
 * names, cycles, finite numbers, a port's field, a jar URL resolved against the descriptor's own
 * URL ({@code https:} or {@code file:} only), its pin or its signature; a bad one named with
 * what it must be.
 */
final class DescriptorValues {
    private final XMLStreamReader r;
    private final DescriptorXml x;
    private final URI base;

    DescriptorValues(XMLStreamReader r, DescriptorXml x, URI base) {
        this.r = r;
        this.x = x;
        this.base = base;
    }

    String required(String el, String attr) {
        String v = r.getAttributeValue(null, attr);
        if (v == null) {
            throw x.error(el, "attribute '" + attr + "' is required");
        }
        return v;
    }

    String component(String el, String what) {
        String component = r.getAttributeValue(null, "component");
        if (component == null) {
            throw x.error(el, "attribute 'component' is required (" + what + ")");
        }
        if (!COMPONENT.matcher(component).matches()) {
            throw x.error(el, "component '" + component + "' is not a component name (" + COMPONENT.pattern() + ")");
        }
        return component;
    }

    Long cycles(String el, String attr) {
        String v = r.getAttributeValue(null, attr);
        if (v == null) {
            return null;
        }
        if (!CYCLES.matcher(v).matches()) {
            throw x.error(el, attr + " '" + v + "' is not a number of cycles (0..999999999)");
        }
        return Long.parseLong(v);
    }

    double number(String el, String attr) {
        String v = required(el, attr);
        double d;
        try {
            d = Double.parseDouble(v);
        } catch (NumberFormatException e) {
            d = Double.NaN;
        }
        if (!Double.isFinite(d) || !v.matches("[-+]?[0-9.eE+-]+")) {
            throw x.error(el, attr + " '" + v + "' is not a finite decimal number");
        }
        return d;
    }

    String portField(String el) {
        String port = required(el, "port");
        String field = required(el, "field");
        if (!PORT_OR_FIELD.matcher(port).matches()) {
            throw x.error(el, "port '" + port + "' is not a port name (" + PORT_OR_FIELD.pattern() + ")");
        }
        if (!PORT_OR_FIELD.matcher(field).matches()) {
            throw x.error(el, "field '" + field + "' is not a field name (" + PORT_OR_FIELD.pattern() + ")");
        }
        return port + "." + field;
    }

    /** The jar attribute, resolved against the descriptor's URL, https or file only. */
    URI jar(String el) {
        String v = required(el, "jar");
        if (v.isBlank() || v.chars().anyMatch(c -> c <= ' ' || c == ',' || c == ';')) {
            throw x.error(el, "jar '" + v + "': a URL without white space, ',' or ';'");
        }
        URI u;
        try {
            u = new URI(v);
        } catch (URISyntaxException e) {
            throw x.error(el, "jar '" + v + "' is not a URL: " + e.getReason());
        }
        URI resolved;
        try {
            resolved = u.isAbsolute() ? u : base.resolve(u);
        } catch (IllegalArgumentException e) {
            throw x.error(el, "jar '" + v + "' cannot be resolved against " + base + ": " + e.getMessage());
        }
        String why = Fetch.refusal(resolved);
        if (why != null) {
            throw x.error(el, "jar '" + v + "'" + (u.isAbsolute() ? "" : " (" + resolved + ")") + ": " + why);
        }
        if (resolved.getFragment() != null) {
            throw x.error(el, "jar '" + v + "': a fragment (#...) names no jar");
        }
        return resolved;
    }

    /** The pin, or null for signed="true"; exactly one of the two. */
    String gate(String el) {
        String sha = r.getAttributeValue(null, "sha256");
        String signed = r.getAttributeValue(null, "signed");
        if (signed != null && !signed.equals("true")) {
            throw x.error(el, "signed '" + signed + "': only signed=\"true\" (or give sha256)");
        }
        if (sha != null && signed != null) {
            throw x.error(el, "both sha256 and signed: a jar is admitted by one of them");
        }
        if (sha == null && signed == null) {
            throw x.error(el, "neither sha256 nor signed=\"true\": every jar is pinned by its SHA-256 or signed by a "
                    + "key of the trust store");
        }
        if (sha != null && !SHA256.matcher(sha).matches()) {
            throw x.error(el, "sha256 '" + sha + "' is not a SHA-256 (64 hex digits)");
        }
        return sha == null ? null : sha.toLowerCase(Locale.ROOT);
    }

    /** A number as the change-set action writes it: an integer without a fraction. */
    static String text(double d) {
        return d == Math.rint(d) && Math.abs(d) < 1e15 ? Long.toString((long) d) : Double.toString(d);
    }
}
