/**
 * Read-only snapshots of the DRCR's state, in the style of OSGi DTOs: plain classes with public
 * fields, no behaviour, no references into the runtime. The web console and the integration
 * tests read the cell only through these.
 */
@org.osgi.annotation.bundle.Export
@org.osgi.annotation.versioning.Version("0.13.0")
package org.arflex.drcr.dto;
