package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import jakarta.servlet.http.HttpServletRequest;
import java.io.IOException;
import java.util.LinkedHashMap;
import java.util.Map;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/**
 * Audit page: the newest entries of the console's audit log ({@link AuditLog}, written by
 * {@link AuditFilter}) and the bundles {@link MarkupGate} keeps from resolving.
 */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-audit",
    "felix.webconsole.title=Audit",
    "felix.webconsole.category=ARFLEX"})
public class AuditPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;
    /** Most entries one answer carries. */
    static final int MAX_ENTRIES = 500;

    @Reference
    private Backend backend;
    @Reference
    private AuditFilter audit;
    @Reference
    private MarkupGate gate;

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    String page() {
        return "audit";
    }

    @Override
    String label() {
        return "arflex-audit";
    }

    @Override
    Object pageGet(String what, HttpServletRequest req) throws HttpError, IOException {
        if (!what.equals("audit")) {
            return super.pageGet(what, req);
        }
        int max = MAX_ENTRIES;
        String n = req.getParameter("max");
        if (n != null) {
            try {
                max = Math.max(1, Math.min(MAX_ENTRIES, Integer.parseInt(n)));
            } catch (NumberFormatException e) {
                throw new HttpError(400, "max: '" + n + "' is not a number");
            }
        }
        AuditLog log = audit.log();
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("file", log.file().toString());
        m.put("entries", log.recent(max));
        m.put("refusedBundles", gate.refusals());
        return m;
    }
}
