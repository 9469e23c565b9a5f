/**
 * The component contract: the immutable model, the hardened parser and the validator that the
 * DRCR and the web console's contract editor share.
 */
@org.osgi.annotation.bundle.Export
@org.osgi.annotation.versioning.Version("0.2.0")
package org.arflex.contract;
