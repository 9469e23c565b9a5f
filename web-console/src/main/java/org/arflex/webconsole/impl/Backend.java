package org.arflex.webconsole.impl;

import com.fasterxml.jackson.databind.ObjectMapper;
import java.io.IOException;
import java.io.InputStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.security.SecureRandom;
import java.util.ArrayList;
import java.util.HexFormat;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.concurrent.ConcurrentHashMap;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.arflex.contract.ContractParser;
import org.arflex.contract.Problem;
import org.arflex.drcr.CellReset;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.UpdateService;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.ParamDTO;
import org.arflex.drcr.dto.PortDTO;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.dto.PortValueDTO;
import org.arflex.drcr.dto.StatsDTO;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;
import org.osgi.service.component.annotations.Activate;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Deactivate;
import org.osgi.service.component.annotations.Reference;
import org.osgi.service.component.annotations.ReferenceCardinality;
import org.osgi.service.component.annotations.ReferencePolicy;

/**
 * Everything the console pages do, behind the HTTP layer: reads the cell through the DRCR's
 * DTO services only, changes it through ComponentManagement, the bundle life cycle and the
 * UpdateService. The DRCR services are optional and dynamic: the console keeps working (and
 * says so) while the DRCR is absent or restarting.
 */
@Component(service = Backend.class, immediate = true)
public class Backend {
    private static final Pattern NAME = Pattern.compile("[A-Za-z0-9][A-Za-z0-9._-]{0,63}");
    private static final Pattern PORT = Pattern.compile("[a-z0-9_]{1,31}");
    private static final int MAX_STAGED = 8;

    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    volatile DrcrService drcr;
    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    volatile ResourceManager resources;
    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    volatile UpdateService updates;
    @Reference(cardinality = ReferenceCardinality.MULTIPLE, policy = ReferencePolicy.DYNAMIC)
    volatile List<ComponentManagement> components;

    private static final com.fasterxml.jackson.core.type.TypeReference<Map<String, Object>> MAP =
            new com.fasterxml.jackson.core.type.TypeReference<>() { };
    final ObjectMapper json = new ObjectMapper();
    private final ContractParser parser = ContractParser.create();
    private final Map<String, Artifacts.Staged> staged = new ConcurrentHashMap<>();
    private final SecureRandom random = new SecureRandom();
    private final Map<String, Long> knownBundles = new ConcurrentHashMap<>();
    private BundleContext context;
    /** The bundle's private data area (staging/, installed/); set on activation. */
    Path dataDir;
    private Path contractsDir;
    private StagingSources stageSources = StagingSources.parse(null);
    Sampler sampler;

    @Activate
    void activate(BundleContext bc) throws IOException {
        this.context = bc;
        this.dataDir = bc.getDataFile("").toPath();
        String configured = bc.getProperty("arflex.contracts.dir");
        String home = System.getenv("ARFLEX_HOME");
        this.contractsDir = configured != null ? Path.of(configured)
                : home != null ? Path.of(home, "contracts") : dataDir.resolve("contracts");
        this.stageSources = StagingSources.parse(bc.getProperty(StagingSources.PROPERTY));
        this.sampler = new Sampler(this::sample, this::portSample);
        cleanStaging();
    }

    @Deactivate
    void deactivate() throws IOException {
        sampler.close();
        cleanStaging();
    }

    private void cleanStaging() throws IOException {
        staged.clear();
        Path dir = dataDir.resolve("staging");
        if (Files.isDirectory(dir)) {
            try (Stream<Path> s = Files.list(dir)) {
                for (Path p : s.toList()) {
                    Files.deleteIfExists(p);
                }
            }
        }
    }

    // ---- reading -------------------------------------------------------------------------

    DrcrService drcr() throws HttpError {
        DrcrService d = drcr;
        if (d == null) {
            throw new HttpError(503, "the DRCR is not running (no DrcrService registered)");
        }
        return d;
    }

    /** The cell, or an object saying the DRCR is absent. */
    Map<String, Object> cell() {
        Map<String, Object> m = new LinkedHashMap<>();
        DrcrService d = drcr;
        m.put("drcr", d != null);
        if (d != null) {
            CellDTO c = d.cell();
            m.put("cell", c);
            ResourceManager rm = resources;
            if (rm != null) {
                m.put("resources", rm.resources());
            }
        }
        return m;
    }

    /** Contract and instance of one component. */
    Map<String, Object> component(String name) throws HttpError {
        checkName(name);
        DrcrService d = drcr();
        Optional<ContractDTO> c = d.contract(name);
        Optional<InstanceDTO> i = d.instance(name);
        if (c.isEmpty() && i.isEmpty()) {
            throw new HttpError(404, "no component named '" + name + "' in the cell");
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("contract", c.orElse(null));
        m.put("instance", i.orElse(null));
        m.put("managed", management(name).isPresent());
        return m;
    }

    Optional<ComponentManagement> management(String name) {
        List<ComponentManagement> list = components;
        if (list == null) {
            return Optional.empty();
        }
        return list.stream().filter(cm -> name.equals(safeName(cm))).findFirst();
    }

    private static String safeName(ComponentManagement cm) {
        try {
            return cm.name();
        } catch (RuntimeException e) {
            return null;
        }
    }

    /** One live sample of a component for the stream (null when it is gone). */
    Map<String, Object> sample(String name) {
        Optional<ComponentManagement> cm = management(name);
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
            m.putAll(json.convertValue(s, MAP));
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
        checkName(name);
        ComponentManagement cm = management(name).orElseThrow(
                () -> new HttpError(404, "component '" + name + "' has no management service (not installed?)"));
        StatsDTO s = cm.stats();
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

    // ---- port values ---------------------------------------------------------------------

    /** Checks a port name as the ABI allows it ({@code [a-z0-9_]{1,31}}). */
    static void checkPort(String port) throws HttpError {
        if (port == null || !PORT.matcher(port).matches()) {
            throw new HttpError(400, "port: '" + port + "' is not a port name (a-z, 0-9, _; up to 31)");
        }
    }

    /** {@code p1,p2} to a list of checked port names (none when absent). */
    static List<String> portList(String text) throws HttpError {
        if (text == null || text.isBlank()) {
            return List.of();
        }
        String[] parts = text.split(",");
        if (parts.length > Sampler.MAX_PORTS) {
            throw new HttpError(400, "ports: at most " + Sampler.MAX_PORTS + " ports per stream, got " + parts.length);
        }
        List<String> out = new ArrayList<>();
        for (String p : parts) {
            checkPort(p.trim());
            out.add(p.trim());
        }
        return out;
    }

    private ComponentManagement requireManagement(String name) throws HttpError {
        return management(name).orElseThrow(
                () -> new HttpError(404, "component '" + name + "' has no management service (not installed?)"));
    }

    /** The newest value of an output port with the type's field names, units and element types. */
    PortValueDTO portValue(String name, String port) throws HttpError {
        checkName(name);
        checkPort(port);
        try {
            return requireManagement(name).portValue(port);
        } catch (IllegalArgumentException e) {
            throw new HttpError(404, e.getMessage());
        } catch (IllegalStateException e) {
            throw new HttpError(409, e.getMessage());
        }
    }

    /** A port value for the stream: index, stamps and the values per field (compact). */
    Object portSample(String name, String port) {
        Optional<ComponentManagement> cm = management(name);
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

    /** Every output port of every contract in the cell: component, port, type, method. */
    Map<String, Object> watchablePorts() throws HttpError {
        List<Map<String, Object>> out = new ArrayList<>();
        CellDTO c = drcr().cell();
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

    // ---- debug monitor -------------------------------------------------------------------

    private Path debugJar() throws HttpError, IOException {
        return DebugMonitor.locate(context.getProperty(DebugMonitor.JAR_PROPERTY));
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
        Bundle installed = null;
        for (Bundle b : context.getBundles()) {
            if (DebugMonitor.SYMBOLIC_NAME.equals(b.getSymbolicName())) {
                installed = b;
            }
        }
        m.put("bundleId", installed == null ? null : installed.getBundleId());
        DrcrService d = drcr();
        m.put("component", DebugMonitor.COMPONENT);
        m.put("instance", d.instance(DebugMonitor.COMPONENT).orElse(null));
        m.put("contract", d.contract(DebugMonitor.COMPONENT).orElse(null));
        return m;
    }

    /**
     * Builds the debug-monitor bundle for {@code targets} ({@code comp.port,...}: state ports of
     * type arflex.Sample 1.x in the cell), stages it and returns the DRCR's plan; installed by
     * {@code install?id=} like any staged bundle.
     */
    Map<String, Object> debugStage(String targets) throws HttpError, IOException {
        List<DebugMonitor.Target> ts = DebugMonitor.targets(targets);
        DrcrService d = drcr();
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
        Map<String, Object> m = planStaged(Artifacts.upload(new java.io.ByteArrayInputStream(jar),
                "debug-monitor for " + String.join(", ", ts.stream().map(DebugMonitor.Target::toString).toList()),
                dataDir.resolve("staging")));
        m.put("targets", ts.stream().map(DebugMonitor.Target::toString).toList());
        return m;
    }

    // ---- changing ------------------------------------------------------------------------

    /** Sets a parameter and returns the value the RT half applied. */
    Map<String, Object> setParam(String name, String param, String value) throws HttpError {
        checkName(name);
        if (param == null || param.isBlank()) {
            throw new HttpError(400, "param: missing");
        }
        if (value == null) {
            throw new HttpError(400, "value: missing");
        }
        ComponentManagement cm = management(name).orElseThrow(
                () -> new HttpError(404, "component '" + name + "' has no management service (not installed?)"));
        try {
            String applied = cm.set(param, value.trim());
            return Map.of("component", name, "param", param, "applied", applied);
        } catch (IllegalArgumentException e) {
            throw new HttpError(400, e.getMessage());
        } catch (IllegalStateException e) {
            throw new HttpError(409, e.getMessage());
        }
    }

    /** The cell-level reset (arflex:reset --cell): everything that waits, providers first; what it did. */
    String resetCell() throws HttpError {
        return CellReset.run(drcr(), n -> management(n).orElseThrow(() -> new IllegalStateException(
                "no management service")).reset());
    }

    /** start, stop (the component's bundle) or reset (operator reset of the instance). */
    Map<String, Object> command(String name, String cmd) throws HttpError {
        checkName(name);
        try {
            switch (cmd == null ? "" : cmd) {
                case "reset" -> management(name).orElseThrow(() -> new HttpError(404,
                        "component '" + name + "' has no management service")).reset();
                case "start" -> bundleOf(name).start();
                case "stop" -> bundleOf(name).stop();
                default -> throw new HttpError(400, "cmd: '" + cmd + "' is not start, stop or reset");
            }
        } catch (BundleException | IllegalStateException e) {
            throw new HttpError(409, cmd + " " + name + ": " + e.getMessage());
        }
        return Map.of("component", name, "done", cmd);
    }

    private Bundle bundleOf(String name) throws HttpError {
        Optional<ContractDTO> c = drcr().contract(name);
        // A stopped bundle's contract leaves the cell; remember where it was so start works.
        Long id = c.map(x -> x.bundleId).orElse(knownBundles.get(name));
        if (id == null) {
            throw new HttpError(404, "no contract named '" + name + "'");
        }
        knownBundles.put(name, id);
        Bundle b = context.getBundle(id);
        if (b == null) {
            knownBundles.remove(name);
            throw new HttpError(404, "the bundle " + id + " of '" + name + "' is gone");
        }
        return b;
    }

    /** Stages a bundle from a URL with a pinned hash and returns its plan. */
    Map<String, Object> stageUrl(String url, String sha256) throws HttpError, IOException {
        var u = Artifacts.checkUrl(url, sha256);
        return planStaged(Artifacts.fetch(u, sha256, dataDir.resolve("staging"), stageSources));
    }

    /** Stages an uploaded bundle and returns its plan. */
    Map<String, Object> stageUpload(InputStream body, String fileName) throws HttpError, IOException {
        return planStaged(Artifacts.upload(body, fileName, dataDir.resolve("staging")));
    }

    private Map<String, Object> planStaged(Artifacts.Staged s) throws HttpError, IOException {
        if (staged.size() >= MAX_STAGED) {
            Files.deleteIfExists(s.file());
            throw new HttpError(429, "too many staged bundles waiting for confirmation; install or discard one");
        }
        String plan;
        try {
            plan = drcr().planInstall(s.file().toUri().toString());
        } catch (HttpError e) {
            Files.deleteIfExists(s.file());
            throw e;
        } catch (RuntimeException e) {
            // No plan, nothing to confirm: the staged jar goes and the error names why.
            Files.deleteIfExists(s.file());
            throw new HttpError(409, "the DRCR could not plan the install of " + s.symbolicName() + " " + s.version()
                    + " (from " + s.origin() + "), nothing staged: " + reason(e));
        }
        byte[] id = new byte[16];
        random.nextBytes(id);
        String key = HexFormat.of().formatHex(id);
        staged.put(key, s);
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("id", key);
        m.put("origin", s.origin());
        m.put("sha256", s.sha256());
        m.put("symbolicName", s.symbolicName());
        m.put("version", s.version());
        m.put("plan", plan);
        return m;
    }

    /** Installs (or updates, when a bundle with that symbolic name exists) a staged bundle. */
    Map<String, Object> installStaged(String id) throws HttpError, IOException {
        Artifacts.Staged s = id == null ? null : staged.remove(id);
        if (s == null) {
            throw new HttpError(404, "id: no staged bundle with this id (expired or already installed)");
        }
        Path kept = Artifacts.keep(s, dataDir.resolve("installed"));
        String location = kept.toUri().toString();
        // The DRCR runs RT halves only of code verified against a pin (docs/DECISIONS.md D12):
        // the staged jar was checked against the SHA-256 the operator pinned and confirmed.
        UpdateService u = updates;
        if (u == null) {
            throw new HttpError(503, "the DRCR is not running (no UpdateService registered)");
        }
        try {
            u.verified(Files.readAllBytes(kept), s.sha256(), "console Deploy of " + s.origin());
        } catch (IllegalArgumentException e) {
            throw new HttpError(409, "install of " + s.symbolicName() + " refused: " + e.getMessage());
        }
        try (InputStream in = Files.newInputStream(kept)) {
            Bundle existing = null;
            for (Bundle b : context.getBundles()) {
                if (s.symbolicName().equals(b.getSymbolicName())) {
                    existing = b;
                }
            }
            Bundle b;
            String action;
            if (existing != null) {
                existing.update(in);
                b = existing;
                action = "updated";
            } else {
                b = context.installBundle(location, in);
                action = "installed";
            }
            b.start();
            return Map.of("bundleId", b.getBundleId(), "symbolicName", s.symbolicName(), "action", action,
                    "sha256", s.sha256());
        } catch (BundleException e) {
            throw new HttpError(409, "install of " + s.symbolicName() + " failed: " + e.getMessage());
        }
    }

    /** Drops a staged bundle without installing it. */
    Map<String, Object> discard(String id) throws IOException {
        Artifacts.Staged s = id == null ? null : staged.remove(id);
        if (s != null) {
            Files.deleteIfExists(s.file());
        }
        return Map.of("discarded", s != null);
    }

    Map<String, Object> planUninstall(String name) throws HttpError {
        checkName(name);
        return Map.of("component", name, "plan", drcr().planUninstall(name));
    }

    Map<String, Object> uninstall(String name) throws HttpError {
        Bundle b = bundleOf(name);
        long id = b.getBundleId();
        try {
            b.uninstall();
        } catch (BundleException e) {
            throw new HttpError(409, "uninstall of " + name + " failed: " + e.getMessage());
        }
        return Map.of("component", name, "bundleId", id, "action", "uninstalled");
    }

    /**
     * The DRCR's dry run of {@code update name}: it downloads from the contract's update URL,
     * checks the pinned SHA-256 and the new contracts, and plans the replacement without
     * installing anything. A failure (no update URL, download, hash mismatch, broken bundle) is
     * an error (404 unknown component, 409 otherwise), never a plan that could be confirmed.
     */
    Map<String, Object> planUpdate(String name) throws HttpError {
        checkName(name);
        DrcrService d = drcr();
        ContractDTO c = d.contract(name).orElseThrow(
                () -> new HttpError(404, "cannot plan the update of " + name + ": no component named '" + name
                        + "' in the cell"));
        String plan;
        try {
            plan = d.planUpdate(name);
        } catch (IllegalArgumentException e) {
            throw new HttpError(404, "cannot plan the update of " + name + ": " + unprefixed(name, reason(e)));
        } catch (RuntimeException e) {
            throw new HttpError(409, "cannot plan the update of " + name + ": " + unprefixed(name, reason(e)));
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("component", name);
        m.put("version", c.version);
        m.put("updateUrl", c.updateUrl);
        m.put("sha256", c.updateSha256);
        m.put("plan", plan);
        return m;
    }

    /**
     * Updates from the contract's update URL. With {@code sha256} (the pin the shown plan was
     * made for), a contract that pins something else by now is refused: plan again.
     */
    Map<String, Object> update(String name, String sha256) throws HttpError {
        checkName(name);
        UpdateService u = updates;
        if (u == null) {
            throw new HttpError(503, "no UpdateService registered (DRCR not running)");
        }
        if (sha256 != null && !sha256.isBlank()) {
            String pinned = drcr().contract(name).map(c -> c.updateSha256).orElse(null);
            if (pinned == null || !pinned.equalsIgnoreCase(sha256.trim())) {
                throw new HttpError(409, "update of " + name + " refused: the contract now pins "
                        + (pinned == null ? "no update" : "SHA-256 " + pinned) + ", the plan shown was for " + sha256.trim()
                        + "; plan the update again");
            }
        }
        try {
            return Map.of("component", name, "report", u.update(name));
        } catch (IllegalStateException | IllegalArgumentException e) {
            throw new HttpError(409, "update of " + name + " refused: " + e.getMessage());
        }
    }

    // ---- contracts -----------------------------------------------------------------------

    List<Problem> validate(String xml, String source) {
        return parser.validate(xml, source);
    }

    Map<String, Object> saveContract(String name, String xml) throws HttpError, IOException {
        checkName(name);
        List<Problem> problems = validate(xml, name + ".xml");
        if (!problems.isEmpty()) {
            Map<String, Object> m = new LinkedHashMap<>();
            m.put("saved", false);
            m.put("problems", problems);
            return m;
        }
        Path dir = Files.createDirectories(contractsDir);
        Path tmp = Files.createTempFile(dir, name, ".tmp");
        Files.writeString(tmp, xml, StandardCharsets.UTF_8);
        Path target = dir.resolve(name + ".xml");
        Files.move(tmp, target, StandardCopyOption.REPLACE_EXISTING, StandardCopyOption.ATOMIC_MOVE);
        return Map.of("saved", true, "path", target.toString(), "problems", List.of());
    }

    List<String> savedContracts() throws IOException {
        if (!Files.isDirectory(contractsDir)) {
            return List.of();
        }
        List<String> names = new ArrayList<>();
        try (Stream<Path> s = Files.list(contractsDir)) {
            s.map(p -> p.getFileName().toString()).filter(f -> f.endsWith(".xml")).sorted()
                    .forEach(f -> names.add(f.substring(0, f.length() - 4)));
        }
        return names;
    }

    String loadContract(String name) throws HttpError, IOException {
        checkName(name);
        Path p = contractsDir.resolve(name + ".xml");
        if (!Files.isRegularFile(p)) {
            throw new HttpError(404, "no saved contract named '" + name + "'");
        }
        return Files.readString(p, StandardCharsets.UTF_8);
    }

    /** An exception's message, or its class when it has none. */
    private static String reason(RuntimeException e) {
        String m = e.getMessage();
        return m == null || m.isBlank() ? e.getClass().getSimpleName() : m;
    }

    /** The DRCR starts its update messages with "name: "; said once is enough. */
    private static String unprefixed(String name, String message) {
        return message.startsWith(name + ": ") ? message.substring(name.length() + 2) : message;
    }

    static void checkName(String name) throws HttpError {
        if (name == null || !NAME.matcher(name).matches()) {
            throw new HttpError(400, "name: '" + name + "' is not a component name (letters, digits, . _ -; up to 64)");
        }
    }
}
