package org.arflex.drcr.impl.services;

import java.util.HashMap;
import java.util.Hashtable;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.Executor;
import java.util.concurrent.RejectedExecutionException;
import java.util.concurrent.atomic.AtomicReference;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.impl.runtime.Cell;
import org.osgi.framework.BundleContext;
import org.osgi.framework.ServiceRegistration;

/**
 * One {@link ComponentManagement} registration per instance, its {@code arflex.state} property
 * kept in step with the cell.
 *
 * <p>The actor only takes a picture of the names and states ({@link #sync}); the registrations
 * are made on the registrar's thread (D54). OSGi delivers service events synchronously, to
 * every listener of the framework: made on the actor, one change held supervision for 0.35 ms
 * at the median and up to 28 ms (measured under load), several times per install. Pictures
 * that come while one is being applied are coalesced: the registrar applies the newest.
 */
public final class ManagementRegistrations {

    private final Cell cell;
    private final BundleContext context;
    private final Executor registrar;
    private final AtomicReference<Map<String, String>> pending = new AtomicReference<>();
    /** Registrar thread (or the closer, once the registrar is gone). */
    private final Map<String, ServiceRegistration<ComponentManagement>> regs = new HashMap<>();
    /** The state each registration's {@link ComponentManagement#STATE_PROPERTY} shows. */
    private final Map<String, String> states = new HashMap<>();
    private boolean closed;

    /**
     * @param registrar where registrations are made: one thread of their own (a caller that
     *                  passes {@code Runnable::run} has them made on the calling thread)
     */
    public ManagementRegistrations(Cell cell, BundleContext context, Executor registrar) {
        this.cell = cell;
        this.context = context;
        this.registrar = registrar;
    }

    /** The cell changed (actor thread): its names and states, to be registered. */
    public void sync() {
        Map<String, String> now = new LinkedHashMap<>();
        for (String n : cell.names()) {
            now.put(n, cell.state(n));
        }
        if (pending.getAndSet(now) != null) {
            return; // the registrar has not applied the last picture yet: it applies this one
        }
        try {
            registrar.execute(this::apply);
        } catch (RejectedExecutionException e) {
            apply(); // the registrar is gone (the DRCR stops): here, as the cell changes
        }
    }

    private synchronized void apply() {
        Map<String, String> now = pending.getAndSet(null);
        if (now == null || closed) {
            return;
        }
        for (String n : List.copyOf(regs.keySet())) {
            if (!now.containsKey(n)) {
                unregister(regs.remove(n));
                states.remove(n);
            }
        }
        for (var e : now.entrySet()) {
            String n = e.getKey();
            String state = e.getValue();
            if (regs.containsKey(n) && state.equals(states.get(n))) {
                continue;
            }
            Hashtable<String, Object> props = new Hashtable<>();
            props.put(ComponentManagement.COMPONENT_PROPERTY, n);
            props.put(ComponentManagement.STATE_PROPERTY, state);
            try {
                if (regs.containsKey(n)) {
                    regs.get(n).setProperties(props);
                } else {
                    regs.put(n, context.registerService(ComponentManagement.class, new ComponentManagementImpl(n, cell), props));
                }
                states.put(n, state);
            } catch (IllegalStateException ex) {
                return; // the DRCR bundle is stopping
            }
        }
    }

    /**
     * Unregisters every ComponentManagement service; later changes register nothing. Called
     * once the registrar has ended (it must not be applying a picture meanwhile).
     */
    public synchronized void close() {
        closed = true;
        for (var r : regs.values()) {
            unregister(r);
        }
        regs.clear();
        states.clear();
    }

    private static void unregister(ServiceRegistration<?> r) {
        try {
            r.unregister();
        } catch (IllegalStateException ignored) {
            // already gone with the bundle
        }
    }
}
