package org.arflex.drcr.impl.lifecycle;

/** Lifecycle states of a component instance. */
public enum State {
    /** Contract read, not yet resolved. */
    INSTALLED,
    /** Resolved but not running: an input, a resource or an operator reset is missing. */
    UNSATISFIED,
    /** The RT half runs and its inputs are bound. */
    ACTIVE,
    /** Removed for good (bundle stopped or uninstalled). Terminal. */
    DESTROYED,
    /** Restarts exhausted or the RT half cannot run; needs reset or update. */
    FAILED
}
