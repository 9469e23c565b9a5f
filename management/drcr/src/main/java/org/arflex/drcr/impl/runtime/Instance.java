package org.arflex.drcr.impl.runtime;

import java.nio.file.Path;
import java.util.LinkedHashMap;
import java.util.Map;
import java.util.TreeMap;
import org.arflex.contract.Contract;
import org.arflex.contract.PropertySpec;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.lifecycle.Lifecycle;
import org.arflex.drcr.impl.supervisor.RestartPolicy;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * One component instance: its contract, lifecycle, restart policy, RT half and output
 * segments. Owned by the {@link Cell}; mutated on the actor thread only. Fields read by DTO
 * snapshots from other threads are volatile.
 */
public final class Instance {
    /** The contract (for services). */
    public Contract contract() {
        return contract;
    }

    final String name;
    /**
     * The id its RT half runs under, in the names of its control block, queues and output
     * segments ({@code /arflex.<rid>.<id>.*}): the name, unless a change set's update gave it
     * a generation id ({@link #generationId}) so the new version runs beside the old (D38).
     */
    final String objectId;
    /** The generation of this instance: 0 for the first, n for the n-th update in a change set. */
    final int generation;
    volatile Contract contract;
    public volatile long bundleId;
    volatile Path executable;
    final Lifecycle life;
    volatile RestartPolicy policy;
    volatile RtHalf half;
    /** A half is being launched (spawned, waiting for READY) off the actor (Starter). Actor only. */
    boolean launching;
    /** Number of the newest launch; a stop of the instance while it launches makes it stale. */
    long launchSeq;
    /** Output port name -> segment; created at the first start, kept until destroyed. */
    final Map<String, RtLauncher.Output> outputs = new LinkedHashMap<>();
    /**
     * Evaluation-only segments (not contract ports, never named in a BIND; {@link EvaluationSegments}):
     * port name -> segment, created with the outputs when the cell runs with arflex.evaluation,
     * removed with them.
     */
    final Map<String, RtLauncher.Output> evaluationOutputs = new LinkedHashMap<>();
    /** Read-only copy of {@link #evaluationOutputs}' names for snapshots: port -> shm name. */
    volatile Map<String, String> evaluationSegments = Map.of();
    /** The state block's segment ({@link StateTransfer}, D41), when the contract declares one. */
    RtLauncher.Output stateSegment;
    /** Input port -> provider segment it is bound to. */
    final Map<String, String> bound = new TreeMap<>();
    /** Configured value bits per parameter (contract order). */
    volatile long[] params;
    volatile boolean awaitingReset;
    volatile boolean everStarted;
    volatile int cpu = -1;
    volatile int restarts;
    volatile String hangReason;
    Actor.Cancellable restartTimer;
    volatile long measuredWcetNs;
    /** Execution-time metric and WCET overruns at the previous sampling of this RT half ({@link WcetMonitor}). */
    org.arflex.drcr.impl.abi.ControlBlock.Metric sampledExec;
    long sampledExecOver;
    /** The sustained level of the previous sampling window when it was above the WCET, else 0 (D82). */
    long sustainedLevelNs;
    /** An isolated WCET exceedance of this instance was logged already. */
    boolean transientWcetLogged;
    /** Known to the planner (its bundle is started); false while only INSTALLED. */
    volatile boolean planned;
    /**
     * The contract was replaced while its RT half ran: the output segments are recreated once
     * that half is gone (never while their producer may still write them). Actor thread.
     */
    boolean outputsStale;
    /** Why it was uninstalled: its DESTROYED reason once its RT half is gone. Actor thread. */
    String destroyReason;

    Instance(Contract c, long bundleId, Path exe, Actor actor, java.util.function.Consumer<String> log) {
        this(c, bundleId, exe, actor, log, 0);
    }

    /** Generation {@code generation} of component {@code c}: a change set's update (D38). */
    Instance(Contract c, long bundleId, Path exe, Actor actor, java.util.function.Consumer<String> log, int generation) {
        this.name = c.name();
        this.generation = generation;
        this.objectId = generationId(c.name(), generation);
        this.contract = c;
        this.bundleId = bundleId;
        this.executable = exe;
        this.life = new Lifecycle(c.name(), actor, log);
        this.policy = new RestartPolicy(c.fault(), actor.clock());
        this.params = defaults(c);
    }

    /** The pid of the running RT half, 0 when none runs. */
    public long pid() {
        RtHalf h = half;
        return h == null ? 0 : h.pid();
    }

    /**
     * The object id of generation {@code g} of component {@code name}: the name for 0, else
     * {@code <g>-<name>}. A component name starts with a letter (contract 3.1), so an id that
     * starts with a digit is never another component's; rt-core takes ids of [a-z0-9-]{1,40}.
     */
    static String generationId(String name, int g) {
        return g == 0 ? name : g + "-" + name;
    }

    static long[] defaults(Contract c) {
        long[] p = new long[c.properties().size()];
        for (int i = 0; i < p.length; i++) {
            PropertySpec ps = c.properties().get(i);
            p[i] = ps.defaultValue().bits();
        }
        return p;
    }

    /**
     * The parameters for contract {@code c} when it takes over from {@code old}: a value set
     * before (by {@code arflex:set} while only installed, or in the running version) is kept
     * for a property of the same name and type whose range still holds it; everything else
     * takes the new contract's default.
     */
    static long[] carried(Contract old, long[] oldParams, Contract c) {
        long[] p = defaults(c);
        for (int i = 0; i < p.length; i++) {
            PropertySpec ps = c.properties().get(i);
            for (int j = 0; j < old.properties().size() && j < oldParams.length; j++) {
                PropertySpec o = old.properties().get(j);
                if (o.name().equals(ps.name()) && o.type() == ps.type() && inRange(ps, oldParams[j])) {
                    p[i] = oldParams[j];
                }
            }
        }
        return p;
    }

    private static boolean inRange(PropertySpec ps, long bits) {
        double v = switch (ps.type()) {
            case DOUBLE -> Double.longBitsToDouble(bits);
            case INT, BOOL -> bits;
        };
        return !Double.isNaN(v) && ps.min().map(m -> v >= m).orElse(true) && ps.max().map(m -> v <= m).orElse(true);
    }
}
