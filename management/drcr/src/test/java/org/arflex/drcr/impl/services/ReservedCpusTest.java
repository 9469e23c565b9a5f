package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Set;
import org.arflex.planner.Capacities;
import org.junit.jupiter.api.Test;

/** arflex.cpus.reserved reaches the planner's capacities, also when the CPU list changes. */
class ReservedCpusTest {

    @Test
    void reservedCpusAreMarkedInEveryCapacitiesBuilt() {
        ResourceManagerImpl rm = new ResourceManagerImpl(null, 0.9, Set.of(1));
        Capacities c = rm.capacities(List.of(0, 1), 1L << 30, 1000);
        assertEquals(List.of(1), c.reservedCpus());
        assertFalse(c.cpu(0).orElseThrow().reserved());
        assertTrue(c.cpu(1).orElseThrow().reserved());
        assertEquals(0.9, c.cpu(1).orElseThrow().utilisationCap());
        // a later capacity change without cpu 1 simply has no reserved cpu
        assertEquals(List.of(), rm.capacities(List.of(0), 1L << 30, 1000).reservedCpus());
    }

    @Test
    void withoutThePropertyNothingIsReserved() {
        Capacities c = new ResourceManagerImpl(null, 1.0).capacities(List.of(0, 1), 1L << 30, 1000);
        assertEquals(List.of(), c.reservedCpus());
    }
}
