package org.arflex.webconsole.impl;

import java.util.LinkedHashMap;
import java.util.Map;
import org.arflex.drcr.CellReset;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.ResourceManager;

/** The Cell page's endpoints (the Graph page reads {@code api/cell} too): the cell, and the cell-level reset. */
final class CellBackend {
    private final Backend backend;

    CellBackend(Backend backend) {
        this.backend = backend;
    }

    Routes routes() {
        return new Routes()
                .get("cell", call -> cell())
                .post("reset-cell", call -> Map.of("result", resetCell()));
    }

    /** The cell, or an object saying the DRCR is absent. */
    Map<String, Object> cell() {
        Map<String, Object> m = new LinkedHashMap<>();
        DrcrService d = backend.drcr;
        m.put("drcr", d != null);
        if (d != null) {
            m.put("cell", d.cell());
            ResourceManager rm = backend.resources;
            if (rm != null) {
                m.put("resources", rm.resources());
            }
        }
        return m;
    }

    /** The cell-level reset (arflex:reset --cell): everything that waits, providers first; what it did. */
    String resetCell() throws HttpError {
        return CellReset.run(backend.drcr(), n -> backend.management(n).orElseThrow(() -> new IllegalStateException(
                "no management service")).reset());
    }
}
