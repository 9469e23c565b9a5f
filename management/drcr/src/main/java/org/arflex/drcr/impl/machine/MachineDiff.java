package org.arflex.drcr.impl.machine;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Objects;
import java.util.TreeSet;

/**
 * The cause of a change of the machine, in one sentence for the plan's title and the components'
 * reasons: {@code cpu 1 left the runtime's cpuset /arflex-it (cgroup v1)}, {@code cpu 3 went
 * offline}, {@code memory limit of /x (cgroup v2) lowered from 1 GiB to 512 MiB}.
 */
public final class MachineDiff {

    private MachineDiff() {
    }

    /** What changed from {@code before} to {@code now}; null when nothing did. */
    public static String cause(MachineView before, MachineView now) {
        Map<String, List<Integer>> cpus = new LinkedHashMap<>();
        boolean moved = !Objects.equals(before.cpusetGroup(), now.cpusetGroup());
        String into = ", which the runtime moved into from " + before.cpusetGroup();
        sort(before.cpus(), now.cpus(), now.online(), "went offline",
                moved ? "not in cpuset " + now.cpusetGroup() + into : "left the runtime's cpuset " + now.cpusetGroup(), cpus);
        sort(now.cpus(), before.cpus(), before.online(), "came online",
                moved ? "in cpuset " + now.cpusetGroup() + into : "joined the runtime's cpuset " + now.cpusetGroup(), cpus);
        List<String> parts = new ArrayList<>();
        cpus.forEach((how, list) -> {
            boolean one = list.size() == 1;
            String verb = how.startsWith("not in") || how.startsWith("in ") ? (one ? "is " : "are ") : "";
            parts.add((one ? "cpu " : "cpus ") + CpuList.format(new TreeSet<>(list)) + " " + verb + how);
        });
        if (parts.isEmpty() && moved) {
            parts.add("the runtime moved from cpuset " + before.cpusetGroup() + " to " + now.cpusetGroup()
                    + " (same cpus " + CpuList.format(now.cpus()) + ")");
        }
        long a = before.memoryLimit();
        long b = now.memoryLimit();
        if (a != b) {
            String where = "memory limit of " + now.memoryGroup();
            parts.add(b < 0 ? where + " removed (was " + bytes(a) + ")"
                    : a < 0 ? where + " set to " + bytes(b)
                    : where + (b < a ? " lowered" : " raised") + " from " + bytes(a) + " to " + bytes(b));
        } else if (!Objects.equals(before.memoryGroup(), now.memoryGroup())) {
            parts.add("the runtime moved from memory cgroup " + before.memoryGroup() + " to " + now.memoryGroup());
        }
        return parts.isEmpty() ? null : String.join("; ", parts);
    }

    /**
     * Files each CPU of {@code from} that is not in {@code to} under how it went: {@code hotplug}
     * when {@code online} lacks it, else {@code cpuset}.
     */
    private static void sort(java.util.Set<Integer> from, java.util.Set<Integer> to, java.util.Set<Integer> online,
            String hotplug, String cpuset, Map<String, List<Integer>> out) {
        for (int c : from) {
            if (!to.contains(c)) {
                out.computeIfAbsent(online.contains(c) ? cpuset : hotplug, k -> new ArrayList<>()).add(c);
            }
        }
    }

    /** {@code 512 MiB}, {@code 1.5 GiB}, {@code 100 B}. */
    static String bytes(long b) {
        String[] units = {"B", "KiB", "MiB", "GiB", "TiB"};
        double v = b;
        int u = 0;
        while (v >= 1024 && u < units.length - 1) {
            v /= 1024;
            u++;
        }
        String s = String.format(Locale.ROOT, "%.2f", v).replaceAll("\\.?0+$", "");
        return s + " " + units[u];
    }
}
