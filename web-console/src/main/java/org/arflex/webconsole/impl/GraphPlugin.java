package org.arflex.webconsole.impl;

import jakarta.servlet.Servlet;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/** Graph page: components and their port links, coloured by state. */
@Component(service = Servlet.class, property = {
    "felix.webconsole.label=arflex-graph",
    "felix.webconsole.title=Graph",
    "felix.webconsole.category=ARFLEX"})
public class GraphPlugin extends PluginBase {
    private static final long serialVersionUID = 1L;

    @Reference
    private Backend backend;

    @Override
    Backend backend() {
        return backend;
    }

    @Override
    String page() {
        return "graph";
    }

    @Override
    String label() {
        return "arflex-graph";
    }

    @Override
    String[] vendorScripts() {
        return new String[] {"cytoscape/dist/cytoscape.min.js", "dagre/dist/dagre.min.js",
            "cytoscape-dagre/cytoscape-dagre.js"};
    }
}
