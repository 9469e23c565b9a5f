/**
 * Generated accessors of the port types in contracts/types (spec §13.5): one class per type,
 * reading and writing the same little-endian bytes as the generated C headers.
 */
@org.osgi.annotation.bundle.Export
@org.osgi.annotation.versioning.Version("0.2.0")
package org.arflex.contract.types;
