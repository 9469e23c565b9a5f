package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * {@code scripts/trace/rt-blame.py} (docs/DECISIONS.md D59) on a trace written here in ftrace's
 * text format: a 1 kHz SCHED_FIFO loop that runs on time, then once is woken on time but gets its
 * CPU only when a linker leaves the kernel (held), once is woken late with nothing on its CPU
 * (late-wake), and once runs 3 ms in one go (long-run). Each is named; the on-time runs are not.
 */
class RtBlameTest {

    static final Path SCRIPT = Components.root().resolve("scripts/trace/rt-blame.py");
    static final int LOOP = 4242;

    private final List<String> lines = new ArrayList<>();

    private void event(String comm, int pid, int cpu, double t, String what) {
        lines.add(String.format(Locale.ROOT, "%16s-%-7d (%7d) [%03d] d..2. %.6f: %s", comm, pid, pid, cpu, t, what));
    }

    private void wake(String current, int currentPid, double t) {
        event(current, currentPid, 0, t, "sched_wakeup: comm=sim-robot pid=" + LOOP + " prio=19 target_cpu=000");
    }

    private void in(String from, int fromPid, double t) {
        event(from, fromPid, 0, t, "sched_switch: prev_comm=" + from + " prev_pid=" + fromPid
                + " prev_prio=120 prev_state=R ==> next_comm=sim-robot next_pid=" + LOOP + " next_prio=19");
    }

    private void out(double t) {
        event("sim-robot", LOOP, 0, t, "sched_switch: prev_comm=sim-robot prev_pid=" + LOOP
                + " prev_prio=19 prev_state=S ==> next_comm=swapper/0 next_pid=0 next_prio=120");
    }

    /** One cycle: woken at t, runs at t + 10 us for 30 us. */
    private void cycle(double t) {
        wake("swapper/0", 0, t);
        in("swapper/0", 0, t + 10e-6);
        out(t + 40e-6);
    }

    @Test
    void namesWhatHeldTheLoop(@TempDir Path dir) throws Exception {
        double t = 100.0;
        for (int i = 0; i < 5; i++, t += 1e-3) {
            cycle(t);
        }
        // held: woken on time while ld is on the CPU, runs 4 ms later
        wake("ld", 777, t);
        in("ld", 777, t + 4e-3);
        out(t + 4.03e-3);
        t += 5e-3;
        for (int i = 0; i < 3; i++, t += 1e-3) {
            cycle(t);
        }
        // late-wake: the CPU is silent for 3 ms, then the wake-up comes
        t += 3e-3;
        cycle(t);
        t += 1e-3;
        for (int i = 0; i < 3; i++, t += 1e-3) {
            cycle(t);
        }
        // long-run: woken and run on time, then 3 ms before it leaves its CPU
        wake("swapper/0", 0, t);
        in("swapper/0", 0, t + 10e-6);
        out(t + 3e-3);
        t += 4e-3;
        for (int i = 0; i < 3; i++, t += 1e-3) {
            cycle(t);
        }
        Path trace = dir.resolve("trace.txt");
        Files.write(trace, lines);

        String outText = run(trace, "sim-robot");
        List<String> late = outText.lines().filter(l -> l.startsWith("  ")).toList();
        assertEquals(3, late.size(), outText);
        assertTrue(late.get(0).contains("held") && late.get(0).contains("ld-777"), outText);
        assertTrue(late.get(1).contains("late-wake"), outText);
        assertTrue(late.get(1).matches(".*silent\\s+3\\.\\d\\d ms.*"), outText);
        assertTrue(late.get(2).contains("long-run"), outText);
        assertTrue(outText.lines().reduce((a, b) -> b).orElse("").startsWith("rt-blame: "), outText);
        assertTrue(outText.contains("held by ld 1") && outText.contains("late-wake 1") && outText.contains("long-run 1"),
                outText);
    }

    @Test
    void saysSoWhenNoSuchLoopRan(@TempDir Path dir) throws Exception {
        cycle(1.0);
        Path trace = dir.resolve("trace.txt");
        Files.write(trace, lines);
        String outText = run(trace, "teach");
        assertTrue(outText.contains("no SCHED_FIFO thread named 'teach...' ran in " + trace), outText);
    }

    static String run(Path trace, String comm) throws IOException, InterruptedException {
        Process p = new ProcessBuilder("python3", SCRIPT.toString(), trace.toString(), comm).redirectErrorStream(true)
                .start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        assertTrue(p.waitFor(60, TimeUnit.SECONDS), "rt-blame.py did not end");
        return out;
    }
}
