package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;

/** An installed component in the {@link Resolver}: its contract, its inputs, its status. */
final class ResolverNode {
    final Contract contract;
    final List<ResolverIn> inputs = new ArrayList<>();
    boolean locallyOk;
    boolean satisfied;

    ResolverNode(Contract contract) {
        this.contract = contract;
        for (PortSpec p : contract.ports()) {
            if (p.direction() == PortSpec.Direction.IN) {
                ResolverIn in = new ResolverIn(contract.name(), p);
                in.owner = this;
                inputs.add(in);
            }
        }
    }

    String name() {
        return contract.name();
    }
}
