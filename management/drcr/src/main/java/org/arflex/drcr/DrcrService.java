package org.arflex.drcr;

import java.util.List;
import java.util.Optional;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;

/**
 * Read-only view of the cell. Every method returns a fresh snapshot that the caller owns; none
 * changes the cell. The dry-run {@code plan*} methods say what an action would do without doing
 * it.
 */
public interface DrcrService {

    /** The whole cell. */
    CellDTO cell();

    /** One instance, if it exists. */
    Optional<InstanceDTO> instance(String name);

    /** One contract, if it exists. */
    Optional<ContractDTO> contract(String name);

    /** What installing the bundle at {@code location} would start, stop and restart, and why. */
    String planInstall(String location);

    /**
     * What {@code update name} would do: downloads from the contract's update URL, checks the
     * pinned SHA-256 and the new contracts, and plans their replacement (nothing is installed).
     */
    String planUpdate(String name);

    /** What uninstalling the bundle carrying component {@code name} would stop, and why. */
    String planUninstall(String name);

    /** What changing the capacities to these values would stop or start, and why. */
    String planCapacity(List<Integer> cpus, long memoryBytes, long networkBps);
}
