package org.arflex.drcr.impl.runtime;

import java.util.List;
import org.arflex.contract.Binding;
import org.arflex.contract.Filter;
import org.arflex.contract.PortSpec;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.lifecycle.State;

/**
 * Says in words why an instance holds the arm (or its outputs): from its control block's flags
 * and hold word, and the planner's wires for the provider of a safety input. Null when it does
 * not hold (SAFETY.md 5: "holding" is a state with a reason, never hidden behind ACTIVE).
 */
final class Holding {

    private static final String[] VERDICTS = {"normal", "limited", "in a protective stop", "without a provider",
        "bound, no value yet", "stale (no fresh value)", "invalid (value rejected)", "damaged (segment header changed)"};

    private static final String SAFETY_TYPE = "arflex.SafetyState";

    private static final String REFERENCE_TYPE = "arflex.JointRef";

    private Holding() {
    }

    static String reason(Cell cell, Instance i, int flags, int hold, boolean awaitingReset) {
        if ((flags & ControlBlock.FLAG_SUPERVISOR_LOST) != 0) {
            return "supervisor lost: holds, then exits (orphan)";
        }
        int cause = hold & 0xff;
        String why = null;
        if (cause == ControlBlock.HOLD_SAFETY_INPUT) {
            why = "protective stop: " + safetyInput(cell, i, (hold >> 8) & 0xff, (hold >> 16) & 0xff);
        } else if (cause == ControlBlock.HOLD_AWAIT_COMMAND && !awaitingReset) {
            why = "stopped: waits for a fresh command (" + freshCommand(i) + ") after the reset";
        } else if (cause == ControlBlock.HOLD_REFERENCE && ((hold >> 8) & 0xff) == ControlBlock.HOLD_REF_INVALID) {
            why = "holds the last valid reference: " + invalidInput(cell, i, (hold >> 16) & 0xff);
        } else if (cause == ControlBlock.HOLD_REFERENCE) {
            why = "holds: waits for a reference that meets the arm (after a stop: one at rest)";
        }
        if (awaitingReset) {
            String r = (flags & ControlBlock.FLAG_SAFE_ACTIVE) != 0 ? "safe mode, awaiting operator reset"
                    : "awaiting operator reset";
            return why == null ? r : why + "; " + r;
        }
        if (why == null && (flags & ControlBlock.FLAG_SAFE_ACTIVE) != 0) {
            why = "safe mode: runtime heartbeat lost";
        }
        return why;
    }

    /** What a fresh command is for this component: by the parameters its contract declares. */
    static String freshCommand(Instance i) {
        boolean run = i.contract.properties().stream().anyMatch(p -> p.name().equals("run"));
        boolean command = i.contract.properties().stream().anyMatch(p -> p.name().equals("command"));
        return run ? "set run true, or a program" : command ? "write its command again" : "a new command";
    }

    /** The reference input whose newest value was rejected (NaN, Inf, out of range), and its provider. */
    private static String invalidInput(Cell cell, Instance i, int index) {
        List<PortSpec> ins = i.contract.inputs();
        String port = index < ins.size() && !SAFETY_TYPE.equals(ins.get(index).type()) ? ins.get(index).name()
                : typedPort(ins, index, REFERENCE_TYPE);
        if (port == null) {
            return "input #" + index + " sends invalid values (NaN, Inf or out of range)";
        }
        String provider = null;
        for (var w : cell.planner().wires()) {
            if (w.consumer().equals(i.name) && w.inPort().equals(port)) {
                provider = w.provider();
            }
        }
        return "input '" + port + "' " + (provider == null ? "" : "from " + provider + " ")
                + "sends invalid values (NaN, Inf or out of range)";
    }

    private static String safetyInput(Cell cell, Instance i, int verdict, int index) {
        String v = verdict < VERDICTS.length ? VERDICTS[verdict] : "verdict " + verdict;
        String port = safetyPort(i.contract.inputs(), index);
        if (port == null) {
            return "safety input #" + index + " " + v;
        }
        String provider = null;
        for (var w : cell.planner().wires()) {
            if (w.consumer().equals(i.name) && w.inPort().equals(port)) {
                provider = w.provider();
            }
        }
        String p = "";
        if (provider != null) {
            String name = provider;
            String state = cell.instances().stream().filter(x -> x.name.equals(name)).findFirst()
                    .map(x -> " " + x.life.state() + (x.life.state() == State.ACTIVE || x.life.reason() == null ? ""
                            : ": " + x.life.reason())).orElse("");
            p = " (provider " + provider + state + ")";
        } else {
            PortSpec spec = i.contract.port(port).orElse(null);
            List<String> guards = cell.instances().stream().filter(x -> x != i && spec != null && guards(spec, x))
                    .map(x -> x.name + " " + x.life.state() + (x.life.reason() == null ? "" : ": " + x.life.reason()))
                    .toList();
            p = guards.isEmpty() ? " (no guard installed)" : " (guard " + String.join("; ", guards) + ")";
        }
        return "safety input '" + port + "' " + v + p;
    }

    /** Whether {@code x} could provide the safety input {@code in} (its type, and its binding rule). */
    private static boolean guards(PortSpec in, Instance x) {
        if (x.contract.outputs().stream().noneMatch(o -> SAFETY_TYPE.equals(o.type()))) {
            return false;
        }
        Binding b = in.binding().orElse(null);
        if (b == null) {
            return true;
        }
        if (b.component().isPresent()) {
            return b.component().get().equals(x.name);
        }
        try {
            return b.filter().map(f -> Filter.parse(f).matches(x.contract.attributes())).orElse(true);
        } catch (RuntimeException e) {
            return false;
        }
    }

    /**
     * The input the hold word names. Its index counts the inputs in the order the RT half
     * declared them, which need not be the contract's: the contract's input at that index is
     * taken when it is an arflex.SafetyState input, else the contract's only such input.
     */
    static String safetyPort(List<PortSpec> ins, int index) {
        return typedPort(ins, index, SAFETY_TYPE);
    }

    /** As {@link #safetyPort}, for an input of port type {@code type}. */
    static String typedPort(List<PortSpec> ins, int index, String type) {
        if (index < ins.size() && type.equals(ins.get(index).type())) {
            return ins.get(index).name();
        }
        List<PortSpec> typed = ins.stream().filter(p -> type.equals(p.type())).toList();
        return typed.size() == 1 ? typed.get(0).name() : null;
    }
}
