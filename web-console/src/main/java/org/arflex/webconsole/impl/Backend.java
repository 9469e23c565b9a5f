package org.arflex.webconsole.impl;

import com.fasterxml.jackson.databind.ObjectMapper;
import java.io.IOException;
import java.nio.file.Path;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.concurrent.ConcurrentHashMap;
import org.arflex.contract.ContractParser;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.UpdateService;
import org.arflex.drcr.dto.ContractDTO;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.service.component.annotations.Activate;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Deactivate;
import org.osgi.service.component.annotations.Reference;
import org.osgi.service.component.annotations.ReferenceCardinality;
import org.osgi.service.component.annotations.ReferencePolicy;

/**
 * The console's side of the cell, shared by every page backend ({@link CellBackend},
 * {@link ComponentBackend}, {@link DeployBackend}, {@link DebugBackend},
 * {@link ContractBackend}): the DRCR's DTO services and the bundle life cycle, with lookups that
 * fail naming what is absent. The DRCR services are optional and dynamic: the console keeps
 * working (and says so) while the DRCR is absent or restarting. On activation it builds the page
 * backends and the table of their endpoints ({@link #routes}), which every page serves.
 */
@Component(service = Backend.class, immediate = true)
public class Backend {
    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    volatile DrcrService drcr;
    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    volatile ResourceManager resources;
    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    volatile UpdateService updates;
    @Reference(cardinality = ReferenceCardinality.MULTIPLE, policy = ReferencePolicy.DYNAMIC)
    volatile List<ComponentManagement> components;

    final ObjectMapper json = new ObjectMapper();
    private final Map<String, Long> knownBundles = new ConcurrentHashMap<>();
    private BundleContext context;
    private StagingArea staging;
    private Routes routes;
    Sampler sampler;

    @Activate
    void activate(BundleContext bc) throws IOException {
        this.context = bc;
        Path dataDir = bc.getDataFile("").toPath();
        String configured = bc.getProperty("arflex.contracts.dir");
        String home = System.getenv("ARFLEX_HOME");
        Path contractsDir = configured != null ? Path.of(configured)
                : home != null ? Path.of(home, "contracts") : dataDir.resolve("contracts");
        ContractParser parser = ContractParser.create();
        this.staging = new StagingArea(this, dataDir.resolve("staging"));
        ComponentBackend component = new ComponentBackend(this);
        this.sampler = new Sampler(component::sample, component::portSample);
        this.routes = new Routes()
                .add(new CellBackend(this).routes())
                .add(component.routes())
                .add(new DeployBackend(this, staging, dataDir.resolve("installed"),
                        StagingSources.parse(bc.getProperty(StagingSources.PROPERTY))).routes())
                .add(new DebugBackend(this, staging, parser).routes())
                .add(new ContractBackend(contractsDir, parser).routes());
        staging.clean();
    }

    @Deactivate
    void deactivate() throws IOException {
        sampler.close();
        staging.clean();
    }

    BundleContext context() {
        return context;
    }

    /** The endpoints every page serves. */
    Routes routes() {
        return routes;
    }

    DrcrService drcr() throws HttpError {
        DrcrService d = drcr;
        if (d == null) {
            throw new HttpError(503, "the DRCR is not running (no DrcrService registered)");
        }
        return d;
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

    ComponentManagement requireManagement(String name) throws HttpError {
        return management(name).orElseThrow(
                () -> new HttpError(404, "component '" + name + "' has no management service (not installed?)"));
    }

    /** The bundle of a component's contract; also of one stopped since (its contract left the cell). */
    Bundle bundleOf(String name) throws HttpError {
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

    /** The bundle with this symbolic name (the last the framework lists), or null. */
    Bundle bundleNamed(String symbolicName) {
        Bundle found = null;
        for (Bundle b : context.getBundles()) {
            if (symbolicName.equals(b.getSymbolicName())) {
                found = b;
            }
        }
        return found;
    }
}
