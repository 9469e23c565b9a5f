package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/** Contract editor: form and XML side by side, validated by the DRCR's own ContractParser. */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-contract",
    "felix.webconsole.title=Contract editor",
    "felix.webconsole.category=ARFLEX"})
public class ContractPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;

    @Reference
    private Backend backend;

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    String page() {
        return "contract";
    }

    @Override
    String label() {
        return "arflex-contract";
    }

}
