package org.arflex.drcr.impl.services;

import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.PortValueDTO;
import org.arflex.drcr.dto.StatsDTO;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.PortValues;
import org.arflex.drcr.impl.runtime.Snapshots;

/** The management service of one instance; every call runs on the actor thread (a port read only its lookup). */
final class ComponentManagementImpl implements ComponentManagement {

    private final String name;
    private final Cell cell;

    ComponentManagementImpl(String name, Cell cell) {
        this.name = name;
        this.cell = cell;
    }

    @Override
    public String name() {
        return name;
    }

    @Override
    public InstanceDTO instance() {
        return cell.actor().call(() -> Snapshots.instance(cell, name)
                .orElseThrow(() -> new IllegalStateException("component '" + name + "' is gone")), Services.CALL_MS);
    }

    @Override
    public String state() {
        return instance().state;
    }

    @Override
    public String get(String param) {
        return cell.actor().call(() -> cell.getParam(name, param), Services.CALL_MS);
    }

    @Override
    public String set(String param, String value) {
        return cell.actor().call(() -> cell.setParam(name, param, value), Services.CALL_MS);
    }

    @Override
    public StatsDTO stats() {
        return instance().stats;
    }

    @Override
    public PortValueDTO portValue(String port) {
        // Only the lookup runs on the actor; the read itself maps the segment read-only here.
        PortValues.Ref ref = cell.actor().call(() -> PortValues.ref(cell, name, port), Services.CALL_MS);
        return PortValues.read(ref, cell.config().monotonicNs().getAsLong());
    }

    @Override
    public void reset() {
        cell.actor().call(() -> cell.reset(name), Services.CALL_MS);
    }
}
