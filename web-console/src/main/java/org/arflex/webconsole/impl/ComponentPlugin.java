package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/** Component page: contract summary, bindings, parameters (editable where mutable), commands, live plots. */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-component",
    "felix.webconsole.title=Component",
    "felix.webconsole.category=ARFLEX"})
public class ComponentPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;

    @Reference
    private Backend backend;

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    String page() {
        return "component";
    }

    @Override
    String label() {
        return "arflex-component";
    }

    @Override
    String[] vendorScripts() {
        return new String[] {"uplot/dist/uPlot.iife.min.js"};
    }

    @Override
    String[] vendorStyles() {
        return new String[] {"uplot/dist/uPlot.min.css"};
    }
}
