package org.arflex.planner.impl;

import java.util.Optional;
import java.util.Set;
import java.util.TreeSet;
import org.arflex.contract.Binding;
import org.arflex.contract.PortSpec;
import org.arflex.planner.Wire;

/** An input of an installed component with its candidate providers. */
final class ResolverIn {
    final String consumer;
    final PortSpec spec;
    final Optional<Binding> binding;
    final LdapFilter filter;
    final String filterError;
    final TreeSet<ResolverOut> candidates = new TreeSet<>();
    Wire wire;
    /** The node of {@link #wire}'s provider (refreshed by every rewire), null without wire. */
    ResolverNode providerNode;
    /** The node that owns this input. */
    ResolverNode owner;
    /** The index set this input is registered in, if any. */
    Set<ResolverIn> home;

    ResolverIn(String consumer, PortSpec spec) {
        this.consumer = consumer;
        this.spec = spec;
        this.binding = spec.binding();
        LdapFilter f = null;
        String err = null;
        Optional<String> text = binding.flatMap(Binding::filter);
        if (text.isPresent() && binding.get().component().isEmpty()) {
            try {
                f = LdapFilter.parse(text.get());
            } catch (IllegalArgumentException e) {
                err = e.getMessage();
            }
        }
        this.filter = f;
        this.filterError = err;
    }

    boolean explicit() {
        return binding.isPresent() && binding.get().component().isPresent();
    }

    String explicitComponent() {
        return binding.get().component().get();
    }

    String explicitPort() {
        return binding.get().port().orElse("");
    }

    boolean required() {
        return !spec.optional();
    }
}
