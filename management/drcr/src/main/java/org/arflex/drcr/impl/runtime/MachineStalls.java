package org.arflex.drcr.impl.runtime;

import java.util.HashMap;
import java.util.LinkedHashSet;
import java.util.Map;
import java.util.Set;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.abi.ControlBlock;

/**
 * Which late cycles of an update's two halves were the machine's (D73). On a kernel that does
 * not preempt its system calls, or in a virtual machine whose CPU is not always run, one stall
 * of a CPU makes every loop on it late that was due in it: the old half, the new half and the
 * halves beside them lose cycles together (measured: 29 late cycles of the new half, 31 of the
 * old and 25 of sim-robot in the same 1000 ms, look by look the same bursts). A look (10 ms) in
 * which a half of a higher priority on the new half's CPU lost a cycle, or the look before it
 * (a stall across two looks), is a stall: the late cycles of both halves in it are the
 * machine's. Only a higher priority: it preempts the new half, so nothing the new half does
 * makes it late (the old half, at the same priority and CPU, can be delayed by a slow new one).
 * A version that is late by itself is late in looks without a stall too, and is still judged on
 * them. Actor thread.
 */
final class MachineStalls {
    private final Cell cell;
    private final Instance next;
    /** Late cycles last seen of each half of a higher priority on the CPU, by object id. */
    private final Map<String, Long> seen = new HashMap<>();
    /** The halves whose late cycles made a look a stall, in the order seen. */
    private final Set<String> stalled = new LinkedHashSet<>();
    private boolean stallBefore;
    private long newMachine;
    private long oldMachine;
    private long oldBehindNew;
    private final Instance old;

    MachineStalls(Cell cell, Instance next, Instance old) {
        this.cell = cell;
        this.next = next;
        this.old = old;
    }

    /** From now on: nothing counted, the other halves' counters taken as they are. */
    void baseline() {
        seen.clear();
        stalled.clear();
        stallBefore = false;
        newMachine = 0;
        oldMachine = 0;
        oldBehindNew = 0;
        lostSinceLastLook();
    }

    /**
     * One look, after both halves' counters were read: {@code newLate} and {@code oldLate} late
     * cycles of the new and the old half since the last look.
     */
    void look(long newLate, long oldLate) {
        boolean stall = lostSinceLastLook();
        if (stall || stallBefore) {
            newMachine += newLate;
            oldMachine += oldLate;
        } else if (newLate > 0 && newCanDelayOld()) {
            oldBehindNew += oldLate;
        }
        stallBefore = stall;
    }

    /**
     * The old half's late cycles, outside the machine's stalls, in looks in which the new half
     * was late too, when the new half can delay it (the same CPU, the old one's priority not
     * above the new one's: a FIFO half runs its cycle to its end before another of its
     * priority): they may be the new half's doing and are not set against its own. Measured:
     * a version late in every 10th cycle had the old half late as often (71 and 73 in 706
     * cycles) and was committed.
     */
    long oldBehindNew() {
        return oldBehindNew;
    }

    private boolean newCanDelayOld() {
        return next.cpu < 0 || old.cpu < 0 || next.cpu == old.cpu
                && old.contract.timing().priority() <= next.contract.timing().priority();
    }

    /** The new half's late cycles counted as the machine's since the baseline. */
    long newMachine() {
        return newMachine;
    }

    /** The old half's late cycles counted as the machine's since the baseline. */
    long oldMachine() {
        return oldMachine;
    }

    /** Who showed the stalls, e.g. {@code "sim-robot (priority 80)"}, or null when none was seen. */
    String witnesses() {
        return stalled.isEmpty() ? null : String.join(" or ", stalled);
    }

    /** The CPU of the new half, -1 when not pinned. */
    int cpu() {
        return next.cpu;
    }

    private boolean lostSinceLastLook() {
        int cpu = next.cpu;
        if (cpu < 0) {
            return false;
        }
        int priority = next.contract.timing().priority();
        boolean lost = false;
        for (Instance i : cell.instances()) {
            Contract c = i.contract;
            if (i.name.equals(next.name) || i.half == null || i.cpu != cpu || c.taskType() == Contract.TaskType.SERVICE
                    || c.timing().priority() <= priority) {
                continue;
            }
            ControlBlock.Stats s = CycleCounts.stats(i.half, i);
            if (s == null) {
                continue;
            }
            long late = LateCycles.of(s, c.taskType());
            Long before = seen.put(i.objectId, late);
            if (before != null && late > before) {
                lost = true;
                stalled.add(i.name + " (priority " + c.timing().priority() + ")");
            }
        }
        return lost;
    }
}
