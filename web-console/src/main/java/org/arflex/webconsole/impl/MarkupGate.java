package org.arflex.webconsole.impl;

import java.io.IOException;
import java.io.InputStream;
import java.io.InputStreamReader;
import java.net.URL;
import java.nio.charset.StandardCharsets;
import java.time.Instant;
import java.util.ArrayList;
import java.util.Collection;
import java.util.Collections;
import java.util.Dictionary;
import java.util.Enumeration;
import java.util.Iterator;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Properties;
import java.util.WeakHashMap;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.Constants;
import org.osgi.framework.hooks.resolver.ResolverHook;
import org.osgi.framework.hooks.resolver.ResolverHookFactory;
import org.osgi.framework.wiring.BundleCapability;
import org.osgi.framework.wiring.BundleRequirement;
import org.osgi.framework.wiring.BundleRevision;
import org.osgi.service.component.annotations.Activate;
import org.osgi.service.component.annotations.Component;

/**
 * Refuses to resolve a bundle whose human-readable manifest headers ({@link #HEADERS}) carry
 * markup ({@code <} or {@code >}), in the raw manifest or in any of the bundle's own
 * localisation files: it stays INSTALLED, so none of its code runs, and the console lists
 * it with the reason. A second line behind the {@link ContentSecurityFilter}: the Web Console
 * puts those headers into its pages as HTML (issue 16, finding 2), and no real bundle needs
 * {@code <} or {@code >} there (none of the runtime's or the cell's does).
 *
 * <p>Why a resolver hook: OSGi has no hook that can veto an install (docs/DECISIONS.md D12),
 * but one that keeps a revision from resolving is standard (Core 60.2) and covers installs and
 * updates from every path (shell, console, {@code Bundle-UpdateLocation}). The bundle is still
 * listed by Felix: the policy keeps what its headers say from running there.
 */
@Component(service = {ResolverHookFactory.class, MarkupGate.class})
public class MarkupGate implements ResolverHookFactory {
    /** The headers the Web Console shows as text or HTML. */
    static final List<String> HEADERS = List.of(Constants.BUNDLE_NAME, Constants.BUNDLE_SYMBOLICNAME,
            Constants.BUNDLE_DESCRIPTION, Constants.BUNDLE_VENDOR, Constants.BUNDLE_DOCURL,
            Constants.BUNDLE_CONTACTADDRESS, Constants.BUNDLE_COPYRIGHT, Constants.BUNDLE_CATEGORY,
            Constants.BUNDLE_VERSION, Constants.BUNDLE_UPDATELOCATION, "Bundle-License", "Bundle-Developers",
            "Bundle-SCM");

    /**
     * A bundle refused.
     *
     * @param bundleId the bundle
     * @param location where it was installed from
     * @param reason   the header and its value (cut)
     * @param time     when it was first refused
     */
    record Refusal(long bundleId, String location, String reason, String time) {
    }

    private final Map<BundleRevision, String> verdicts = Collections.synchronizedMap(new WeakHashMap<>());
    private final Map<Long, Refusal> refused = Collections.synchronizedMap(new LinkedHashMap<>());
    private BundleContext context;

    @Activate
    void activate(BundleContext bc) {
        this.context = bc;
    }

    /** The refusals of bundles that are still installed, oldest first. */
    List<Refusal> refusals() {
        List<Refusal> out = new ArrayList<>();
        synchronized (refused) {
            for (Refusal r : refused.values()) {
                if (context == null || context.getBundle(r.bundleId()) != null) {
                    out.add(r);
                }
            }
        }
        return out;
    }

    @Override
    public ResolverHook begin(Collection<BundleRevision> triggers) {
        return new ResolverHook() {
            @Override
            public void filterResolvable(Collection<BundleRevision> candidates) {
                for (Iterator<BundleRevision> it = candidates.iterator(); it.hasNext();) {
                    BundleRevision r = it.next();
                    String why = verdict(r);
                    if (why != null) {
                        it.remove();
                    }
                }
            }

            @Override
            public void filterSingletonCollisions(BundleCapability singleton,
                    Collection<BundleCapability> collisionCandidates) {
                // no opinion
            }

            @Override
            public void filterMatches(BundleRequirement requirement, Collection<BundleCapability> candidates) {
                // no opinion
            }

            @Override
            public void end() {
                // nothing held
            }
        };
    }

    /** Null when the revision may resolve, else why not (remembered per revision). */
    private String verdict(BundleRevision r) {
        Bundle b = r.getBundle();
        if (b == null || b.getBundleId() == 0) {
            return null;
        }
        synchronized (verdicts) {
            if (verdicts.containsKey(r)) {
                return verdicts.get(r);
            }
        }
        String why;
        try {
            why = markup(b.getHeaders(""), localisations(b));
        } catch (RuntimeException e) {
            why = null; // a bundle that cannot be read is the framework's to refuse, not ours
        }
        verdicts.put(r, why);
        if (why != null) {
            Refusal before = refused.get(b.getBundleId());
            if (before == null || !before.reason().equals(why)) {
                refused.put(b.getBundleId(), new Refusal(b.getBundleId(), b.getLocation(), why, Instant.now().toString()));
                System.err.println("arflex console: bundle " + b.getBundleId() + " (" + b.getLocation()
                        + ") is not resolved: " + why);
            }
        }
        return why;
    }

    /**
     * The first human-readable header whose value carries markup, raw or through any of the
     * given localisations ({@code %key} values), as {@code Header "value"}; null when none does.
     */
    static String markup(Dictionary<String, String> raw, List<Properties> localisations) {
        for (String h : HEADERS) {
            String v = raw.get(h);
            if (v == null) {
                continue;
            }
            if (hasMarkup(v)) {
                return "markup in the manifest header " + h + ": " + quote(v);
            }
            if (v.startsWith("%")) {
                String key = v.substring(1);
                for (Properties p : localisations) {
                    String l = p.getProperty(key);
                    if (l != null && hasMarkup(l)) {
                        return "markup in the manifest header " + h + " (localised " + v + "): " + quote(l);
                    }
                }
            }
        }
        return null;
    }

    static boolean hasMarkup(String v) {
        return v.indexOf('<') >= 0 || v.indexOf('>') >= 0;
    }

    private static String quote(String v) {
        String s = v.length() > 160 ? v.substring(0, 160) + "…" : v;
        return "\"" + s + "\"";
    }

    /**
     * Every properties file next to the bundle's localisation base (its own entries only:
     * {@code getEntryPaths} and {@code getEntry} never resolve the bundle, which a resolver
     * hook must not cause).
     */
    private static List<Properties> localisations(Bundle b) {
        List<Properties> out = new ArrayList<>();
        String base = b.getHeaders("").get(Constants.BUNDLE_LOCALIZATION);
        if (base == null) {
            base = Constants.BUNDLE_LOCALIZATION_DEFAULT_BASENAME;
        }
        int slash = base.lastIndexOf('/');
        String dir = slash < 0 ? "/" : base.substring(0, slash + 1);
        Enumeration<String> paths = b.getEntryPaths(dir);
        while (paths != null && paths.hasMoreElements()) {
            String p = paths.nextElement();
            if (p.endsWith(".properties")) {
                URL u = b.getEntry(p);
                if (u != null) {
                    Properties props = new Properties();
                    try (InputStream in = u.openStream()) {
                        props.load(new InputStreamReader(in, StandardCharsets.ISO_8859_1));
                        out.add(props);
                    } catch (IOException | IllegalArgumentException e) {
                        // unreadable: the framework will not use it either
                    }
                }
            }
        }
        return out;
    }
}
