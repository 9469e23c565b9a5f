/**
 * The DRCR's service API: a read-only view of the cell ({@link org.arflex.drcr.DrcrService}),
 * one {@link org.arflex.drcr.ComponentManagement} service per component instance, the
 * {@link org.arflex.drcr.ResourceManager} and the {@link org.arflex.drcr.UpdateService}.
 */
@org.osgi.annotation.bundle.Export
@org.osgi.annotation.versioning.Version("0.8.0")
package org.arflex.drcr;
