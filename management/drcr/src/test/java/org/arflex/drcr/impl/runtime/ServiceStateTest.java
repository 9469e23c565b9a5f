package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.lang.reflect.Proxy;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Dictionary;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.services.ManagementRegistrations;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.Test;
import org.osgi.framework.BundleContext;
import org.osgi.framework.ServiceRegistration;

/**
 * Readiness as a service: each ComponentManagement registration carries the instance's state in
 * {@code arflex.state}, changed with it (over a registry stub that records what the DRCR did).
 */
class ServiceStateTest {

    private final ManualActor actor = new ManualActor();
    private final FakeLauncher launcher = new FakeLauncher();
    private final List<String> log = new ArrayList<>();
    /** name -> the properties of its registration now; absent once unregistered. */
    private final Map<String, Map<String, Object>> registry = new LinkedHashMap<>();
    private final List<String> events = new ArrayList<>();

    private static String contract(String name, String ports) {
        return "<component xmlns=\"urn:arflex:contract:1\" name=\"" + name + "\" version=\"1.0.0\">"
                + "<implementation executable=\"" + name + "\" task=\"periodic\" movesHardware=\"false\"/>"
                + "<ports>" + ports + "</ports>"
                + "<timing period=\"1ms\" deadline=\"1ms\" wcet=\"50us\" priority=\"80\"/>"
                + "<resources memory=\"1MiB\" network=\"0\"/><criticality>5</criticality>"
                + "<fault restart=\"permanent\" intensity=\"2\" window=\"10s\" backoff=\"100ms\" safe=\"hold\""
                + " heartbeatTimeout=\"100ms\"/></component>";
    }

    private static final String PROVIDER = contract("prov",
            "<out name=\"y\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>");
    private static final String CONSUMER = contract("cons",
            "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"><bind component=\"prov\" port=\"y\"/></in>");

    private static Map<String, Object> map(Dictionary<?, ?> d) {
        Map<String, Object> m = new LinkedHashMap<>();
        for (var k = d.keys(); k.hasMoreElements(); ) {
            Object key = k.nextElement();
            m.put((String) key, d.get(key));
        }
        return m;
    }

    /** A registry stub: registerService, and on the registration setProperties and unregister. */
    private BundleContext context() {
        return (BundleContext) Proxy.newProxyInstance(getClass().getClassLoader(), new Class<?>[] {BundleContext.class},
                (p, m, a) -> {
                    if (!m.getName().equals("registerService") || a[0] != ComponentManagement.class) {
                        throw new UnsupportedOperationException(m.getName());
                    }
                    String name = ((ComponentManagement) a[1]).name();
                    registry.put(name, map((Dictionary<?, ?>) a[2]));
                    events.add("REGISTERED " + registry.get(name));
                    return Proxy.newProxyInstance(getClass().getClassLoader(), new Class<?>[] {ServiceRegistration.class},
                            (p2, m2, a2) -> {
                                switch (m2.getName()) {
                                    case "setProperties" -> {
                                        registry.put(name, map((Dictionary<?, ?>) a2[0]));
                                        events.add("MODIFIED " + registry.get(name));
                                    }
                                    case "unregister" -> {
                                        registry.remove(name);
                                        events.add("UNREGISTERING " + name);
                                    }
                                    default -> throw new UnsupportedOperationException(m2.getName());
                                }
                                return null;
                            });
                });
    }

    private void install(Cell cell, String xml) throws Exception {
        Contract c = ContractParser.create(PortTypes.builtin()).parse(xml, "test.xml");
        assertTrue(actor.call(() -> cell.install(c, c.name().hashCode(), Path.of("/nonexistent/" + c.name())), 0), log::toString);
        actor.runAll();
    }

    private String state(String name) {
        return (String) registry.get(name).get(ComponentManagement.STATE_PROPERTY);
    }

    @Test
    void theStatePropertyFollowsTheInstance() throws Exception {
        Cell cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> 1_000_000_000L, false),
                actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add);
        ManagementRegistrations services = new ManagementRegistrations(cell, context(), Runnable::run);
        cell.onChange(services::sync);

        install(cell, CONSUMER);
        assertEquals("UNSATISFIED", state("cons"), events.toString());
        assertEquals("cons", registry.get("cons").get(ComponentManagement.COMPONENT_PROPERTY));

        install(cell, PROVIDER);
        assertEquals("ACTIVE", state("prov"), events.toString());
        assertEquals("ACTIVE", state("cons"), events.toString());
        assertEquals(2, events.stream().filter(e -> e.startsWith("REGISTERED")).count(), "one registration each: " + events);
        int seen = events.size();
        actor.call(() -> {
            services.sync();
            return null;
        }, 0);
        assertEquals(seen, events.size(), "no MODIFIED event without a change of state: " + events);

        actor.call(() -> cell.uninstall("prov", "bundle stopped"), 0);
        actor.runAll();
        assertEquals("UNSATISFIED", state("cons"), events.toString());
        assertTrue(!registry.containsKey("prov"), events.toString());
        assertTrue(events.contains("UNREGISTERING prov"), events.toString());
        actor.call(() -> {
            cell.shutdownAll("test end");
            services.close();
            return null;
        }, 0);
        actor.runAll();
        assertEquals(Map.of(), registry);
    }

    @Test
    void registrationsAreMadeOnTheRegistrarNotOnTheActorAndOnlyTheNewestPictureIsApplied() throws Exception {
        Cell cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> 1_000_000_000L, false),
                actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add);
        List<Runnable> registrar = new ArrayList<>();
        ManagementRegistrations services = new ManagementRegistrations(cell, context(), registrar::add);
        cell.onChange(services::sync);

        install(cell, CONSUMER); // UNSATISFIED
        install(cell, PROVIDER); // then both ACTIVE: several changes on the actor
        assertEquals(Map.of(), registry, "the actor registered nothing itself: " + events);
        assertEquals(1, registrar.size(), "pictures taken while one waits are coalesced");
        registrar.remove(0).run();
        assertEquals("ACTIVE", state("prov"), events.toString());
        assertEquals("ACTIVE", state("cons"), events.toString());
        assertEquals(List.of("REGISTERED", "REGISTERED"), events.stream().map(e -> e.split(" ")[0]).toList(),
                "the newest picture only, nothing of the states in between: " + events);

        // the DRCR stops: the registrar has ended, the actor closes; later changes register nothing
        services.close();
        assertEquals(Map.of(), registry);
        actor.call(() -> cell.uninstall("prov", "bundle stopped"), 0);
        actor.runAll();
        registrar.forEach(Runnable::run);
        assertEquals(Map.of(), registry, events.toString());
    }
}
