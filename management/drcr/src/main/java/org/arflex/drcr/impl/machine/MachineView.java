package org.arflex.drcr.impl.machine;

import java.util.Collections;
import java.util.SortedSet;
import java.util.TreeSet;

/**
 * What the machine gives the runtime at one moment: its online CPUs, the CPUs of its cgroup
 * cpuset and its cgroup memory limit, with the cgroup each comes from. Immutable.
 *
 * @param online      the online CPUs (/sys/devices/system/cpu/online)
 * @param cpuset      the effective CPUs of the runtime's cpuset, null when no cpuset controller
 *                    applies to it
 * @param cpusetGroup the cpuset's cgroup, e.g. {@code /arflex-it (cgroup v1)}; null with no cpuset
 * @param memoryLimit the memory limit in bytes, -1 for none
 * @param memoryGroup the memory cgroup the limit is read from, null with no memory controller
 */
public record MachineView(SortedSet<Integer> online, SortedSet<Integer> cpuset, String cpusetGroup, long memoryLimit,
        String memoryGroup) {

    public MachineView {
        online = Collections.unmodifiableSortedSet(new TreeSet<>(online));
        cpuset = cpuset == null ? null : Collections.unmodifiableSortedSet(new TreeSet<>(cpuset));
    }

    /** The CPUs the runtime may use: online and in its cpuset. */
    public SortedSet<Integer> cpus() {
        TreeSet<Integer> c = new TreeSet<>(online);
        if (cpuset != null) {
            c.retainAll(cpuset);
        }
        return Collections.unmodifiableSortedSet(c);
    }

    /** For the log and arflex:resources: {@code cpus 0 (online 0-1, cpuset /x (cgroup v1): 0), memory limit none (...)}. */
    public String describe() {
        return "cpus " + CpuList.format(cpus()) + " (online " + CpuList.format(online)
                + (cpuset == null ? ", no cpuset" : ", cpuset " + cpusetGroup + ": " + CpuList.format(cpuset)) + "), memory limit "
                + (memoryLimit < 0 ? "none" : MachineDiff.bytes(memoryLimit))
                + (memoryGroup == null ? " (no memory cgroup)" : " (memory " + memoryGroup + ")");
    }
}
