package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/** Cell page: every component, its state and why it is not Active, RT statistics, resource budgets per CPU. */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-cell",
    "felix.webconsole.title=Cell",
    "felix.webconsole.category=ARFLEX"})
public class CellPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;

    @Reference
    private Backend backend;

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    String page() {
        return "cell";
    }

    @Override
    String label() {
        return "arflex-cell";
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
