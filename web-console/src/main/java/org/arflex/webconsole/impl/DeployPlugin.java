package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/** Deploy page: install from upload or URL (pinned SHA-256), update, uninstall; plan shown before confirming. */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-deploy",
    "felix.webconsole.title=Deploy",
    "felix.webconsole.category=ARFLEX"})
public class DeployPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;

    @Reference
    private Backend backend;

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    String page() {
        return "deploy";
    }

    @Override
    String label() {
        return "arflex-deploy";
    }

}
