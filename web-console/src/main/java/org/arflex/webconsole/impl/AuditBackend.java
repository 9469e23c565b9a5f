package org.arflex.webconsole.impl;

import java.io.IOException;
import java.util.LinkedHashMap;
import java.util.Map;

/**
 * The Audit page's endpoint ({@code api/audit}, served by that page only): the newest entries of
 * the console's audit log ({@link AuditLog}, written by {@link AuditFilter}), the security history
 * and the refusals of the current minute counted but not written ({@link AuditTrail}), and the
 * bundles {@link MarkupGate} keeps from resolving.
 */
final class AuditBackend {
    /** Most entries one answer carries. */
    static final int MAX_ENTRIES = 500;

    private final AuditFilter audit;
    private final MarkupGate gate;

    AuditBackend(AuditFilter audit, MarkupGate gate) {
        this.audit = audit;
        this.gate = gate;
    }

    Routes routes() {
        return new Routes().get("audit", call -> audit(call.param("max")));
    }

    /**
     * The log's file, its newest {@code max} entries (1 to {@value #MAX_ENTRIES}; that many when
     * absent), the same of the security history, the refusals not written, the refused bundles.
     */
    Map<String, Object> audit(String max) throws HttpError, IOException {
        int n = MAX_ENTRIES;
        if (max != null) {
            try {
                n = Math.max(1, Math.min(MAX_ENTRIES, Integer.parseInt(max)));
            } catch (NumberFormatException e) {
                throw new HttpError(400, "max: '" + max + "' is not a number");
            }
        }
        AuditTrail trail = audit.trail();
        AuditLog log = trail.main();
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("file", log.file().toString());
        m.put("entries", log.recent(n));
        m.put("securityFile", trail.security().file().toString());
        m.put("security", trail.security().recent(n));
        m.put("refusalsNotWritten", trail.refusalsNotWritten());
        m.put("refusedBundles", gate.refusals());
        return m;
    }
}
