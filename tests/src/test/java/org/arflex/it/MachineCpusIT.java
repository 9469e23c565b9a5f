package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * Resources from the machine (issue 32, docs/decisions/D85): the runtime JVM runs in a cgroup v1
 * cpuset the test makes (its RT halves, spawned later, inherit it); taking CPU 1 out of that
 * cpuset re-plans the cell as an API change does, with the cause in the reasons, and returning it
 * restores what was shed. The contracts are the samples' with WCETs that make one CPU too small:
 * sample-counter 5 ms of 10 (criticality 5), sample-scaler 3 ms of 10 (3), debug-monitor 1 ms of
 * 20 with a 5 ms deadline (1). On two CPUs the monitor shares CPU 1 with the scaler (R = 4 ms);
 * on CPU 0 alone it would wait behind both (R = 9 ms) and is shed, the lowest criticality.
 */
class MachineCpusIT {

    static final long T = 30_000;

    static Path variants(Path dir) throws Exception {
        Files.createDirectories(dir);
        Jars.withContract(CellIT.COUNTER, dir.resolve("counter.jar"), x -> x.replace("wcet=\"200us\"", "wcet=\"5ms\""));
        Jars.withContract(CellIT.SCALER, dir.resolve("scaler.jar"), x -> x.replace("wcet=\"200us\"", "wcet=\"3ms\""));
        Jars.withContract(Components.jar("debug-monitor"), dir.resolve("monitor.jar"), x -> x.replace(
                "<timing period=\"20ms\" deadline=\"20ms\" wcet=\"200us\" priority=\"5\"/>",
                "<timing period=\"20ms\" deadline=\"5ms\" wcet=\"1ms\" priority=\"5\"/>"));
        return dir;
    }

    /** Starts a runtime and moves its JVM into {@code cs}; returns once the DRCR names that cpuset. */
    static Runtime inCpuset(String name, TestCpuset cs) throws Exception {
        Runtime rt = new Runtime(name);
        try {
            cs.add(rt.jvmPid());
            rt.waitUntil("the DRCR to see its cpuset " + cs.group(), T,
                    () -> rt.cmd("arflex:resources").contains("cpuset " + cs.group()));
            return rt;
        } catch (Exception | Error e) {
            rt.close();
            throw e;
        }
    }

    static int cpu(Runtime rt, String name) {
        return ((Number) rt.instance(name).get("cpu")).intValue();
    }

    static String reason(Runtime rt, String name) {
        Object r = rt.instance(name).get("failureReason");
        return r == null ? "" : r.toString();
    }

    /** Cpus_allowed_list of each thread of a process, by thread name. */
    static String allowed(long pid) throws Exception {
        StringBuilder sb = new StringBuilder();
        try (var tasks = Files.list(Path.of("/proc", Long.toString(pid), "task"))) {
            for (Path t : tasks.sorted().toList()) {
                String name = "";
                String cpus = "";
                for (String l : Files.readAllLines(t.resolve("status"))) {
                    if (l.startsWith("Name:")) {
                        name = l.substring(5).strip();
                    } else if (l.startsWith("Cpus_allowed_list:")) {
                        cpus = l.substring(18).strip();
                    }
                }
                sb.append(name).append("=").append(cpus).append(' ');
            }
        }
        return sb.toString().strip();
    }

    @Test
    void aCpuTakenFromTheRuntimesCpusetShedsTheLowestCriticalityAndItsReturnRestoresIt() throws Exception {
        String left = "cpu 1 left the runtime's cpuset ";
        try (TestCpuset cs = new TestCpuset("arflex-it-" + ProcessHandle.current().pid() + "-shed", "0-1");
                Runtime rt = inCpuset("machine-shed", cs)) {
            Path jars = variants(rt.dir.resolve("variants"));
            rt.installAndStart(jars.resolve("counter.jar"));
            rt.installAndStart(jars.resolve("scaler.jar"));
            rt.installAndStart(jars.resolve("monitor.jar"));
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler", "debug-monitor");
            assertEquals(Map.of("sample-counter", 0, "sample-scaler", 1, "debug-monitor", 1),
                    Map.of("sample-counter", cpu(rt, "sample-counter"), "sample-scaler", cpu(rt, "sample-scaler"),
                            "debug-monitor", cpu(rt, "debug-monitor")));
            long counter = rt.pid("sample-counter");
            long scaler = rt.pid("sample-scaler");

            cs.cpus("0");
            rt.waitUntil("debug-monitor shed, sample-scaler moved to cpu 0", T,
                    () -> "UNSATISFIED".equals(rt.state("debug-monitor")) && "ACTIVE".equals(rt.state("sample-scaler"))
                            && cpu(rt, "sample-scaler") == 0 && rt.pid("sample-scaler") != scaler);
            String why = reason(rt, "debug-monitor");
            assertTrue(why.startsWith("cpu 0: response time 9 ms of 'debug-monitor' exceeds deadline 5 ms (U=0.85)"), why);
            assertTrue(why.endsWith("; " + left + cs.group()), why);
            assertTrue(rt.cmd("arflex:list").contains(left + cs.group()), rt.cmd("arflex:list"));
            assertEquals("ACTIVE", rt.state("sample-counter"));
            assertEquals(counter, rt.pid("sample-counter"), "sample-counter kept its CPU and its half");
            assertTrue(rt.logContains("because " + left + cs.group()), rt.tail());
            assertTrue(rt.logContains("moved cpu 1 -> 0; " + left + cs.group()), rt.tail());
            String resources = rt.cmd("arflex:resources");
            assertTrue(resources.startsWith("cpus: 0(U=0.800)\n"), resources);
            assertTrue(resources.contains("\nmachine change: " + left + cs.group()), resources);

            cs.cpus("0-1");
            rt.awaitState("ACTIVE", T, "debug-monitor");
            assertEquals("", reason(rt, "debug-monitor"));
            assertEquals(1, cpu(rt, "debug-monitor"));
            assertEquals(counter, rt.pid("sample-counter"));
            assertEquals("ACTIVE", rt.state("sample-scaler"));
            assertTrue(rt.cmd("arflex:resources").contains("\nmachine change: cpu 1 joined the runtime's cpuset " + cs.group()),
                    rt.cmd("arflex:resources"));
            // for the record (D85): the DRCR's lines, and where the kernel left the counter's threads
            rt.logSince(0).stream().filter(l -> l.startsWith("err|") && (l.contains("arflex: machine") || l.contains("; cpu 1 ")))
                    .forEach(l -> System.out.println("MachineCpusIT: " + l));
            System.out.println("MachineCpusIT: sample-counter threads after the return: " + allowed(rt.pid("sample-counter")));
        }
    }

    @Test
    void aComponentThatDoesNotFitTheOneCpuTheMachineGivesIsRefusedWithItsResponseTime() throws Exception {
        try (TestCpuset cs = new TestCpuset("arflex-it-" + ProcessHandle.current().pid() + "-one", "0");
                Runtime rt = inCpuset("machine-one", cs)) {
            String resources = rt.cmd("arflex:resources");
            assertTrue(resources.startsWith("cpus: 0(U=0.000)\n"), resources);
            assertTrue(resources.contains("\nmachine change: cpu 1 is not in cpuset " + cs.group()
                    + ", which the runtime moved into from / (cgroup v1)"), resources);
            Path jars = variants(rt.dir.resolve("variants"));
            rt.installAndStart(jars.resolve("counter.jar"));
            rt.awaitState("ACTIVE", T, "sample-counter");
            rt.installAndStart(jars.resolve("monitor.jar"));
            rt.awaitState("UNSATISFIED", T, "debug-monitor");
            String why = reason(rt, "debug-monitor");
            assertEquals("cpu 0: response time 6 ms of 'debug-monitor' exceeds deadline 5 ms (U=0.55)", why);
            assertEquals(0L, rt.pid("debug-monitor"));
            assertTrue(Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("debug-monitor")),
                    Runtime.rtProcesses(rt.rid)::toString);
            assertNotEquals(0L, rt.pid("sample-counter"));
        }
    }
}
