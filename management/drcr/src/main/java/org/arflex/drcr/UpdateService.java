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

    /**
     * Records a jar the caller is about to install as verified: its SHA-256 must equal
     * {@code sha256}, the pin the caller checked it against (the console's Deploy page). Only a
     * verified jar, or the file in a trusted folder it was installed from, may run RT halves.
     *
     * @param origin where the jar came from, for the log
     * @throws IllegalArgumentException when the jar's SHA-256 is not {@code sha256} or it is not a jar
     */
    void verified(byte[] jar, String sha256, String origin);
}
