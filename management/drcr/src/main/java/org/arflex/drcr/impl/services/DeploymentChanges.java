package org.arflex.drcr.impl.services;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import org.arflex.contract.Contract;
import org.arflex.contract.PropertySpec;
import org.arflex.drcr.impl.runtime.Params;

/**
 * The uninstalls and parameter writes of a deployment set (D50) against the cell, before
 * anything is fetched into Felix: an uninstalled component runs and is not also installed by the
 * set; a write names a component that runs after the set (running, installed or updated by it),
 * a parameter of its contract as it will be (the new one for an install or update), and a value
 * of that parameter's type and range; a component that keeps running keeps an immutable
 * parameter. The change set checks the same again (ChangeSetExecutor), this is what the dry run
 * can say without a bundle. Pure: no cell, no I/O.
 */
final class DeploymentChanges {

    private DeploymentChanges() {
    }

    /**
     * The problems, one line each (naming the descriptor's line and the action), empty when none.
     *
     * @param changes  the set's uninstalls and writes
     * @param running  the contracts of the components the cell runs now
     * @param installs the contracts the set installs
     * @param updates  the new contracts of the components the set updates
     */
    static List<String> check(List<DeploymentDescriptor.Entry> changes, List<Contract> running, List<Contract> installs,
                              List<Contract> updates) {
        Map<String, Contract> now = new LinkedHashMap<>();
        running.forEach(c -> now.put(c.name(), c));
        Map<String, Contract> fresh = new LinkedHashMap<>();
        installs.forEach(c -> fresh.put(c.name(), c));
        updates.forEach(c -> fresh.put(c.name(), c));
        List<String> uninstalled = changes.stream().filter(e -> e.kind() == DeploymentDescriptor.Kind.UNINSTALL)
                .map(DeploymentDescriptor.Entry::component).toList();
        List<String> problems = new ArrayList<>();
        for (DeploymentDescriptor.Entry e : changes) {
            String head = "line " + e.line() + ", " + e.action() + ": ";
            String n = e.component();
            if (e.kind() == DeploymentDescriptor.Kind.UNINSTALL) {
                if (installs.stream().anyMatch(c -> c.name().equals(n))) {
                    problems.add(head + "'" + n + "' is also installed by the set");
                } else if (!now.containsKey(n)) {
                    problems.add(head + "'" + n + "' is not running");
                }
                continue;
            }
            if (uninstalled.contains(n)) {
                problems.add(head + "'" + n + "' is uninstalled by the set");
                continue;
            }
            boolean keepsRunning = !fresh.containsKey(n);
            Contract c = keepsRunning ? now.get(n) : fresh.get(n);
            if (c == null) {
                problems.add(head + "no component '" + n + "' runs or is installed by the set");
                continue;
            }
            Optional<PropertySpec> p = c.properties().stream().filter(x -> x.name().equals(e.parameter())).findFirst();
            if (p.isEmpty()) {
                problems.add(head + n + " " + c.version() + " has no parameter '" + e.parameter() + "' (has "
                        + c.properties().stream().map(PropertySpec::name).toList() + ")");
                continue;
            }
            try {
                Params.parse(p.get(), e.value());
            } catch (IllegalArgumentException ex) {
                problems.add(head + n + "." + ex.getMessage());
                continue;
            }
            if (keepsRunning && !p.get().mutable()) {
                problems.add(head + n + "." + e.parameter() + " is immutable while it runs (mutable=false)");
            }
        }
        return problems;
    }
}
