package org.arflex.drcr.impl.runtime;

import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.Binding;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PropertySpec;
import org.arflex.drcr.dto.BindingDTO;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.ParamDTO;
import org.arflex.drcr.dto.PortDTO;
import org.arflex.drcr.dto.ResourcesDTO;
import org.arflex.drcr.dto.StatsDTO;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.supervisor.RtHalf;

/** Builds DTO snapshots of a cell. Called on the actor thread so a snapshot is consistent. */
public final class Snapshots {

    private Snapshots() {
    }

    /** The whole cell. */
    public static CellDTO cell(Cell cell, ResourcesDTO resources) {
        CellDTO d = new CellDTO();
        d.runtimeId = cell.config().runtimeId();
        d.generation = cell.generation();
        List<Instance> all = cell.instances();
        d.contracts = all.stream().map(i -> contract(i.contract, i.bundleId)).toArray(ContractDTO[]::new);
        d.instances = all.stream().map(i -> instance(cell, i)).toArray(InstanceDTO[]::new);
        List<BindingDTO> b = new ArrayList<>();
        for (InstanceDTO i : d.instances) {
            b.addAll(List.of(i.bindings));
        }
        d.bindings = b.toArray(BindingDTO[]::new);
        d.resources = resources;
        d.problems = cell.problems().toArray(String[]::new);
        return d;
    }

    /** One instance, if present. */
    public static java.util.Optional<InstanceDTO> instance(Cell cell, String name) {
        return cell.instance(name).map(i -> instance(cell, i));
    }

    /** One contract, if present. */
    public static java.util.Optional<ContractDTO> contract(Cell cell, String name) {
        return cell.instance(name).map(i -> contract(i.contract, i.bundleId));
    }

    static ContractDTO contract(Contract c, long bundleId) {
        ContractDTO d = new ContractDTO();
        d.name = c.name();
        d.version = c.version();
        d.description = c.description();
        d.executable = c.executable();
        d.taskType = c.taskType().name();
        d.movesHardware = c.movesHardware();
        d.periodNs = c.timing().periodNs();
        d.deadlineNs = c.timing().deadlineNs();
        d.wcetNs = c.timing().wcetNs();
        d.priority = c.timing().priority();
        d.cpus = c.timing().cpus().stream().mapToInt(Integer::intValue).toArray();
        d.memoryBytes = c.resources().memoryBytes();
        d.networkBps = c.resources().networkBps();
        d.criticality = c.criticality();
        d.restart = c.fault().restart().name();
        d.intensity = c.fault().intensity();
        d.windowMs = c.fault().windowMs();
        d.backoffMs = c.fault().backoffMs();
        d.safeOutput = c.fault().safeOutput().name();
        d.updateUrl = c.update().map(u -> u.url().toString()).orElse(null);
        d.updateSha256 = c.update().map(u -> u.sha256()).orElse(null);
        d.source = c.source();
        d.bundleId = bundleId;
        d.ports = c.ports().stream().map(Snapshots::port).toArray(PortDTO[]::new);
        return d;
    }

    static PortDTO port(PortSpec p) {
        PortDTO d = new PortDTO();
        d.name = p.name();
        d.direction = p.direction().name();
        d.type = p.type();
        d.typeVersion = p.typeVersion().toString();
        d.method = p.method().name();
        d.binding = p.binding().map(Snapshots::binding).orElse(null);
        d.optional = p.optional();
        return d;
    }

    static String binding(Binding b) {
        if (b.component().isPresent()) {
            return b.component().get() + "." + b.port().orElse("?");
        }
        return b.filter().orElse(null);
    }

    static InstanceDTO instance(Cell cell, Instance i) {
        InstanceDTO d = new InstanceDTO();
        d.name = i.name;
        d.state = i.life.state().name();
        d.targetState = i.life.target().name();
        d.failureReason = i.life.reason();
        d.restartsLeft = i.policy.restartsLeft();
        d.restarts = i.restarts;
        RtHalf half = i.half;
        d.pid = half != null ? half.pid() : 0;
        d.cpu = i.cpu;
        int flags = half != null ? half.flags() : 0;
        d.awaitingReset = i.awaitingReset || (flags & ControlBlock.FLAG_RESET_REQUIRED) != 0;
        d.safeMode = (flags & ControlBlock.FLAG_SAFE_ACTIVE) != 0;
        d.holding = Holding.reason(cell, i, flags, half != null ? half.hold() : 0, d.awaitingReset);
        d.evaluationSegments = new java.util.TreeMap<>(i.evaluationSegments);
        d.bundleId = i.bundleId;
        List<BindingDTO> bs = new ArrayList<>();
        java.util.Map<String, Long> rejects = half == null ? java.util.Map.of()
                : half.inputRejects(i.contract.inputs().stream().map(org.arflex.contract.PortSpec::name).toList());
        for (var w : cell.planner().wires()) {
            if (w.consumer().equals(i.name)) {
                BindingDTO b = new BindingDTO();
                b.consumer = w.consumer();
                b.input = w.inPort();
                b.provider = w.provider();
                b.output = w.outPort();
                b.rejected = rejects.getOrDefault(w.inPort(), 0L);
                bs.add(b);
            }
        }
        d.bindings = bs.toArray(BindingDTO[]::new);
        List<PropertySpec> props = i.contract.properties();
        long[] values = i.params;
        d.params = new ParamDTO[props.size()];
        for (int k = 0; k < props.size(); k++) {
            PropertySpec p = props.get(k);
            ParamDTO pd = new ParamDTO();
            pd.name = p.name();
            pd.type = p.type().name();
            pd.value = Params.format(p, half != null ? half.paramValue(k) : values[k]);
            pd.defaultValue = p.defaultValue().toString();
            pd.min = p.min().orElse(null);
            pd.max = p.max().orElse(null);
            pd.unit = p.unit();
            pd.mutable = p.mutable();
            d.params[k] = pd;
        }
        d.stats = half != null ? stats(half, i.contract.timing().wcetNs(), cell.config().monotonicNs().getAsLong()) : null;
        return d;
    }

    static StatsDTO stats(RtHalf half, long wcetNs, long nowNs) {
        ControlBlock.Detail det = half.detail(wcetNs);
        ControlBlock.Stats s = det != null ? det.stats() : null;
        StatsDTO d = new StatsDTO();
        d.rtState = ControlBlock.stateName(half.rtState());
        long hb = half.rtHeartbeatNs();
        d.heartbeatAgeMs = hb == 0 ? -1 : Math.max(0, (nowNs - hb) / 1_000_000L);
        d.forgedRequests = half.forgedRequests();
        if (s != null) {
            d.cycles = s.cycles();
            d.overruns = s.overruns();
            d.wcetOverruns = s.execOverWcet();
            d.updateErrors = s.updateErrors();
            d.safeCycles = s.safeCycles();
            d.maxLatencyNs = s.latencyMaxNs();
            d.maxExecNs = s.execMaxNs();
            d.meanExecNs = s.execCount() > 0 ? s.execSumNs() / s.execCount() : 0;
        }
        if (det != null && det.latency() != null && det.exec() != null) {
            histogram(d, det.latency(), det.exec());
        }
        return d;
    }

    /** Percentiles of both metrics and the non-empty latency bins (compact). */
    static void histogram(StatsDTO d, ControlBlock.Metric lat, ControlBlock.Metric exec) {
        d.latencyCount = lat.count();
        d.latencyP50Ns = lat.percentileNs(50.0);
        d.latencyP99Ns = lat.percentileNs(99.0);
        d.latencyP999Ns = lat.percentileNs(99.9);
        d.execP50Ns = exec.percentileNs(50.0);
        d.execP99Ns = exec.percentileNs(99.0);
        d.execP999Ns = exec.percentileNs(99.9);
        d.histBinNs = ControlBlock.HIST_BIN_NS;
        long[] bins = lat.bins();
        int n = 0;
        for (int i = 0; i < ControlBlock.HIST_BINS; i++) {
            if (bins[i] != 0) {
                n++;
            }
        }
        d.latencyHistBins = new int[n];
        d.latencyHistCounts = new long[n];
        for (int i = 0, k = 0; i < ControlBlock.HIST_BINS; i++) {
            if (bins[i] != 0) {
                d.latencyHistBins[k] = i;
                d.latencyHistCounts[k++] = bins[i];
            }
        }
        d.latencyHistOverflow = lat.overflow();
    }
}
