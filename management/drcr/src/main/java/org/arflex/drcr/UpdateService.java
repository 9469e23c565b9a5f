package org.arflex.drcr;

/** Continuous deployment of component bundles from their contract's update URL. */
public interface UpdateService {

    /**
     * Downloads the bundle from the update URL of component {@code name}'s contract (https or
     * file only), checks the pinned SHA-256 and updates the bundle. On any failure the old
     * version keeps running.
     *
     * @return a report of what was done
     * @throws IllegalStateException with the reason when the update was refused or failed
     */
    String update(String name);
}
