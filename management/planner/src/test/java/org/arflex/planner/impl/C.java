package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import org.arflex.contract.Binding;
import org.arflex.contract.Contract;
import org.arflex.contract.FaultPolicy;
import org.arflex.contract.PortSpec;
import org.arflex.contract.Resources;
import org.arflex.contract.Timing;
import org.arflex.contract.TypeVersion;

/** Test builder of contracts: {@code C.of("a").out("y", "arflex.Sample").in("x", "arflex.Sample").build()}. */
public final class C {
    public static final long MS = 1_000_000L;
    public static final long MIB = 1L << 20;

    private final String name;
    private String version = "1.0.0";
    private Contract.TaskType type = Contract.TaskType.PERIODIC;
    private final Map<String, String> attrs = new LinkedHashMap<>();
    private final List<PortSpec> ports = new ArrayList<>();
    private Timing timing = new Timing(10 * MS, 10 * MS, 1 * MS, 50, List.of());
    private long mem = MIB;
    private long net = 0;
    private int crit = 1;

    private C(String name) {
        this.name = name;
    }

    public static C of(String name) {
        return new C(name);
    }

    public C version(String v) {
        version = v;
        return this;
    }

    public C service() {
        type = Contract.TaskType.SERVICE;
        return this;
    }

    public C sporadic() {
        type = Contract.TaskType.SPORADIC;
        return this;
    }

    public C attr(String k, String v) {
        attrs.put(k, v);
        return this;
    }

    public C out(String port, String type) {
        return out(port, type, "1.0", PortSpec.Method.STATE);
    }

    public C out(String port, String type, String tv, PortSpec.Method m) {
        ports.add(new PortSpec(port, PortSpec.Direction.OUT, type, TypeVersion.parse(tv), m, 1,
                PortSpec.Overflow.DROP_OLDEST, Optional.empty(), false));
        return this;
    }

    public C in(String port, String type) {
        return in(port, type, "1.0", PortSpec.Method.STATE, Optional.empty(), false);
    }

    public C in(String port, String type, String tv, PortSpec.Method m, Optional<Binding> b, boolean optional) {
        ports.add(new PortSpec(port, PortSpec.Direction.IN, type, TypeVersion.parse(tv), m, 1,
                PortSpec.Overflow.DROP_OLDEST, b, optional));
        return this;
    }

    public C inFrom(String port, String type, String provider, String providerPort) {
        return in(port, type, "1.0", PortSpec.Method.STATE, Optional.of(Binding.explicit(provider, providerPort)), false);
    }

    public C inFilter(String port, String type, String filter) {
        return in(port, type, "1.0", PortSpec.Method.STATE, Optional.of(Binding.filter(filter)), false);
    }

    /** A safety input (contracts/SPEC.md §6.8): optional to start, its loss a HOLD. */
    public C inSafety(String port) {
        ports.add(new PortSpec(port, PortSpec.Direction.IN, "arflex.SafetyState", TypeVersion.parse("1.0"),
                PortSpec.Method.STATE, 1, PortSpec.Overflow.DROP_OLDEST, Optional.empty(), true, true));
        return this;
    }

    public C inOptional(String port, String type) {
        return in(port, type, "1.0", PortSpec.Method.STATE, Optional.empty(), true);
    }

    /** Periodic timing in ms (fractions allowed via ns overload). */
    public C timing(double periodMs, double deadlineMs, double wcetMs, int prio, Integer... cpus) {
        timing = new Timing((long) (periodMs * MS), (long) (deadlineMs * MS), (long) (wcetMs * MS), prio, List.of(cpus));
        return this;
    }

    /** Makes the timing exclusive (SPEC 8.6), keeping everything else. */
    public C exclusive() {
        timing = new Timing(timing.periodNs(), timing.deadlineNs(), timing.wcetNs(), timing.priority(), timing.cpus(),
                true);
        return this;
    }

    public C mem(long bytes) {
        mem = bytes;
        return this;
    }

    public C net(long bps) {
        net = bps;
        return this;
    }

    public C crit(int c) {
        crit = c;
        return this;
    }

    public Contract build() {
        return new Contract(name, version, "", name + "-rt", type, false, attrs, ports, List.of(), timing,
                new Resources(mem, net), crit,
                new FaultPolicy(FaultPolicy.Restart.PERMANENT, 3, 10_000, 100, FaultPolicy.SafeOutput.HOLD, 500),
                Optional.empty(), "test:" + name);
    }
}
