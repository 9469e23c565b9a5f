package org.arflex.drcr.impl.services;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Optional;
import org.arflex.contract.Binding;
import org.arflex.contract.Contract;
import org.arflex.contract.Filter;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.contract.PortTypes;
import org.arflex.planner.Wire;

/**
 * The port-format check of a deployment set (docs/DECISIONS.md D45), before anything is
 * installed or spawned: each new contract's inputs and outputs against the peers they will be
 * bound to in the cell the set makes. A port's format is what its contract declares (SPEC §6.2,
 * §6.3): its type, the type version it was built against, and its method; a provider feeds a
 * consumer when the types and methods are equal and the provider's version can feed the
 * consumer's (§13.4). The resolver applies the same rule, but there a mismatch only shows as a
 * consumer that loses its provider, or a new component left without one; here it is a refusal
 * naming the component, the port, the peer and both formats.
 *
 * <p>Checked:
 * <ul>
 * <li>an update, against the wires of the running cell: every consumer bound to one of its
 * outputs still gets that output in a format it reads (the output still exists), and every
 * provider bound to one of its inputs still feeds the new input;</li>
 * <li>a new component: each input bound explicitly ({@code <bind component port>}) to a peer
 * that has such an output in a format it reads; each required input bound by type or filter has
 * at least one provider in its format when it has candidates of the same type name; and every
 * running consumer that names one of its outputs explicitly reads that output's format.</li>
 * </ul>
 * The peers are taken as they will be after the set (a peer updated by the same set with its
 * new contract; a component the set uninstalls is no peer, D50). Pure: no cell, no I/O.
 */
public final class PortFormats {

    private final PortTypes types;

    /** @param types the port type registry, to list the fields of a type in messages (null: not listed) */
    public PortFormats(PortTypes types) {
        this.types = types;
    }

    /**
     * The problems of the set, one line each, empty when every format fits.
     *
     * @param running  the contracts of the cell's components now
     * @param wires    the cell's wires now
     * @param installs the contracts the set installs
     * @param updates  the new contracts of the components the set updates
     */
    public List<String> check(List<Contract> running, List<Wire> wires, List<Contract> installs, List<Contract> updates) {
        return check(running, wires, installs, updates, java.util.Set.of());
    }

    /**
     * As {@link #check(List, List, List, List)}, with the components the set uninstalls: they are
     * no peers after the set (their wires go, no new input may name them).
     */
    public List<String> check(List<Contract> running, List<Wire> wires, List<Contract> installs, List<Contract> updates,
                              java.util.Set<String> uninstalls) {
        Map<String, Contract> after = new LinkedHashMap<>();
        running.stream().filter(c -> !uninstalls.contains(c.name())).forEach(c -> after.put(c.name(), c));
        updates.forEach(c -> after.put(c.name(), c));
        installs.forEach(c -> after.put(c.name(), c));
        Map<String, Contract> updated = new LinkedHashMap<>();
        updates.forEach(c -> updated.put(c.name(), c));
        List<String> problems = new ArrayList<>();
        for (Contract u : updates) {
            for (Wire w : wires) {
                if (w.provider().equals(u.name())) {
                    Contract consumer = after.get(w.consumer());
                    Optional<PortSpec> in = consumer == null ? Optional.empty() : consumer.port(w.inPort());
                    if (in.isEmpty()) {
                        continue; // the consumer is updated too and no longer has that input
                    }
                    Optional<PortSpec> out = u.port(w.outPort()).filter(p -> p.direction() == PortSpec.Direction.OUT);
                    if (out.isEmpty()) {
                        problems.add("update " + u.name() + " " + u.version() + ": output '" + w.outPort()
                                + "' is gone, but " + w.target() + " reads it (" + format(in.get()) + ")");
                    } else if (!feeds(out.get(), in.get())) {
                        problems.add("update " + u.name() + " " + u.version() + ": output '" + w.outPort() + "' changes to "
                                + format(out.get()) + ", but its peer " + w.target() + (updated.containsKey(w.consumer())
                                ? " (updated by the set)" : " (running)") + " reads " + format(in.get()) + mismatch(out.get(), in.get()));
                    }
                }
                if (w.consumer().equals(u.name())) {
                    Optional<PortSpec> in = u.port(w.inPort()).filter(p -> p.direction() == PortSpec.Direction.IN);
                    Contract provider = after.get(w.provider());
                    Optional<PortSpec> out = provider == null ? Optional.empty() : provider.port(w.outPort());
                    if (in.isEmpty() || out.isEmpty()) {
                        continue; // the input is dropped, or the provider's side is reported above
                    }
                    if (updated.containsKey(w.provider())) {
                        continue; // both ends are new: reported from the provider's side
                    }
                    if (!feeds(out.get(), in.get())) {
                        problems.add("update " + u.name() + " " + u.version() + ": input '" + w.inPort() + "' changes to "
                                + format(in.get()) + ", but its peer " + w.source() + " (running) writes "
                                + format(out.get()) + mismatch(out.get(), in.get()));
                    }
                }
            }
        }
        for (Contract n : installs) {
            for (PortSpec in : n.inputs()) {
                problems.addAll(input(n, in, after, uninstalls));
            }
            for (PortSpec out : n.outputs()) {
                for (Contract c : after.values()) {
                    for (PortSpec in : c.inputs()) {
                        Optional<Binding> b = in.binding();
                        if (c != n && b.isPresent() && b.get().component().filter(n.name()::equals).isPresent()
                                && b.get().port().filter(out.name()::equals).isPresent() && !feeds(out, in)) {
                            problems.add("install " + n.name() + " " + n.version() + ": output '" + out.name() + "' is "
                                    + format(out) + ", but its peer " + c.name() + "." + in.name() + " names it and reads "
                                    + format(in) + mismatch(out, in));
                        }
                    }
                }
            }
        }
        return problems;
    }

    /** A new component's input against the providers it can be bound to. */
    private List<String> input(Contract n, PortSpec in, Map<String, Contract> after, java.util.Set<String> uninstalls) {
        String head = "install " + n.name() + " " + n.version() + ": input '" + in.name() + "' (" + format(in) + ")";
        Optional<Binding> b = in.binding();
        if (b.isPresent() && b.get().component().isPresent()) {
            String peer = b.get().component().get();
            String port = b.get().port().orElse("");
            Contract p = after.get(peer);
            if (p == null && uninstalls.contains(peer)) {
                return List.of(head + " names its peer " + peer + "." + port + ", but the set uninstalls " + peer);
            }
            if (p == null) {
                return List.of(); // not in the cell: the planner says so
            }
            Optional<PortSpec> out = p.port(port).filter(o -> o.direction() == PortSpec.Direction.OUT);
            if (out.isEmpty()) {
                return List.of(head + " names its peer " + peer + "." + port + ", but " + peer + " " + p.version()
                        + " has no output '" + port + "'");
            }
            if (!feeds(out.get(), in)) {
                return List.of(head + " names its peer " + peer + "." + port + ", which writes " + format(out.get())
                        + mismatch(out.get(), in));
            }
            return List.of();
        }
        if (in.optional() || in.safety()) {
            return List.of(); // may stay unbound; the planner shows it
        }
        Filter filter;
        try {
            filter = b.flatMap(Binding::filter).map(Filter::parse).orElse(null);
        } catch (IllegalArgumentException e) {
            return List.of(); // the contract reader refused it already
        }
        List<String> near = new ArrayList<>();
        for (Contract p : after.values()) {
            if (p == n || (filter != null && !filter.matches(p.attributes()))) {
                continue;
            }
            for (PortSpec out : p.outputs()) {
                if (!out.type().equals(in.type())) {
                    continue;
                }
                if (feeds(out, in)) {
                    return List.of(); // a provider in its format: the planner picks one
                }
                near.add(p.name() + "." + out.name() + " writes " + format(out) + mismatch(out, in));
            }
        }
        return near.isEmpty() ? List.of()
                : List.of(head + " has no provider in its format; its peers of that type: " + String.join("; ", near));
    }

    /** True when {@code out} feeds {@code in} (SPEC §6.2, §13.4; the resolver's rule). */
    static boolean feeds(PortSpec out, PortSpec in) {
        return out.type().equals(in.type()) && out.method() == in.method() && out.typeVersion().canFeed(in.typeVersion());
    }

    /** {@code arflex.JointRef 1.0 state}. */
    static String format(PortSpec p) {
        return p.type() + " " + p.typeVersion() + " " + p.method().name().toLowerCase(Locale.ROOT);
    }

    /** What differs, in words, with the fields of two different types when they are known. */
    private String mismatch(PortSpec out, PortSpec in) {
        if (!out.type().equals(in.type())) {
            return " (another type" + fields(out.type(), "written") + fields(in.type(), "read") + ")";
        }
        if (out.method() != in.method()) {
            return " (method " + out.method().name().toLowerCase(Locale.ROOT) + " is not "
                    + in.method().name().toLowerCase(Locale.ROOT) + ")";
        }
        if (out.typeVersion().major() != in.typeVersion().major()) {
            return " (major version " + out.typeVersion().major() + " is not " + in.typeVersion().major() + ")";
        }
        return " (version " + out.typeVersion() + " lacks what " + in.typeVersion() + " added)";
    }

    private String fields(String type, String how) {
        if (types == null) {
            return "";
        }
        Optional<PortType> t = types.find(type);
        if (t.isEmpty()) {
            return "";
        }
        List<String> f = t.get().fields().stream().filter(x -> !x.padding())
                .map(x -> x.array() ? x.name() + "[" + x.count() + "]" : x.name()).toList();
        return "; " + how + ": " + type + " {" + String.join(", ", f) + "}";
    }
}
