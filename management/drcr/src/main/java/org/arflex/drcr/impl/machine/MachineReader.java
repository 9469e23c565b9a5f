package org.arflex.drcr.impl.machine;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.HashMap;
import java.util.Map;
import java.util.SortedSet;

/**
 * Reads what the machine gives this process ({@link MachineView}) from /proc and /sys under a
 * root (the real {@code /}, or a temporary tree in tests): the online CPUs, the process's cgroup
 * (from /proc/self/cgroup, found where /proc/self/mountinfo says the hierarchy is mounted), its
 * cpuset's effective CPUs (cgroup v1 {@code cpuset.effective_cpus}, v2 {@code
 * cpuset.cpus.effective}) and its memory limit (v1 {@code hierarchical_memory_limit} of
 * memory.stat, v2 the smallest {@code memory.max} of the cgroup and its ancestors). A v1
 * controller wins over v2 (hybrid hierarchies mount both). Cheap: a few small files per read.
 */
public final class MachineReader {

    /** cgroup v1 writes this (or a page-rounded value near it) for no limit. */
    private static final long NO_LIMIT = 1L << 60;

    private final Path root;

    /** @param root the file-system root the /proc and /sys paths are read under */
    public MachineReader(Path root) {
        this.root = root;
    }

    /** A hierarchy as /proc/self/mountinfo gives it: mount point and the cgroup path of its root. */
    private record Mount(Path point, String root) {
    }

    /**
     * Reads the machine now.
     *
     * @throws MachineReadException naming the file and what is wrong with it
     */
    public MachineView read() throws MachineReadException {
        SortedSet<Integer> online = cpus(file("sys/devices/system/cpu/online"));
        Map<String, String> groups = new HashMap<>(); // controller ("" for v2) -> cgroup path
        for (String line : lines(file("proc/self/cgroup"))) {
            String[] f = line.split(":", 3);
            if (f.length != 3 || !f[2].startsWith("/")) {
                throw new MachineReadException(file("proc/self/cgroup") + ": line '" + line
                        + "' is not <id>:<controllers>:<path>");
            }
            for (String c : f[1].split(",")) {
                groups.put(c, f[2]);
            }
        }
        Map<String, Mount> mounts = mounts(); // controller ("" for v2) -> mount
        SortedSet<Integer> cpuset = null;
        String cpusetGroup = null;
        Path v1 = dir(mounts, groups, "cpuset");
        Path v2 = dir(mounts, groups, "");
        if (v1 != null) {
            Path f = v1.resolve("cpuset.effective_cpus");
            cpuset = cpus(Files.exists(f) ? f : v1.resolve("cpuset.cpus"));
            cpusetGroup = groups.get("cpuset") + " (cgroup v1)";
        } else if (v2 != null && Files.exists(v2.resolve("cpuset.cpus.effective"))) {
            cpuset = cpus(v2.resolve("cpuset.cpus.effective"));
            cpusetGroup = groups.get("") + " (cgroup v2)";
        }
        long limit = -1;
        String memoryGroup = null;
        Path m1 = dir(mounts, groups, "memory");
        if (m1 != null) {
            memoryGroup = groups.get("memory") + " (cgroup v1)";
            limit = v1Limit(m1);
        } else if (v2 != null && Files.exists(v2.resolve("memory.max"))) {
            memoryGroup = groups.get("") + " (cgroup v2)";
            Path top = mounts.get("").point();
            for (Path d = v2; d != null && d.startsWith(top); d = d.getParent()) {
                Path f = d.resolve("memory.max");
                if (Files.exists(f)) {
                    String v = text(f).strip();
                    long l = v.equals("max") ? -1 : bytes(f, v);
                    if (l >= 0 && (limit < 0 || l < limit)) {
                        limit = l;
                    }
                }
            }
        }
        return new MachineView(online, cpuset, cpusetGroup, limit, memoryGroup);
    }

    private long v1Limit(Path dir) throws MachineReadException {
        Path stat = dir.resolve("memory.stat");
        String value = null;
        Path from = stat;
        if (Files.exists(stat)) {
            for (String l : lines(stat)) {
                if (l.startsWith("hierarchical_memory_limit ")) {
                    value = l.substring("hierarchical_memory_limit ".length()).strip();
                }
            }
        }
        if (value == null) {
            from = dir.resolve("memory.limit_in_bytes");
            value = text(from).strip();
        }
        long l = bytes(from, value);
        return l >= NO_LIMIT ? -1 : l;
    }

    private static long bytes(Path f, String v) throws MachineReadException {
        try {
            long l = Long.parseLong(v);
            if (l < 0) {
                throw new NumberFormatException();
            }
            return l;
        } catch (NumberFormatException e) {
            throw new MachineReadException(f + ": '" + v + "' is not a number of bytes");
        }
    }

    /** The directory of this process's cgroup for a controller ("" for v2), or null when not mounted. */
    private Path dir(Map<String, Mount> mounts, Map<String, String> groups, String controller) {
        Mount m = mounts.get(controller);
        String path = groups.get(controller);
        if (m == null || path == null) {
            return null;
        }
        String rel = path.startsWith(m.root()) ? path.substring(m.root().length()) : path;
        rel = rel.replaceFirst("^/+", "");
        Path d = rel.isEmpty() ? m.point() : m.point().resolve(rel);
        return Files.isDirectory(d) ? d : null;
    }

    private Map<String, Mount> mounts() throws MachineReadException {
        Map<String, Mount> out = new HashMap<>();
        Path f = file("proc/self/mountinfo");
        for (String line : lines(f)) {
            int dash = line.indexOf(" - ");
            String[] a = line.substring(0, Math.max(dash, 0)).split(" ");
            String[] b = dash < 0 ? new String[0] : line.substring(dash + 3).split(" ");
            if (dash < 0 || a.length < 5 || b.length < 3) {
                throw new MachineReadException(f + ": line '" + line + "' is not a mountinfo line");
            }
            Mount m = new Mount(root.resolve(unescape(a[4]).replaceFirst("^/+", "")), unescape(a[3]));
            if (b[0].equals("cgroup2")) {
                out.putIfAbsent("", m);
            } else if (b[0].equals("cgroup")) {
                for (String o : b[2].split(",")) {
                    if (o.equals("cpuset") || o.equals("memory")) {
                        out.putIfAbsent(o, m);
                    }
                }
            }
        }
        return out;
    }

    /** mountinfo escapes space, tab, newline and backslash as \ooo. */
    private static String unescape(String s) {
        StringBuilder sb = new StringBuilder();
        for (int i = 0; i < s.length(); i++) {
            char c = s.charAt(i);
            if (c == '\\' && i + 3 < s.length() && s.substring(i + 1, i + 4).chars().allMatch(d -> d >= '0' && d <= '7')) {
                sb.append((char) Integer.parseInt(s.substring(i + 1, i + 4), 8));
                i += 3;
            } else {
                sb.append(c);
            }
        }
        return sb.toString();
    }

    private SortedSet<Integer> cpus(Path f) throws MachineReadException {
        String t = text(f);
        try {
            return CpuList.parse(t);
        } catch (IllegalArgumentException e) {
            throw new MachineReadException(f + ": '" + t.strip() + "': " + e.getMessage());
        }
    }

    private Path file(String rel) {
        return root.resolve(rel);
    }

    private static java.util.List<String> lines(Path f) throws MachineReadException {
        return text(f).lines().filter(l -> !l.isBlank()).toList();
    }

    private static String text(Path f) throws MachineReadException {
        try {
            return Files.readString(f, StandardCharsets.UTF_8);
        } catch (IOException | java.io.UncheckedIOException e) {
            throw new MachineReadException("cannot read " + f + ": " + e);
        }
    }
}
