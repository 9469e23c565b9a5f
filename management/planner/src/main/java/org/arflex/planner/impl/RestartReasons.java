package org.arflex.planner.impl;

import java.util.List;
import java.util.Map;
import java.util.SortedMap;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Wire;

/**
 * Why a component Active before and after a change is restarted or rebound: a replaced contract,
 * an input wired to another provider, gained or lost (a lost safety input: HOLD), a provider port
 * of another shape, a move to another CPU.
 */
final class RestartReasons {
    /** How the reason of a HOLD starts: a safety input lost its provider. */
    static final String SAFETY_LOST = "safety input ";

    private final Resolver resolver;
    /** CPU of every Active component before the change. */
    private final Map<String, Integer> cpuOf;

    RestartReasons(Resolver resolver, Map<String, Integer> cpuOf) {
        this.resolver = resolver;
        this.cpuOf = cpuOf;
    }

    /**
     * Collects into {@code why} what changed for a component Active before and after; returns
     * true when only its input wires changed (same contract, same CPU, every provider port of
     * the same shape), which the DRCR applies live with UNBIND/BIND instead of a restart.
     */
    boolean collect(String n, SortedMap<String, Contract> replaced, List<Wire> oldWires,
            List<Wire> newWires, Map<String, Contract> oldContracts, AdmissionResult adm, List<String> why) {
        boolean structural = false;
        if (replaced.containsKey(n)) {
            structural = true;
            String o = replaced.get(n).version();
            String v = resolver.contract(n).get().version();
            why.add(o.equals(v) ? "contract changed (version " + v + ")" : "replaced " + o + " -> " + v);
        }
        Map<String, Wire> before = new TreeMap<>();
        for (Wire w : oldWires) {
            before.put(w.inPort(), w);
        }
        Map<String, Wire> after = new TreeMap<>();
        for (Wire w : newWires) {
            after.put(w.inPort(), w);
        }
        TreeSet<String> ports = new TreeSet<>(before.keySet());
        ports.addAll(after.keySet());
        for (String p : ports) {
            Wire b = before.get(p);
            Wire a = after.get(p);
            if (a != null && b != null && a.equals(b)) {
                Contract oldProvider = oldContracts.get(a.provider());
                if (oldProvider != null) {
                    PortSpec op = oldProvider.port(a.outPort()).orElse(null);
                    PortSpec np = resolver.contract(a.provider()).get().port(a.outPort()).orElse(null);
                    if (op != null && np != null && !samePortShape(op, np)) {
                        structural = true;
                        why.add("provider port " + a.source() + " changed (" + shape(op) + " -> " + shape(np) + ")");
                    }
                }
            } else if (a != null && b != null) {
                why.add("input '" + p + "' now from " + a.source() + " (was " + b.source() + ")");
            } else if (a != null) {
                why.add("input '" + p + "' now from " + a.source());
            } else if (resolver.contract(n).flatMap(c -> c.port(p)).map(PortSpec::safety).orElse(false)) {
                why.add(SAFETY_LOST + "'" + p + "' lost " + b.source() + ": protective stop until a guard is bound and "
                        + "the operator resets");
            } else {
                why.add("input '" + p + "' lost " + b.source());
            }
        }
        Integer oldCpu = cpuOf.get(n);
        OptionalIntBox newCpu = new OptionalIntBox(adm.cpuOf(n));
        if (oldCpu != null && newCpu.present && oldCpu != newCpu.value) {
            structural = true;
            why.add("moved cpu " + oldCpu + " -> " + newCpu.value);
        }
        return !structural;
    }

    private record OptionalIntBox(boolean present, int value) {
        OptionalIntBox(java.util.OptionalInt o) {
            this(o.isPresent(), o.isPresent() ? o.getAsInt() : -1);
        }
    }

    private static boolean samePortShape(PortSpec a, PortSpec b) {
        return a.type().equals(b.type()) && a.typeVersion().equals(b.typeVersion()) && a.method() == b.method()
                && a.depth() == b.depth() && a.overflow() == b.overflow();
    }

    private static String shape(PortSpec p) {
        return p.type() + " " + p.typeVersion() + " " + p.method().name().toLowerCase(java.util.Locale.ROOT)
                + " depth " + p.depth();
    }
}
