package org.arflex.it;

import static org.junit.jupiter.api.Assertions.fail;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;

/**
 * A cgroup v1 cpuset made for one test under {@code /sys/fs/cgroup/cpuset} (made as
 * scripts/rt-shield.sh makes its own: cpuset.mems copied from the root before the CPUs are
 * written). A process moved in takes its later children with it (they inherit the cgroup).
 * {@link #close()} moves whatever is left back to the root and removes the cgroup.
 */
final class TestCpuset implements AutoCloseable {

    static final Path ROOT = Path.of("/sys/fs/cgroup/cpuset");

    final String name;
    final Path dir;

    /** Makes the cpuset {@code /name} with these CPUs (e.g. "0-1"); fails the test where there is no v1 cpuset to write. */
    TestCpuset(String name, String cpus) throws IOException {
        if (!Files.isWritable(ROOT.resolve("cgroup.procs"))) {
            fail("no writable cgroup v1 cpuset hierarchy at " + ROOT + " (the test needs root and cgroup v1 cpusets)");
        }
        this.name = name;
        this.dir = ROOT.resolve(name);
        Files.createDirectory(dir);
        write("cpuset.mems", Files.readString(ROOT.resolve("cpuset.mems")).strip());
        cpus(cpus);
    }

    /** The cgroup path as /proc/self/cgroup shows it, with the version, as the DRCR names it. */
    String group() {
        return "/" + name + " (cgroup v1)";
    }

    /** Sets the cpuset's CPUs (the kernel moves its tasks off the CPUs taken away). */
    void cpus(String cpus) throws IOException {
        write("cpuset.cpus", cpus);
    }

    /** Moves a process (every thread of it) into this cpuset. */
    void add(long pid) throws IOException {
        write("cgroup.procs", Long.toString(pid));
    }

    private void write(String file, String value) throws IOException {
        Files.writeString(dir.resolve(file), value);
    }

    @Override
    public void close() throws IOException {
        if (!Files.isDirectory(dir)) {
            return;
        }
        for (String pid : Files.readString(dir.resolve("cgroup.procs")).split("\\s+")) {
            if (!pid.isBlank()) {
                try {
                    Files.writeString(ROOT.resolve("cgroup.procs"), pid);
                } catch (IOException e) {
                    // it ended meanwhile
                }
            }
        }
        Files.delete(dir); // rmdir: a cgroup's control files go with it
    }
}
