package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import org.osgi.service.component.annotations.Activate;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/**
 * Audit page: the newest entries of the console's audit log ({@link AuditLog}, written by
 * {@link AuditFilter}) and the bundles {@link MarkupGate} keeps from resolving; its endpoint,
 * {@code api/audit} ({@link AuditBackend}), is served by this page only.
 */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-audit",
    "felix.webconsole.title=Audit",
    "felix.webconsole.category=ARFLEX"})
public class AuditPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;

    @Reference
    private Backend backend;
    @Reference
    private AuditFilter audit;
    @Reference
    private MarkupGate gate;
    private Routes routes;

    @Activate
    void activate() {
        routes = new Routes().add(backend.routes()).add(new AuditBackend(audit, gate).routes());
    }

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    Routes routes() {
        return routes;
    }

    @Override
    String page() {
        return "audit";
    }

    @Override
    String label() {
        return "arflex-audit";
    }
}
