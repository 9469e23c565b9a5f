package org.arflex.webconsole.impl;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.stream.Stream;
import org.arflex.contract.ContractParser;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.PortDTO;
import org.osgi.framework.Bundle;

/**
 * The Debug page's endpoints: the debug-monitor jar (or why it is missing) and the installed
 * monitor, the output ports it could watch, and staging a monitor built for chosen ports
 * ({@link DebugMonitor}); it is then installed, watched and removed like any component.
 */
final class DebugBackend {
    private final Backend backend;
    private final StagingArea staging;
    private final ContractParser parser;

    DebugBackend(Backend backend, StagingArea staging, ContractParser parser) {
        this.backend = backend;
        this.staging = staging;
        this.parser = parser;
    }

    Routes routes() {
        return new Routes()
                .get("debug", call -> debugStatus())
                .get("ports", call -> watchablePorts())
                .post("debug-stage", call -> debugStage(call.param("targets")));
    }

    private Path debugJar() throws HttpError, IOException {
        return DebugMonitor.locate(backend.context().getProperty(DebugMonitor.JAR_PROPERTY));
    }

    /** Where the debug-monitor jar is (or why not), and the installed monitor, if any. */
    Map<String, Object> debugStatus() throws HttpError, IOException {
        Map<String, Object> m = new LinkedHashMap<>();
        try {
            m.put("jar", debugJar().toString());
        } catch (HttpError e) {
            m.put("jar", null);
            m.put("jarProblem", e.getMessage());
        }
        Bundle installed = backend.bundleNamed(DebugMonitor.SYMBOLIC_NAME);
        m.put("bundleId", installed == null ? null : installed.getBundleId());
        DrcrService d = backend.drcr();
        m.put("component", DebugMonitor.COMPONENT);
        m.put("instance", d.instance(DebugMonitor.COMPONENT).orElse(null));
        m.put("contract", d.contract(DebugMonitor.COMPONENT).orElse(null));
        return m;
    }

    /** Every output port of every contract in the cell: component, port, type, method. */
    Map<String, Object> watchablePorts() throws HttpError {
        List<Map<String, Object>> out = new ArrayList<>();
        CellDTO c = backend.drcr().cell();
        for (ContractDTO k : c.contracts == null ? new ContractDTO[0] : c.contracts) {
            for (PortDTO p : k.ports == null ? new PortDTO[0] : k.ports) {
                if ("OUT".equals(p.direction)) {
                    Map<String, Object> m = new LinkedHashMap<>();
                    m.put("component", k.name);
                    m.put("port", p.name);
                    m.put("type", p.type);
                    m.put("typeVersion", p.typeVersion);
                    m.put("method", p.method);
                    out.add(m);
                }
            }
        }
        return Map.of("ports", out);
    }

    /**
     * Builds the debug-monitor bundle for {@code targets} ({@code comp.port,...}: state ports of
     * type arflex.Sample 1.x in the cell), stages it and returns the DRCR's plan; installed by
     * {@code install?id=} like any staged bundle.
     */
    Map<String, Object> debugStage(String targets) throws HttpError, IOException {
        List<DebugMonitor.Target> ts = DebugMonitor.targets(targets);
        DrcrService d = backend.drcr();
        for (DebugMonitor.Target t : ts) {
            ContractDTO c = d.contract(t.component()).orElseThrow(() -> new HttpError(404,
                    "targets: no component '" + t.component() + "' in the cell"));
            PortDTO p = Stream.of(c.ports == null ? new PortDTO[0] : c.ports)
                    .filter(x -> "OUT".equals(x.direction) && t.port().equals(x.name)).findFirst()
                    .orElseThrow(() -> new HttpError(404, "targets: '" + t.component() + "' has no output port '"
                            + t.port() + "'"));
            if (!"arflex.Sample".equals(p.type) || !"STATE".equals(p.method) || !p.typeVersion.startsWith("1.")) {
                throw new HttpError(400, "targets: " + t + " is " + p.type + " " + p.typeVersion + " " + p.method
                        + "; the debug monitor watches state ports of type arflex.Sample 1.x only");
            }
        }
        byte[] jar = DebugMonitor.build(debugJar(), ts, parser);
        Map<String, Object> m = staging.plan(Artifacts.upload(new ByteArrayInputStream(jar),
                "debug-monitor for " + String.join(", ", ts.stream().map(DebugMonitor.Target::toString).toList()),
                staging.dir()));
        m.put("targets", ts.stream().map(DebugMonitor.Target::toString).toList());
        return m;
    }
}
