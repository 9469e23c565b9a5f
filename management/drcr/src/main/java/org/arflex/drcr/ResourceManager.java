package org.arflex.drcr;

import java.util.List;
import org.arflex.drcr.dto.ResourcesDTO;

/**
 * Capacities the DRCR admits components against. Initial values come from the framework
 * properties {@code arflex.cpus} (for example {@code 0,1} or {@code 1-3}), {@code arflex.memory}
 * (bytes, suffixes k/m/g allowed) and {@code arflex.network} (bytes per second). Every change
 * makes the DRCR re-plan: when a capacity shrinks, the lowest criticality stops first.
 */
public interface ResourceManager {

    /** Current capacities and their use. */
    ResourcesDTO resources();

    /** Sets the CPUs available to RT tasks. */
    void setCpus(List<Integer> cpus);

    /** Sets the memory capacity in bytes. */
    void setMemory(long bytes);

    /** Sets the network capacity in bytes per second. */
    void setNetwork(long bytesPerSecond);
}
