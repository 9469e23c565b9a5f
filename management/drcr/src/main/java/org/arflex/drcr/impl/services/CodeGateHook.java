package org.arflex.drcr.impl.services;

import java.util.Collection;
import java.util.Collections;
import java.util.Iterator;
import java.util.Map;
import java.util.WeakHashMap;
import org.osgi.framework.Bundle;
import org.osgi.framework.hooks.resolver.ResolverHook;
import org.osgi.framework.hooks.resolver.ResolverHookFactory;
import org.osgi.framework.wiring.BundleCapability;
import org.osgi.framework.wiring.BundleRequirement;
import org.osgi.framework.wiring.BundleRevision;

/**
 * The code gate for Java code (issue 16: "nothing unverified is installed or executed"). The
 * {@link CodeGate} decides at the extender whether a bundle's RT halves may run; a bundle's
 * Java code (its activator, its components) would still run once Felix starts it, whatever
 * door it came through. OSGi cannot veto an install, but a resolver hook can keep a revision
 * from resolving (Core 60.2): a bundle the gate refuses stays INSTALLED, none of its classes
 * load, and {@code start} says it cannot be resolved; the gate's log line says why. This covers
 * installs and updates from every path (shell, console, {@code Bundle-UpdateLocation}).
 *
 * <p>Bundles resolved before the DRCR registered this hook (the runtime's own, from its
 * trusted folders) are judged again only when they are refreshed. The system bundle is never
 * judged. Each revision is judged once (its content does not change).
 */
public final class CodeGateHook implements ResolverHookFactory {

    private final CodeGate gate;
    private final Map<BundleRevision, String> verdicts = Collections.synchronizedMap(new WeakHashMap<>());

    public CodeGateHook(CodeGate gate) {
        this.gate = gate;
    }

    /**
     * The gate's verdict on a bundle's current revision, judged once: the extender asks this
     * after the resolve asked it, so a bundle's content is hashed once, not twice.
     */
    public String refusal(Bundle b) {
        BundleRevision r = b.adapt(BundleRevision.class);
        return r == null ? gate.refusal(b) : refusal(r);
    }

    /**
     * Null when the revision may resolve, else why not (judged once per revision). The content
     * is read through the bundle, so a verdict is kept only when the bundle's revision was the
     * same before and after it was read (the extender's look ahead, D54, runs beside Felix's
     * {@code update}) and the content could be read.
     */
    String refusal(BundleRevision r) {
        Bundle b = r.getBundle();
        if (b == null || b.getBundleId() == 0) {
            return null;
        }
        String v = verdicts.get(r);
        if (v == null) {
            v = judge(b);
            if (!v.contains(UNREADABLE) && current(b) == r) {
                verdicts.put(r, v);
            }
        }
        return v.isEmpty() ? null : v;
    }

    private static BundleRevision current(Bundle b) {
        try {
            return b.adapt(BundleRevision.class);
        } catch (RuntimeException e) {
            return null;
        }
    }

    /**
     * The gate's verdict ("" when admitted). A bundle whose install is still under way when a
     * resolve started by another thread includes it cannot be read yet ("No bundle associated
     * with resource"): it is asked again for up to {@link #SETTLE_MS}, and if it still cannot be
     * read it is refused for this resolve only (fail closed; the next resolve asks again).
     */
    private String judge(Bundle b) {
        long deadline = System.nanoTime() + SETTLE_MS * 1_000_000L;
        while (true) {
            String why = gate.refusal(b);
            String v = why == null ? "" : why;
            if (!v.contains(UNREADABLE) || System.nanoTime() - deadline > 0) {
                return v;
            }
            java.util.concurrent.locks.LockSupport.parkNanos(20_000_000L); // the install completes meanwhile
        }
    }

    /** How CodeGate names content it could not read. */
    private static final String UNREADABLE = "(unreadable:";
    /** How long a bundle that is still being installed is given to become readable. */
    static final long SETTLE_MS = 2_000;

    @Override
    public ResolverHook begin(Collection<BundleRevision> triggers) {
        return new ResolverHook() {
            @Override
            public void filterResolvable(Collection<BundleRevision> candidates) {
                for (Iterator<BundleRevision> it = candidates.iterator(); it.hasNext();) {
                    if (refusal(it.next()) != null) {
                        it.remove();
                    }
                }
            }

            @Override
            public void filterSingletonCollisions(BundleCapability singleton,
                                                    Collection<BundleCapability> collisionCandidates) {
                // not the gate's business
            }

            @Override
            public void filterMatches(BundleRequirement requirement, Collection<BundleCapability> candidates) {
                // not the gate's business
            }

            @Override
            public void end() {
                // nothing held
            }
        };
    }
}
