package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.Collections;
import java.util.HashSet;
import java.util.Map;
import java.util.Set;
import java.util.function.UnaryOperator;
import java.util.zip.ZipEntry;
import java.util.zip.ZipFile;
import java.util.zip.ZipOutputStream;

/**
 * Copies of a component bundle the build made, with some of its entries rewritten: the new
 * versions of a component the update tests install (UpdateSetIT, ShadowRunIT, StateTransferIT,
 * ReconfigBench).
 */
final class BundleCopies {

    private BundleCopies() {
    }

    /**
     * Writes {@code dir/<name>.jar}: the entries of {@code bundle} in their order, each one named
     * in {@code edits} replaced by what its function makes of it; every entry named must be in
     * the bundle.
     */
    static Path copy(Path dir, Path bundle, String name, Map<String, UnaryOperator<byte[]>> edits) throws IOException {
        Path out = dir.resolve(name + ".jar");
        Set<String> found = new HashSet<>();
        try (ZipFile in = new ZipFile(bundle.toFile()); ZipOutputStream zo = new ZipOutputStream(Files.newOutputStream(out))) {
            for (ZipEntry e : Collections.list(in.entries())) {
                byte[] b = in.getInputStream(e).readAllBytes();
                UnaryOperator<byte[]> edit = edits.get(e.getName());
                if (edit != null) {
                    b = edit.apply(b);
                    found.add(e.getName());
                }
                zo.putNextEntry(new ZipEntry(e.getName()));
                zo.write(b);
                zo.closeEntry();
            }
        }
        for (String entry : edits.keySet()) {
            assertTrue(found.contains(entry), entry + " in " + bundle);
        }
        return out;
    }

    /** An edit of a text entry (UTF-8) that must change it; {@code what} names the entry in the failure. */
    static UnaryOperator<byte[]> text(UnaryOperator<String> edit, String what) {
        return b -> {
            String before = new String(b, StandardCharsets.UTF_8);
            String after = edit.apply(before);
            assertNotEquals(before, after, what);
            return after.getBytes(StandardCharsets.UTF_8);
        };
    }
}
