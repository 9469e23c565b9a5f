package org.arflex.drcr.dto;

/** A component instance and its state. */
public class InstanceDTO {
    /** Instance name (the component name). */
    public String name;
    /** INSTALLED, UNSATISFIED, ACTIVE, DESTROYED or FAILED. */
    public String state;
    /** The state the DRCR is driving the instance to. */
    public String targetState;
    /** Why the instance is not Active (unsatisfied input, admission refusal, crash...), or null. */
    public String failureReason;
    /** Restarts left in the current intensity window. */
    public int restartsLeft;
    /** Total restarts since install. */
    public int restarts;
    /** Process id of the RT half, or 0 when none runs. */
    public long pid;
    /** CPU admission placed the task on, or -1. */
    public int cpu;
    /**
     * True when the RT half waits for an operator reset before driving outputs: restarted while
     * it moves hardware, or (since 0.4.0) latched by the RT half itself, e.g. after the runtime
     * heartbeat was lost.
     */
    public boolean awaitingReset;
    /** Since 0.4.0: the RT half runs its safe hook instead of its update (heartbeat lost or reset required). */
    public boolean safeMode;
    /**
     * Since 0.6.0: why this instance holds the arm (or its outputs) now, or null when it does
     * not: supervisor lost, a safety input that does not permit motion (which input, why, and its
     * provider's state), waiting for an operator reset (and why), waiting for a fresh command
     * after a reset, safe mode. An ACTIVE instance with a non-null value is shown as HOLDING.
     */
    public String holding;
    /** Id of the bundle that carries the contract. */
    public long bundleId;
    /** The wires of this instance's inputs. */
    public BindingDTO[] bindings;
    /** Parameters with their applied values. */
    public ParamDTO[] params;
    /** RT statistics, or null when no RT half runs. */
    public StatsDTO stats;
    /**
     * Since 0.2.0: evaluation-only segments the DRCR created for this instance (port name ->
     * shm object name, e.g. truth -> /arflex.rt1.robot.out.truth), only when the runtime
     * runs with arflex.evaluation=true; never bound to a component, for evaluation tools to map
     * read-only. Empty otherwise.
     */
    public java.util.Map<String, String> evaluationSegments;
}
