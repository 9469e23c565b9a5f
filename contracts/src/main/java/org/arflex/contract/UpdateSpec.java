package org.arflex.contract;

import java.net.URI;

/**
 * Where a newer bundle of this component is published.
 *
 * @param url    https or file URL of the bundle jar
 * @param sha256 pinned SHA-256 of the jar, 64 lower-case hex digits
 */
public record UpdateSpec(URI url, String sha256) {
}
