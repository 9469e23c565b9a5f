package org.arflex.planner.impl;

import org.arflex.contract.PortSpec;

/** An output of an installed component. */
record ResolverOut(String component, PortSpec spec) implements Comparable<ResolverOut> {
    String ref() {
        return component + "." + spec.name();
    }

    @Override
    public int compareTo(ResolverOut o) {
        int c = component.compareTo(o.component);
        return c != 0 ? c : spec.name().compareTo(o.spec.name());
    }
}
