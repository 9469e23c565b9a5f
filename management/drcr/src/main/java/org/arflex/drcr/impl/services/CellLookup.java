package org.arflex.drcr.impl.services;

import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.Instance;

/** Looks up the cell's instances for the change sets' service, on the actor, which alone changes the registry. */
final class CellLookup {

    private CellLookup() {
    }

    /** The instance of that name, or null. */
    static Instance find(Cell cell, String name) {
        return cell.actor().call(() -> cell.instance(name).orElse(null), Services.CALL_MS);
    }
}
