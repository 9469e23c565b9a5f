package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import org.arflex.drcr.ChangeSetService;
import org.osgi.service.component.annotations.Activate;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;
import org.osgi.service.component.annotations.ReferenceCardinality;
import org.osgi.service.component.annotations.ReferencePolicy;

/**
 * Change sets page (D46): type a set's actions, see the DRCR's plan of the whole set and its
 * admission, apply the plan shown with an explicit confirm, follow its outcome, and the history
 * of the sets applied in this runtime. Its endpoints ({@link ChangeSetBackend}) are served under
 * this page's label only, beside every page's common ones.
 */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=" + ChangeSetPlugin.LABEL,
    "felix.webconsole.title=Change sets",
    "felix.webconsole.category=ARFLEX"})
public class ChangeSetPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;
    static final String LABEL = "arflex-changesets";

    @Reference
    private Backend backend;
    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    private volatile ChangeSetService changeSets;
    @Reference(cardinality = ReferenceCardinality.OPTIONAL, policy = ReferencePolicy.DYNAMIC)
    private volatile AuditFilter auditFilter;

    private Routes routes;

    @Activate
    void activate(org.osgi.framework.BundleContext bc) {
        ChangeSetBackend sets = new ChangeSetBackend(() -> changeSets, apply -> {
            Thread t = new Thread(apply, "arflex-console-changeset");
            t.setDaemon(true);
            t.start();
        }, this::audit, System::currentTimeMillis, StagingSources.parse(bc.getProperty(StagingSources.PROPERTY)));
        this.routes = new Routes().add(backend.routes()).add(sets.routes());
    }

    /**
     * The outcome of an apply, once known, as one more audit entry (method {@code OUTCOME}); a
     * committed one is a change and goes to the security history too (D81).
     */
    private void audit(String user, String remote, List<String> actions, Map<String, Object> view) {
        AuditFilter f = auditFilter;
        AuditTrail trail = f == null ? null : f.trail();
        if (trail == null) {
            return;
        }
        Map<String, String> params = new LinkedHashMap<>();
        params.put("actions", String.join("\n", actions));
        params.put("outcome", String.valueOf(view.get("outcome")));
        Object why = view.get("why");
        boolean good = "committed".equals(view.get("outcome"));
        trail.request(user, remote, "OUTCOME", "/system/console/" + LABEL + "/api/changeset-apply", params,
                good ? 200 : 409, good ? null : why == null ? null : why.toString());
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
        return "changesets";
    }

    @Override
    String label() {
        return LABEL;
    }
}
