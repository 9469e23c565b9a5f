package org.arflex.drcr.impl.machine;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Set;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The machine watch over a fake /proc and /sys tree (D85). */
class MachineWatchTest {

    @TempDir
    Path root;

    private final List<String> causes = new ArrayList<>();
    private final List<MachineView> views = new ArrayList<>();
    private final List<String> log = new ArrayList<>();

    private MachineWatch watch(FakeMachine m) throws Exception {
        MachineReader r = new MachineReader(m.root);
        return new MachineWatch(r, r.read(), (before, now, cause) -> {
            causes.add(cause);
            views.add(now);
        }, log::add);
    }

    @Test
    void aCpuLeavingTheCpusetIsReportedWithItsCauseAndItsReturnToo() throws Exception {
        FakeMachine m = FakeMachine.v1(root);
        MachineWatch w = watch(m);
        assertEquals(Set.of(0, 1), w.last().cpus());
        assertNull(w.poll(), "nothing changed");
        m.set("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus", "0\n");
        assertEquals("cpu 1 left the runtime's cpuset /arflex-it (cgroup v1)", w.poll());
        assertEquals(Set.of(0), views.get(0).cpus());
        assertNull(w.poll(), "reported once");
        m.set("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus", "0-1\n");
        assertEquals("cpu 1 joined the runtime's cpuset /arflex-it (cgroup v1)", w.poll());
        assertEquals(Set.of(0, 1), views.get(1).cpus());
        assertEquals(2, causes.size());
        assertTrue(log.get(0).startsWith("arflex: machine: cpu 1 left the runtime's cpuset /arflex-it (cgroup v1): now cpus 0"),
                log::toString);
    }

    @Test
    void aCpuGoingOfflineIsNamedSo() throws Exception {
        FakeMachine m = FakeMachine.v1(root);
        MachineWatch w = watch(m);
        m.set("sys/devices/system/cpu/online", "0\n");
        m.set("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus", "0\n");
        assertEquals("cpu 1 went offline", w.poll());
    }

    @Test
    void aLoweredMemoryLimitIsReported() throws Exception {
        FakeMachine m = FakeMachine.v1(root);
        MachineWatch w = watch(m);
        assertEquals(-1, w.last().memoryLimit());
        m.set("sys/fs/cgroup/memory/job/memory.stat", "hierarchical_memory_limit 536870912\n");
        assertEquals("memory limit of /job (cgroup v1) set to 512 MiB", w.poll());
        m.set("sys/fs/cgroup/memory/job/memory.stat", "hierarchical_memory_limit 268435456\n");
        assertEquals("memory limit of /job (cgroup v1) lowered from 512 MiB to 256 MiB", w.poll());
        assertEquals(268435456L, views.get(1).memoryLimit());
    }

    @Test
    void cgroupV2CpusetAndTheSmallestMemoryMaxOfTheAncestors() throws Exception {
        FakeMachine m = FakeMachine.v2(root);
        MachineWatch w = watch(m);
        assertEquals(Set.of(0, 1, 2, 3), w.last().cpus());
        assertEquals(1L << 30, w.last().memoryLimit());
        m.set("sys/fs/cgroup/app/svc/cpuset.cpus.effective", "0-1\n");
        m.set("sys/fs/cgroup/app/svc/memory.max", "536870912\n");
        assertEquals("cpus 2-3 left the runtime's cpuset /app/svc (cgroup v2); memory limit of /app/svc (cgroup v2) "
                + "lowered from 1 GiB to 512 MiB", w.poll());
    }

    @Test
    void aMalformedFileIsAClearErrorLoggedOnceAndTheLastGoodViewIsKept() throws Exception {
        FakeMachine m = FakeMachine.v1(root);
        MachineWatch w = watch(m);
        m.set("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus", "0-x\n");
        assertNull(w.poll());
        assertNull(w.poll());
        Path f = root.resolve("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus");
        assertEquals(List.of("arflex: machine: " + f + ": '0-x': '0-x' is not a CPU number or range (expected e.g. 0,2-3); "
                + "keeping cpus 0-1 (online 0-1, cpuset /arflex-it (cgroup v1): 0-1), memory limit none (memory /job (cgroup v1))"),
                log);
        assertEquals(Set.of(0, 1), w.last().cpus());
        assertTrue(w.problem().startsWith(f.toString()), w.problem());
        assertTrue(causes.isEmpty());
        // readable again, with a change made meanwhile: reported against the last good view
        m.set("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus", "1\n");
        assertEquals("cpu 0 left the runtime's cpuset /arflex-it (cgroup v1)", w.poll());
        assertNull(w.problem());
    }

    @Test
    void aChangeTheListenerFailedToApplyIsTriedAgain() throws Exception {
        FakeMachine m = FakeMachine.v1(root);
        MachineReader r = new MachineReader(m.root);
        int[] calls = {0};
        MachineWatch w = new MachineWatch(r, r.read(), (b, n, c) -> {
            if (calls[0]++ == 0) {
                throw new IllegalStateException("actor busy");
            }
        }, log::add);
        m.set("sys/fs/cgroup/cpuset/arflex-it/cpuset.effective_cpus", "0\n");
        assertThrows(IllegalStateException.class, w::poll);
        assertEquals(Set.of(0, 1), w.last().cpus());
        assertEquals("cpu 1 left the runtime's cpuset /arflex-it (cgroup v1)", w.poll());
        assertEquals(Set.of(0), w.last().cpus());
    }

    @Test
    void theRuntimeMovedToAnotherCpuset() throws Exception {
        FakeMachine m = FakeMachine.v1(root);
        MachineWatch w = watch(m);
        m.set("proc/self/cgroup", "4:memory:/job\n3:cpuset:/half\n0::/\n");
        m.set("sys/fs/cgroup/cpuset/half/cpuset.effective_cpus", "1\n");
        assertEquals("cpu 0 is not in cpuset /half (cgroup v1), which the runtime moved into from /arflex-it (cgroup v1)",
                w.poll());
    }

    @Test
    void cpuListsParseStrictlyAndPrintCompactly() {
        assertEquals(Set.of(0, 2, 3, 4), CpuList.parse("0,2-4\n"));
        assertEquals(Set.of(), CpuList.parse("\n"));
        assertEquals("0,2-4", CpuList.format(Set.of(4, 0, 3, 2)));
        assertEquals("CPU range '3-1' runs backwards",
                assertThrows(IllegalArgumentException.class, () -> CpuList.parse("3-1")).getMessage());
        assertEquals("CPU 99999 in '0-99999' is above 8191",
                assertThrows(IllegalArgumentException.class, () -> CpuList.parse("0-99999")).getMessage());
        assertThrows(IllegalArgumentException.class, () -> CpuList.parse("0,,1"));
    }
}
