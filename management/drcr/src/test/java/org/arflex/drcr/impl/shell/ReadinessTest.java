package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import java.util.concurrent.atomic.AtomicLong;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.junit.jupiter.api.Test;

/**
 * arflex:await over a stub DRCR whose every look advances the test's clock by 10 s and counts as
 * a change, and runs {@link #step} (what the cell does meanwhile): the waits end by the
 * condition or by the deadline, without sleeping.
 */
class ReadinessTest {

    private static final long S = 1_000_000_000L;

    private final AtomicLong clock = new AtomicLong();
    private final CellWatch watch = new CellWatch(clock::get);
    private final List<InstanceDTO> instances = new ArrayList<>();
    private int looks;
    private Runnable step = () -> { };

    private final DrcrService drcr = new DrcrService() {
        @Override
        public CellDTO cell() {
            look();
            CellDTO c = new CellDTO();
            c.instances = instances.toArray(new InstanceDTO[0]);
            return c;
        }

        @Override
        public Optional<InstanceDTO> instance(String name) {
            look();
            return instances.stream().filter(i -> i.name.equals(name)).findFirst();
        }

        @Override
        public Optional<ContractDTO> contract(String name) {
            return Optional.empty();
        }

        @Override
        public String planInstall(String location) {
            return "";
        }

        @Override
        public String planUpdate(String name) {
            return "";
        }

        @Override
        public String planUninstall(String name) {
            return "";
        }

        @Override
        public String planCapacity(List<Integer> cpus, long memoryBytes, long networkBps) {
            return "";
        }
    };

    private final Readiness readiness = new Readiness(drcr, watch);

    private void look() {
        looks++;
        step.run();
        clock.addAndGet(10 * S);
        watch.changed();
    }

    private InstanceDTO instance(String name, String state, String reason) {
        InstanceDTO i = new InstanceDTO();
        i.name = name;
        i.state = state;
        i.failureReason = reason;
        instances.add(i);
        return i;
    }

    @Test
    void returnsOnceTheComponentIsActive() {
        InstanceDTO v = instance("vision", "UNSATISFIED", "input tcp_pose: no provider");
        step = () -> {
            if (looks == 3) {
                v.state = "ACTIVE";
                v.failureReason = null;
            }
        };
        assertEquals("vision ACTIVE (after 30.0 s)", readiness.await("vision"));
    }

    @Test
    void waitsForAComponentNotInstalledYet() {
        step = () -> {
            if (looks == 2) {
                instance("vision", "ACTIVE", null);
            }
        };
        assertEquals("vision ACTIVE (after 20.0 s)", readiness.await("vision", "active", "--timeout", "120"));
    }

    @Test
    void aTimeoutNamesTheComponentItsStateAndItsReason() {
        instance("vision", "UNSATISFIED", "input tcp_pose: no provider \"camera\"\n");
        assertEquals("error: vision is UNSATISFIED, not ACTIVE, after 25 s: input tcp_pose: no provider \"camera\"",
                readiness.await("vision", "--timeout", "25"));
        assertEquals(3, looks, "looked at 10, 20 and 30 s of a 25 s wait");
    }

    @Test
    void aComponentNeverInstalledIsNamedWithWhatIsThere() {
        instance("sim-robot", "ACTIVE", null);
        String r = readiness.await("vison", "--timeout", "5");
        assertEquals("error: no component 'vison' after 5 s (installed: [sim-robot])", r);
    }

    @Test
    void aFailedComponentEndsTheWaitAtOnce() {
        instance("vision", "FAILED", "crashed 4 times in 10 s");
        assertEquals("error: vision is FAILED, not ACTIVE: crashed 4 times in 10 s (arflex:reset vision gives it a new chance)",
                readiness.await("vision", "--timeout", "600"));
        assertEquals(1, looks);
    }

    @Test
    void otherStatesCanBeAwaited() {
        InstanceDTO v = instance("vision", "ACTIVE", null);
        step = () -> {
            if (looks == 2) {
                v.state = "DESTROYED";
            }
        };
        assertEquals("vision DESTROYED (after 20.0 s)", readiness.await("vision", "DESTROYED"));
    }

    @Test
    void theWholeCell() {
        InstanceDTO a = instance("sim-robot", "ACTIVE", null);
        InstanceDTO b = instance("vision", "UNSATISFIED", "input tcp_pose: no provider");
        assertEquals("error: not ACTIVE after 15 s: vision UNSATISFIED (input tcp_pose: no provider)",
                readiness.await("--cell", "--timeout", "15"));
        step = () -> b.state = "ACTIVE";
        assertTrue(readiness.await("--cell").startsWith("cell ACTIVE: 2 components"));
        instances.clear();
        assertEquals("error: no components after 5 s", readiness.await("--cell", "--timeout", "5"));
        assertEquals("ACTIVE", a.state);
    }

    @Test
    void badArgumentsGiveTheUsage() {
        for (String[] args : new String[][] {{}, {"vision", "RUNNING"}, {"vision", "--timeout"}, {"vision", "--timeout", "-1"},
            {"--cell", "x"}, {"a", "ACTIVE", "b"}}) {
            assertEquals(Readiness.USAGE, readiness.await(args), String.join(" ", args));
        }
        assertEquals(0, looks);
    }
}
