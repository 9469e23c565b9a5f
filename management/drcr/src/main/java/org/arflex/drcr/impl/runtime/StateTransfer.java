package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import org.arflex.contract.Contract;
import org.arflex.contract.PortType;
import org.arflex.contract.PortTypes;
import org.arflex.contract.StateSpec;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.abi.PortSegment;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * State transfer (docs/DECISIONS.md D41, contract SPEC §12.1). A contract may declare a state
 * block, {@code <state type typeVersion>}: a value of a port type its RT half publishes every
 * cycle into {@code /arflex.<rid>.<id>.state} (created here with the instance's output
 * segments, closed with them). When a change set updates such a component, the plan checks
 * that the new version adopts the running version's state block (same type, a version that
 * feeds it, or a declared {@code <convertsFrom>}) and refuses the set naming both otherwise;
 * the new half is told the old half's state segment (ADOPT, after READY, before START) and
 * takes its newest value over at START, while the old half keeps running for the warm window
 * as before. A rollback needs nothing handed back: the old half never stopped.
 */
final class StateTransfer {

    private StateTransfer() {
    }

    /** The state segment of the RT half running under object id {@code id}. */
    static String segmentName(String runtimeId, String id) {
        return "/arflex." + runtimeId + "." + id + ".state";
    }

    /** Creates the instance's state segment when its contract declares a state and it has none (actor thread). */
    static void ensure(RtLauncher launcher, PortTypes types, String runtimeId, Instance inst) throws IOException {
        StateSpec st = inst.contract.state().orElse(null);
        if (st == null || inst.stateSegment != null) {
            return;
        }
        PortType t = types.find(st.type()).orElseThrow(() -> new IOException(
                "state block: port type " + st.type() + " is not known to this runtime"));
        inst.stateSegment = launcher.createOutput(segmentName(runtimeId, inst.objectId), PortSegment.METHOD_STATE,
                t.name(), t.version().major(), t.version().minor(), (int) t.size(), 1, PortSegment.OVERFLOW_NONE);
    }

    /** Closes (unlinks) the instance's state segment (actor thread). */
    static void close(Instance inst) {
        if (inst.stateSegment != null) {
            inst.stateSegment.close();
            inst.stateSegment = null;
        }
    }

    /**
     * Why the running version {@code old} cannot hand its state to {@code next}, or null. Null
     * too when {@code old} declares no state: there is nothing to hand over and the new half
     * starts from nothing, as every update did before D41.
     */
    static String problem(Contract old, Contract next) {
        StateSpec from = old.state().orElse(null);
        if (from == null) {
            return null;
        }
        StateSpec to = next.state().orElse(null);
        if (to == null) {
            return "state block: the running version " + old.version() + " hands over " + from + ", the new version "
                    + next.version() + " declares no state and would start from nothing";
        }
        if (!to.adopts(from.type(), from.typeVersion())) {
            return "state block: the running version " + old.version() + " hands over " + from + ", the new version "
                    + next.version() + " takes " + to + " and declares no conversion from " + from;
        }
        return null;
    }

    /**
     * Why the running half {@code inst} may not be replaced by a new version in a change set
     * because of a stop it holds, or null: it awaits an operator reset (the DRCR's own after a
     * restart, or RESET_REQUIRED on its control block: a latched protective stop) and its version
     * declares no state block, so the new half would start from nothing, i.e. without the stop
     * (docs/DECISIONS.md D52: fail closed). A running version with a state hands the latch over
     * (force-guard's adopt hook latches the new half).
     */
    static String latchProblem(Instance inst) {
        if (inst.contract.state().isPresent()) {
            return null;
        }
        boolean awaiting = inst.awaitingReset
                || (inst.half != null && (inst.half.flags() & ControlBlock.FLAG_RESET_REQUIRED) != 0);
        return !awaiting ? null : "'" + inst.name + "' awaits an operator reset and its running version "
                + inst.contract.version() + " hands over no state block: a new half would start without the stop; "
                + "reset it first, or update it outside a change set";
    }

    /**
     * Why the two versions of a component that moves hardware may not run side by side for an
     * update's window, or null when they may: both send their motion only through their outputs
     * (SPEC §4.3 {@code motionThrough="outputs"}: the consumers read one of them, a device of its
     * own would be driven by both) and both declare a state block, so the new half continues
     * the old one's motion. A contract that does not say where its motion goes drives a device
     * itself: fail closed.
     */
    static String besideProblem(Contract old, Contract next) {
        for (Contract c : new Contract[] {old, next}) {
            if (c.movesHardware() && !c.motionThroughOutputs()) {
                return "version " + c.version() + " drives its device itself (implementation/@motionThrough is not "
                        + "\"outputs\"): a new half would drive it beside the old one";
            }
        }
        for (Contract c : new Contract[] {old, next}) {
            if (c.state().isEmpty()) {
                return "version " + c.version() + " declares no state block (§12.1): a new half would drive it beside "
                        + "the old one without continuing its motion";
            }
        }
        return null;
    }

    /** The state segment the new half {@code next} adopts at START: the running half's, or null. */
    static String source(Instance old, Instance next) {
        if (old == null || old.stateSegment == null || next.contract.state().isEmpty()) {
            return null;
        }
        return old.stateSegment.name();
    }
}
