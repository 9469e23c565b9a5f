package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.net.URI;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.ArrayList;
import java.util.HexFormat;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.function.Consumer;
import java.util.jar.Manifest;
import org.arflex.contract.Contract;
import org.arflex.contract.UpdateSpec;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.UpdateService;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ContractReader;
import org.arflex.drcr.impl.runtime.Snapshots;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;

/**
 * The DRCR's services: the read-only {@link DrcrService} and the {@link UpdateService} (the
 * registrations of one {@link ComponentManagement} per instance: {@link ManagementRegistrations}).
 */
public final class Services implements DrcrService, UpdateService {

    /** Timeout of a call into the actor (starting a component can take a few seconds). */
    static final long CALL_MS = 60_000;

    private final Cell cell;
    private final ResourceManagerImpl resources;
    private final ContractReader reader;
    private final BundleContext context;
    private final Consumer<String> log;
    private final CodeGate gate;

    public Services(Cell cell, ResourceManagerImpl resources, ContractReader reader, BundleContext context,
                    CodeGate gate, Consumer<String> log) {
        this.cell = cell;
        this.gate = gate;
        this.resources = resources;
        this.reader = reader;
        this.context = context;
        this.log = log;
    }

    /** The management service of one instance (for the shell, without a registry lookup). */
    public Optional<ComponentManagement> management(String name) {
        return cell.actor().call(() -> cell.names().contains(name)
                ? Optional.<ComponentManagement>of(new ComponentManagementImpl(name, cell)) : Optional.empty(), CALL_MS);
    }

    // ---- DrcrService -------------------------------------------------------------------------

    @Override
    public CellDTO cell() {
        ResourceManager r = resources;
        var res = r.resources();
        return cell.actor().call(() -> Snapshots.cell(cell, res), CALL_MS);
    }

    @Override
    public Optional<InstanceDTO> instance(String name) {
        return cell.actor().call(() -> Snapshots.instance(cell, name), CALL_MS);
    }

    @Override
    public Optional<ContractDTO> contract(String name) {
        return cell.actor().call(() -> Snapshots.contract(cell, name), CALL_MS);
    }

    @Override
    public String planInstall(String location) {
        byte[] jar;
        try {
            jar = Fetch.read(URI.create(location));
        } catch (IOException | IllegalArgumentException e) {
            throw new IllegalArgumentException("cannot read " + location + ": " + e.getMessage());
        }
        ContractReader.Result r = readJar(location, jar);
        StringBuilder sb = new StringBuilder();
        for (String p : r.problems()) {
            sb.append("problem: ").append(p).append('\n');
        }
        if (r.contracts().isEmpty()) {
            return sb.append("no valid contract in ").append(location).toString();
        }
        Change.Builder b = Change.builder();
        r.contracts().forEach(b::put);
        return sb + cell.actor().call(() -> cell.dryRun(b.build()).toText(), CALL_MS);
    }

    @Override
    public String planUpdate(String name) {
        Fetched f = fetchUpdate(name);
        Change.Builder b = Change.builder();
        f.result().contracts().forEach(b::put);
        return "update of " + name + " from " + f.url() + " (sha256 verified)\n"
                + cell.actor().call(() -> cell.dryRun(b.build()).toText(), CALL_MS);
    }

    @Override
    public String planUninstall(String name) {
        return cell.actor().call(() -> {
            Long bundle = cell.instance(name).map(i -> i.bundleId).orElseThrow(
                    () -> new IllegalArgumentException("no component '" + name + "'"));
            Change.Builder b = Change.builder();
            cell.namesOfBundle(bundle).forEach(b::uninstall);
            return cell.dryRun(b.build()).toText();
        }, CALL_MS);
    }

    @Override
    public String planCapacity(List<Integer> cpus, long memoryBytes, long networkBps) {
        Capacities caps = resources.capacities(cpus, memoryBytes, networkBps);
        return cell.actor().call(() -> cell.dryRun(Change.capacities(caps)).toText(), CALL_MS);
    }

    // ---- UpdateService -----------------------------------------------------------------------

    /** A downloaded, hash-checked and readable update. */
    private record Fetched(long bundleId, String url, byte[] jar, String sha, ContractReader.Result result) {
    }

    /** Download, pinned hash, contracts: every check before anything is installed. */
    private Fetched fetchUpdate(String name) {
        record Target(UpdateSpec spec, long bundleId) {
        }
        Target t = cell.actor().call(() -> {
            var inst = cell.instance(name).orElseThrow(() -> new IllegalArgumentException("no component '" + name + "'"));
            UpdateSpec u = inst.contract().update().orElseThrow(() -> new IllegalStateException(
                    name + ": its contract has no update URL"));
            return new Target(u, inst.bundleId);
        }, CALL_MS);
        byte[] jar;
        try {
            jar = Fetch.read(t.spec().url());
        } catch (IOException | IllegalArgumentException e) {
            throw new IllegalStateException(name + ": update not installed, the old version keeps running: cannot download "
                    + t.spec().url() + ": " + e.getMessage());
        }
        String got = sha256(jar);
        if (!got.equalsIgnoreCase(t.spec().sha256())) {
            throw new IllegalStateException(name + ": update not installed, the old version keeps running: SHA-256 of "
                    + t.spec().url() + " is " + got + ", the contract pins " + t.spec().sha256());
        }
        ContractReader.Result r = readJar(t.spec().url().toString(), jar);
        if (!r.problems().isEmpty() || r.contracts().stream().noneMatch(c -> c.name().equals(name))) {
            throw new IllegalStateException(name + ": update not installed, the old version keeps running: the new bundle "
                    + (r.problems().isEmpty() ? "has no contract for " + name : "is broken:\n" + String.join("\n", r.problems())));
        }
        return new Fetched(t.bundleId(), t.spec().url().toString(), jar, got, r);
    }

    @Override
    public String update(String name) {
        Fetched f = fetchUpdate(name);
        Bundle b = context.getBundle(f.bundleId());
        if (b == null) {
            throw new IllegalStateException(name + ": bundle " + f.bundleId() + " is gone");
        }
        try {
            gate.verified(f.jar(), "arflex:update " + name + " from " + f.url() + ", sha256 " + f.sha());
            b.update(new ByteArrayInputStream(f.jar()));
        } catch (BundleException | IOException e) {
            throw new IllegalStateException(name + ": bundle update failed, the old version keeps running: " + e.getMessage());
        }
        String v = f.result().contracts().stream().filter(c -> c.name().equals(name)).map(Contract::version).findFirst()
                .orElse("?");
        log.accept("arflex: updated bundle " + f.bundleId() + " from " + f.url() + " (sha256 " + f.sha() + ")");
        return name + ": updated to " + v + " from " + f.url() + " (sha256 verified)";
    }

    @Override
    public void verified(byte[] jar, String sha256, String origin) {
        String got = sha256(jar);
        if (!got.equalsIgnoreCase(sha256)) {
            throw new IllegalArgumentException("SHA-256 of " + origin + " is " + got + ", not " + sha256);
        }
        try {
            gate.verified(jar, origin + ", sha256 " + got);
        } catch (IOException e) {
            throw new IllegalArgumentException(origin + " is not a jar: " + e.getMessage());
        }
    }

    static String sha256(byte[] data) {
        try {
            MessageDigest md = MessageDigest.getInstance("SHA-256");
            ContentDigest.update(md, data);
            return HexFormat.of().formatHex(md.digest());
        } catch (NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }

    /** Reads the contracts of a jar held in memory (a broken jar is a problem, not an exception). */
    public ContractReader.Result readJar(String label, byte[] jar) {
        Map<String, byte[]> entries;
        String header;
        try {
            entries = new BoundedJar(label).entries(jar);
            Manifest m = BoundedJar.manifest(entries);
            if (m == null) {
                return new ContractReader.Result(List.of(), List.of(label + ": not a bundle (no manifest)"));
            }
            header = m.getMainAttributes().getValue(ContractReader.HEADER);
        } catch (IOException | RuntimeException e) {
            return new ContractReader.Result(List.of(), List.of(label + ": broken jar: " + e.getMessage()));
        }
        if (header == null) {
            return new ContractReader.Result(List.of(), List.of(label + ": no " + ContractReader.HEADER + " header"));
        }
        List<String> problems = new ArrayList<>();
        ContractReader.Result r = reader.read(label, header, p -> {
            byte[] b = entries.get(p);
            return b == null ? null : new ByteArrayInputStream(b);
        });
        problems.addAll(r.problems());
        return new ContractReader.Result(r.contracts(), problems);
    }
}
