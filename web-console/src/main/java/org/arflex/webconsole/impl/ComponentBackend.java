package org.arflex.webconsole.impl;

import com.fasterxml.jackson.core.type.TypeReference;
import java.util.LinkedHashMap;
import java.util.Map;
import java.util.Optional;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.ParamDTO;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.dto.PortValueDTO;
import org.arflex.drcr.dto.StatsDTO;
import org.osgi.framework.BundleException;

/**
 * The Component page's endpoints: a component's contract and instance, its latency histogram and
 * port values, setting a parameter, start, stop and reset; and the samples of the live stream
 * ({@link Sampler}). The Cell and Debug pages set parameters through it too.
 */
final class ComponentBackend {
    private static final TypeReference<Map<String, Object>> MAP = new TypeReference<>() { };

    private final Backend backend;

    ComponentBackend(Backend backend) {
        this.backend = backend;
    }

    Routes routes() {
        return new Routes()
                .get("component", call -> component(call.name()))
                .get("histogram", call -> histogram(call.name()))
                .get("port", call -> portValue(call.name(), call.param("port")))
                .post("param", call -> setParam(call.name(), call.param("param"), call.param("value")))
                .post("command", call -> command(call.name(), call.param("cmd")));
    }

    /** Contract and instance of one component. */
    Map<String, Object> component(String name) throws HttpError {
        Names.checkName(name);
        DrcrService d = backend.drcr();
        Optional<ContractDTO> c = d.contract(name);
        Optional<InstanceDTO> i = d.instance(name);
        if (c.isEmpty() && i.isEmpty()) {
            throw new HttpError(404, "no component named '" + name + "' in the cell");
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("contract", c.orElse(null));
        m.put("instance", i.orElse(null));
        m.put("managed", backend.management(name).isPresent());
        return m;
    }

    /** One live sample of a component for the stream (null when it is gone). */
    Map<String, Object> sample(String name) {
        Optional<ComponentManagement> cm = backend.management(name);
        if (cm.isEmpty()) {
            return null;
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("t", System.currentTimeMillis());
        ComponentManagement c = cm.get();
        m.put("state", c.state());
        StatsDTO s = c.stats();
        if (s != null) {
            // Every field of the DTO, whatever the DRCR's version carries.
            m.putAll(backend.json.convertValue(s, MAP));
        }
        InstanceDTO i = c.instance();
        Map<String, Object> params = new LinkedHashMap<>();
        if (i != null && i.params != null) {
            for (ParamDTO p : i.params) {
                params.put(p.name, p.value);
            }
        }
        m.put("params", params);
        return m;
    }

    /**
     * The RT half's wake-up latency histogram as the DRCR reads it from the control block:
     * lower bin edges and counts of the non-empty bins, the bin width, the overflow count and
     * the percentiles (all ns).
     */
    Map<String, Object> histogram(String name) throws HttpError {
        Names.checkName(name);
        StatsDTO s = backend.requireManagement(name).stats();
        if (s == null || s.latencyHistBins == null) {
            throw new HttpError(409, "component '" + name + "' has no RT half running (no histogram)");
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("component", name);
        m.put("binNs", s.histBinNs);
        long[] edges = new long[s.latencyHistBins.length];
        for (int i = 0; i < edges.length; i++) {
            edges[i] = s.latencyHistBins[i] * s.histBinNs;
        }
        m.put("lowerEdgesNs", edges);
        m.put("counts", s.latencyHistCounts);
        m.put("overflow", s.latencyHistOverflow);
        m.put("samples", s.latencyCount);
        m.put("p50Ns", s.latencyP50Ns);
        m.put("p99Ns", s.latencyP99Ns);
        m.put("p999Ns", s.latencyP999Ns);
        return m;
    }

    /** The newest value of an output port with the type's field names, units and element types. */
    PortValueDTO portValue(String name, String port) throws HttpError {
        Names.checkName(name);
        Names.checkPort(port);
        try {
            return backend.requireManagement(name).portValue(port);
        } catch (IllegalArgumentException e) {
            throw new HttpError(404, e.getMessage());
        } catch (IllegalStateException e) {
            throw new HttpError(409, e.getMessage());
        }
    }

    /** A port value for the stream: index, stamps and the values per field (compact). */
    Object portSample(String name, String port) {
        Optional<ComponentManagement> cm = backend.management(name);
        if (cm.isEmpty()) {
            return Map.of("error", "component '" + name + "' is gone");
        }
        PortValueDTO v = cm.get().portValue(port);
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("index", v.index);
        m.put("stampNs", v.stampNs);
        m.put("published", v.published);
        Map<String, double[]> f = new LinkedHashMap<>();
        for (PortFieldDTO d : v.fields) {
            f.put(d.name, d.values);
        }
        m.put("fields", f);
        return m;
    }

    /** Sets a parameter and returns the value the RT half applied. */
    Map<String, Object> setParam(String name, String param, String value) throws HttpError {
        Names.checkName(name);
        if (param == null || param.isBlank()) {
            throw new HttpError(400, "param: missing");
        }
        if (value == null) {
            throw new HttpError(400, "value: missing");
        }
        ComponentManagement cm = backend.requireManagement(name);
        try {
            String applied = cm.set(param, value.trim());
            return Map.of("component", name, "param", param, "applied", applied);
        } catch (IllegalArgumentException e) {
            throw new HttpError(400, e.getMessage());
        } catch (IllegalStateException e) {
            throw new HttpError(409, e.getMessage());
        }
    }

    /** start, stop (the component's bundle) or reset (operator reset of the instance). */
    Map<String, Object> command(String name, String cmd) throws HttpError {
        Names.checkName(name);
        try {
            switch (cmd == null ? "" : cmd) {
                case "reset" -> backend.management(name).orElseThrow(() -> new HttpError(404,
                        "component '" + name + "' has no management service")).reset();
                case "start" -> backend.bundleOf(name).start();
                case "stop" -> backend.bundleOf(name).stop();
                default -> throw new HttpError(400, "cmd: '" + cmd + "' is not start, stop or reset");
            }
        } catch (BundleException | IllegalStateException e) {
            throw new HttpError(409, cmd + " " + name + ": " + e.getMessage());
        }
        return Map.of("component", name, "done", cmd);
    }
}
