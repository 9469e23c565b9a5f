package org.arflex.drcr.impl.machine;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;

/** A /proc and /sys tree in a temporary folder, as a cgroup v1 or v2 machine writes it. */
final class FakeMachine {
    final Path root;
    final Path group;

    private FakeMachine(Path root, Path group) {
        this.root = root;
        this.group = group;
    }

    /** cgroup v1: the process in cpuset /arflex-it and memory /job, 2 CPUs online, no memory limit. */
    static FakeMachine v1(Path root) throws IOException {
        write(root, "sys/devices/system/cpu/online", "0-1\n");
        write(root, "proc/self/cgroup", "4:memory:/job\n3:cpuset:/arflex-it\n0::/\n");
        write(root, "proc/self/mountinfo", """
                22 1 0:20 / /sys rw,nosuid - sysfs sysfs rw
                30 22 0:26 / /sys/fs/cgroup/unified rw - cgroup2 cgroup2 rw
                31 22 0:27 / /sys/fs/cgroup/cpuset rw - cgroup cgroup rw,cpuset
                32 22 0:28 / /sys/fs/cgroup/memory rw - cgroup cgroup rw,memory
                """);
        Files.createDirectories(root.resolve("sys/fs/cgroup/unified"));
        FakeMachine m = new FakeMachine(root, root.resolve("sys/fs/cgroup/cpuset/arflex-it"));
        m.set("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus", "0-1");
        m.set("sys/fs/cgroup/memory/job/memory.stat", "cache 0\nhierarchical_memory_limit 9223372036854771712\n");
        return m;
    }

    /** cgroup v2 only: the process in /app/svc, cpus 0-3, memory.max max in svc and 1 GiB in app. */
    static FakeMachine v2(Path root) throws IOException {
        write(root, "sys/devices/system/cpu/online", "0-3\n");
        write(root, "proc/self/cgroup", "0::/app/svc\n");
        write(root, "proc/self/mountinfo", "30 22 0:26 / /sys/fs/cgroup rw - cgroup2 cgroup2 rw\n");
        FakeMachine m = new FakeMachine(root, root.resolve("sys/fs/cgroup/app/svc"));
        m.set("sys/fs/cgroup/app/svc/cpuset.cpus.effective", "0-3\n");
        m.set("sys/fs/cgroup/app/svc/memory.max", "max\n");
        m.set("sys/fs/cgroup/app/memory.max", "1073741824\n");
        return m;
    }

    void set(String rel, String text) throws IOException {
        write(root, rel, text);
    }

    private static void write(Path root, String rel, String text) throws IOException {
        Path f = root.resolve(rel);
        Files.createDirectories(f.getParent());
        Files.writeString(f, text);
    }
}
