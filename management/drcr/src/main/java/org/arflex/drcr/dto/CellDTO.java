package org.arflex.drcr.dto;

/** The whole cell as one snapshot: contracts, instances, wiring, resources and problems. */
public class CellDTO {
    /** The runtime id used in every shm and mq name ({@code /arflex.<runtimeId>.*}). */
    public String runtimeId;
    /** Increases by one with every change of the cell. */
    public long generation;
    /** Every contract known to the DRCR. */
    public ContractDTO[] contracts;
    /** Every component instance, one per contract. */
    public InstanceDTO[] instances;
    /** Every wire between an output and an input. */
    public BindingDTO[] bindings;
    /** Capacities and their use. */
    public ResourcesDTO resources;
    /** Contracts that were rejected (file, line, section and reason), and other problems. */
    public String[] problems;
}
