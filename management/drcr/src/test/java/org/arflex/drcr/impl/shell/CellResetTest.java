package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.lang.reflect.Proxy;
import java.util.ArrayList;
import java.util.List;
import org.arflex.drcr.CellReset;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.junit.jupiter.api.Test;

/** arflex:reset --cell: everything that waits, providers first, and what was refused and why. */
class CellResetTest {

    private static InstanceDTO inst(String name, String state, boolean awaiting, boolean safe) {
        InstanceDTO i = new InstanceDTO();
        i.name = name;
        i.state = state;
        i.awaitingReset = awaiting;
        i.safeMode = safe;
        return i;
    }

    private static DrcrService cellOf(InstanceDTO... instances) {
        CellDTO c = new CellDTO();
        c.instances = instances;
        return (DrcrService) Proxy.newProxyInstance(DrcrService.class.getClassLoader(), new Class<?>[] {DrcrService.class},
                (p, m, a) -> {
                    if (m.getName().equals("cell")) {
                        return c;
                    }
                    throw new UnsupportedOperationException(m.getName());
                });
    }

    @Test
    void resetsProvidersFirstAndSaysWhatItDid() {
        // the robot's reset is refused while its guard is still stopped; the guard's succeeds
        DrcrService drcr = cellOf(inst("sim-robot", "ACTIVE", true, true), inst("force-guard", "ACTIVE", true, true),
                inst("vision", "ACTIVE", false, false), inst("trajectory", "ACTIVE", false, true),
                inst("camera", "ACTIVE", true, false));
        List<String> order = new ArrayList<>();
        String out = CellReset.run(drcr, n -> {
            if (n.equals("sim-robot") && !order.contains("force-guard")) {
                throw new IllegalStateException("sim-robot: reset refused, the cause persists: guard stopped");
            }
            if (n.equals("camera")) {
                throw new IllegalStateException("camera: reset refused, the cause persists: stale heartbeat");
            }
            order.add(n);
        });
        assertEquals(List.of("force-guard", "trajectory", "sim-robot"), order);
        assertTrue(out.startsWith("cell: reset force-guard, trajectory, sim-robot"), out);
        assertTrue(out.contains("refused camera: camera: reset refused, the cause persists: stale heartbeat"), out);
        assertTrue(!out.contains("vision"), "vision did not wait: " + out);
        assertTrue(out.contains("wait for a fresh command"), out);
    }

    @Test
    void nothingWaiting() {
        assertEquals("cell: nothing waits for a reset", CellReset.run(cellOf(inst("a", "ACTIVE", false, false)), n -> {
            throw new AssertionError("reset " + n);
        }));
    }
}
