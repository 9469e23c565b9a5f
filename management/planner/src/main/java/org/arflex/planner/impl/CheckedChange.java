package org.arflex.planner.impl;

import java.util.LinkedHashMap;
import java.util.Map;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;

/**
 * A {@link Change} checked against the cell's state before anything is touched: every name it
 * installs, replaces, uninstalls, blocks, unblocks or measures must fit the installed set (else an
 * {@link IllegalArgumentException} naming the component), and what it leaves: the contracts it
 * puts, which of them are installs, the replaced ones with their old contract (identical
 * replacements dropped), the uninstalled ones with theirs, and the blocked set, measured WCETs and
 * capacities after it.
 */
final class CheckedChange {
    final Map<String, Contract> puts;
    final TreeSet<String> installed;
    /** name -> old contract. */
    final TreeMap<String, Contract> replaced;
    final TreeMap<String, Contract> uninstalled;
    final TreeMap<String, String> newBlocked;
    final TreeMap<String, Long> newMeasured;
    final Capacities newCaps;

    private CheckedChange(Map<String, Contract> puts, TreeSet<String> installed, TreeMap<String, Contract> replaced,
            TreeMap<String, Contract> uninstalled, TreeMap<String, String> newBlocked, TreeMap<String, Long> newMeasured,
            Capacities newCaps) {
        this.puts = puts;
        this.installed = installed;
        this.replaced = replaced;
        this.uninstalled = uninstalled;
        this.newBlocked = newBlocked;
        this.newMeasured = newMeasured;
        this.newCaps = newCaps;
    }

    /** Checks {@code change} against the state ({@code blocked}, {@code measured}, {@code capacities} as they are now). */
    static CheckedChange check(Change change, Resolver resolver, Map<String, String> blocked, Map<String, Long> measured,
            Capacities capacities) {
        Map<String, Contract> puts = new LinkedHashMap<>();
        TreeSet<String> installed = new TreeSet<>();
        TreeMap<String, Contract> replaced = new TreeMap<>(); // name -> old contract
        for (Contract c : change.installs()) {
            if (resolver.contains(c.name())) {
                throw new IllegalArgumentException("install '" + c.name() + "': already installed (version "
                        + resolver.contract(c.name()).get().version() + "); use replace");
            }
            addPut(puts, c);
            installed.add(c.name());
        }
        for (Contract c : change.replaces()) {
            if (!resolver.contains(c.name())) {
                throw new IllegalArgumentException("replace '" + c.name() + "': not installed; use install");
            }
            addPut(puts, c);
            replaced.put(c.name(), resolver.contract(c.name()).get());
        }
        for (Contract c : change.puts()) {
            addPut(puts, c);
            if (resolver.contains(c.name())) {
                replaced.put(c.name(), resolver.contract(c.name()).get());
            } else {
                installed.add(c.name());
            }
        }
        TreeMap<String, Contract> uninstalled = new TreeMap<>();
        for (String n : change.uninstalls()) {
            if (!resolver.contains(n)) {
                throw new IllegalArgumentException("uninstall '" + n + "': not installed");
            }
            if (puts.containsKey(n)) {
                throw new IllegalArgumentException("component '" + n + "' is both uninstalled and installed in one change");
            }
            uninstalled.put(n, resolver.contract(n).get());
        }
        Transients.checkOverlaps(change, puts.keySet(), installed);
        // Identical replacements change nothing.
        replaced.entrySet().removeIf(e -> e.getValue().equals(puts.get(e.getKey())));
        TreeMap<String, String> newBlocked = new TreeMap<>(blocked);
        newBlocked.keySet().removeAll(uninstalled.keySet());
        for (String n : change.unblocks()) {
            if (!blocked.containsKey(n)) {
                throw new IllegalArgumentException("unblock '" + n + "': not blocked");
            }
            if (change.blocks().containsKey(n)) {
                throw new IllegalArgumentException("component '" + n + "' is both blocked and unblocked in one change");
            }
            newBlocked.remove(n);
        }
        for (var e : change.blocks().entrySet()) {
            if (!installedAfter(resolver, e.getKey(), puts, uninstalled)) {
                throw new IllegalArgumentException("block '" + e.getKey() + "': not installed");
            }
            newBlocked.put(e.getKey(), e.getValue());
        }
        TreeMap<String, Long> newMeasured = new TreeMap<>(measured);
        newMeasured.keySet().removeAll(uninstalled.keySet());
        for (var e : change.measuredWcetNs().entrySet()) {
            if (!installedAfter(resolver, e.getKey(), puts, uninstalled)) {
                throw new IllegalArgumentException("measured WCET for '" + e.getKey() + "': not installed");
            }
            if (e.getValue() == 0) {
                newMeasured.remove(e.getKey());
            } else {
                newMeasured.put(e.getKey(), e.getValue());
            }
        }
        Capacities newCaps = change.capacities().orElse(capacities);
        return new CheckedChange(puts, installed, replaced, uninstalled, newBlocked, newMeasured, newCaps);
    }

    private static void addPut(Map<String, Contract> puts, Contract c) {
        if (puts.put(c.name(), c) != null) {
            throw new IllegalArgumentException("contract '" + c.name() + "' is given twice in one change");
        }
    }

    private static boolean installedAfter(Resolver resolver, String n, Map<String, Contract> puts, Map<String, Contract> uninstalled) {
        return puts.containsKey(n) || (resolver.contains(n) && !uninstalled.containsKey(n));
    }
}
