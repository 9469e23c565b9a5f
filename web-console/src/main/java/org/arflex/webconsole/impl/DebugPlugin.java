package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/** Debug monitor page: install the debug-monitor component watching chosen ports, watch its values live, remove it again. */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-debug",
    "felix.webconsole.title=Debug monitor",
    "felix.webconsole.category=ARFLEX"})
public class DebugPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;

    @Reference
    private Backend backend;

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    String page() {
        return "debug";
    }

    @Override
    String label() {
        return "arflex-debug";
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
