package org.arflex.drcr.impl.services;

import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.function.Consumer;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleException;

/**
 * Takes a deployment set back when its change set did not hold (D50): refused, torn down,
 * rejected in a shadow run, or applied and then one of its updates rolled back after the switch
 * (or its new version did not start at the switch).
 *
 * <p>Not applied: nothing of it runs, the bundles the set installed in Felix are uninstalled
 * again. Applied and rolled back: the set's own changes are taken back by one more change set
 * ({@code uninstall} its new components, {@code install} again what it uninstalled, the values
 * its writes replaced written back), and only when that one is applied are its bundles
 * uninstalled from Felix: a bundle whose component still runs stays, and the text says why.
 * Updates the set committed stay committed (their old versions are gone after their window).
 */
final class DeploymentUndo {

    /** What the set changed, for taking it back. */
    record Done(List<Bundle> bundles, List<String> installed, List<String> uninstalled, List<String> updated,
                Map<String, String> oldValues) {
    }

    private final ChangeSetService changeSets;
    private final Consumer<String> log;

    DeploymentUndo(ChangeSetService changeSets, Consumer<String> log) {
        this.changeSets = changeSets;
        this.log = log;
    }

    /**
     * The updates of {@code updated} that an applied set's text says did not hold, each with how
     * ({@code update c rolled back after the switch}, {@code update c did not start at the
     * switch}: the verdicts of UpdateWindow); empty when every one was committed or has no verdict.
     */
    static List<String> notHeld(String text, List<String> updated) {
        List<String> out = new ArrayList<>();
        for (String c : updated) {
            if (text == null) {
                continue;
            }
            if (text.contains("update " + c + ": rolled back after ")) {
                out.add("update " + c + " rolled back after the switch");
            } else if (text.contains("update " + c + ": the new version did not start")) {
                out.add("update " + c + " did not start at the switch");
            }
        }
        return out;
    }

    /**
     * The change set that takes an applied set back: its new components uninstalled, its
     * uninstalled ones installed again, the old values written back (keys {@code "<component>
     * <parameter>"}).
     */
    static List<String> actions(Done done) {
        List<String> a = new ArrayList<>();
        done.installed().forEach(n -> a.add("uninstall " + n));
        done.uninstalled().forEach(n -> a.add("install " + n));
        done.oldValues().forEach((k, v) -> a.add("set " + k + " " + v));
        return a;
    }

    /**
     * After an applied set whose updates did not hold ({@code back}, as {@link #notHeld} says): the
     * undo change set, then the bundles. Appends what happened to {@code text}; returns why the
     * set is not kept.
     */
    String takeBack(String url, StringBuilder text, Done done, List<String> back) {
        String why = String.join(", ", back);
        List<String> undo = actions(done);
        if (undo.isEmpty()) {
            return why + "; the set had nothing else to take back";
        }
        text.append("taking the set back (").append(why).append("): ").append(String.join("; ", undo)).append('\n');
        ChangeSetDTO r;
        try {
            r = changeSets.apply(undo);
        } catch (RuntimeException e) {
            r = new ChangeSetDTO();
            r.refusal = e.toString();
            r.text = "";
        }
        if (r.text != null) {
            text.append(r.text);
        }
        if (!r.applied) {
            String p = "deployment set " + url + ": could not be taken back: " + r.refusal + "; its components run and "
                    + "their bundles stay installed";
            log.accept("arflex: " + p);
            text.append("warning: ").append(p).append('\n');
            return why + "; taking it back was refused (" + r.refusal + ")";
        }
        uninstall(url, text, done.bundles());
        return why + "; the set was taken back";
    }

    /** Uninstalls what the set installed in Felix, and says so in {@code text}. */
    void uninstall(String url, StringBuilder text, List<Bundle> installed) {
        List<String> gone = new ArrayList<>();
        for (Bundle b : installed) {
            try {
                b.uninstall();
                gone.add("bundle " + b.getBundleId() + " (" + b.getLocation() + ")");
            } catch (BundleException | IllegalStateException e) {
                String p = "deployment set " + url + ": bundle " + b.getBundleId() + " could not be uninstalled again: "
                        + e.getMessage();
                log.accept("arflex: " + p);
                text.append("warning: ").append(p).append('\n');
            }
        }
        if (!gone.isEmpty()) {
            text.append("uninstalled again: ").append(String.join(", ", gone)).append('\n');
        }
    }
}
