package org.arflex.contract;

import java.util.Optional;

/**
 * The binding rule of an input: either an explicit provider {@code component.port}, or an LDAP
 * style filter over the provider's attributes (RFC 1960 syntax, as OSGi filters), or neither
 * (any provider of a compatible type). Exactly one provider must match, otherwise the
 * resolver reports ambiguity.
 *
 * @param component explicit provider component name
 * @param port      explicit provider port name (with component)
 * @param filter    filter over provider attributes, for example {@code (&(role=robot)(sim=true))}
 */
public record Binding(Optional<String> component, Optional<String> port, Optional<String> filter) {

    /** An explicit {@code component.port} binding. */
    public static Binding explicit(String component, String port) {
        return new Binding(Optional.of(component), Optional.of(port), Optional.empty());
    }

    /** A filter binding. */
    public static Binding filter(String filter) {
        return new Binding(Optional.empty(), Optional.empty(), Optional.of(filter));
    }
}
