package org.arflex.drcr.impl.services;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.lang.management.ManagementFactory;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.util.concurrent.Callable;
import java.util.zip.ZipEntry;
import java.util.zip.ZipOutputStream;

/** Zip bombs for the tests (issue 30, finding 1): small on disk, huge once inflated. */
final class Bombs {

    private Bombs() {
    }

    /** A jar with a manifest and {@code entries} entries {@code bomb-<i>} of {@code each} zero bytes, deflated. */
    static byte[] zeros(int entries, long each) throws IOException {
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        byte[] chunk = new byte[1 << 20];
        try (ZipOutputStream z = new ZipOutputStream(b)) {
            z.putNextEntry(new ZipEntry("META-INF/MANIFEST.MF"));
            z.write("Manifest-Version: 1.0\r\nBundle-SymbolicName: bomb\r\n\r\n".getBytes(StandardCharsets.UTF_8));
            for (int i = 0; i < entries; i++) {
                z.putNextEntry(new ZipEntry("bomb-" + i));
                for (long left = each; left > 0; left -= chunk.length) {
                    z.write(chunk, 0, (int) Math.min(chunk.length, left));
                }
            }
        }
        return b.toByteArray();
    }

    /**
     * The same zip whose central directory declares every entry {@code declared} bytes long,
     * inflated and compressed: the sizes it declares are lies, only its inflated bytes tell.
     */
    static byte[] lying(byte[] zip, int declared) {
        byte[] out = zip.clone();
        ByteBuffer b = ByteBuffer.wrap(out).order(ByteOrder.LITTLE_ENDIAN);
        int eocd = out.length - 22;
        while (b.getInt(eocd) != 0x06054b50) {
            eocd--;
        }
        int at = b.getInt(eocd + 16);
        int n = Short.toUnsignedInt(b.getShort(eocd + 10));
        for (int i = 0; i < n; i++) {
            b.putInt(at + 20, declared);
            b.putInt(at + 24, declared);
            at += 46 + Short.toUnsignedInt(b.getShort(at + 28)) + Short.toUnsignedInt(b.getShort(at + 30))
                    + Short.toUnsignedInt(b.getShort(at + 32));
        }
        return out;
    }

    /**
     * A bundle as Felix gives an installed one (its entries' inflated streams) with a manifest and
     * {@code entries} entries {@code bomb-<i>} of {@code each} zero bytes, made as they are read.
     */
    static org.osgi.framework.Bundle installed(int entries, long each) {
        java.util.List<String> names = new java.util.ArrayList<>();
        names.add("META-INF/");
        for (int i = 0; i < entries; i++) {
            names.add("bomb-" + i);
        }
        return (org.osgi.framework.Bundle) java.lang.reflect.Proxy.newProxyInstance(
                org.osgi.framework.Bundle.class.getClassLoader(), new Class<?>[] {org.osgi.framework.Bundle.class},
                (proxy, m, args) -> switch (m.getName()) {
                    case "getLocation" -> "file:/tmp/bomb.jar";
                    case "getBundleId" -> 43L;
                    case "getSymbolicName" -> "bomb";
                    case "getEntryPaths" -> java.util.Collections.enumeration(
                            args[0].equals("/") ? names : args[0].equals("META-INF/") ? java.util.List.of(
                                    "META-INF/MANIFEST.MF") : java.util.List.of());
                    case "getEntry" -> new java.net.URL("test", "", -1, "/" + args[0], new java.net.URLStreamHandler() {
                        @Override
                        protected java.net.URLConnection openConnection(java.net.URL u) {
                            return new java.net.URLConnection(u) {
                                @Override
                                public void connect() {
                                }

                                @Override
                                public java.io.InputStream getInputStream() {
                                    return zeros(((String) args[0]).startsWith("bomb-") ? each : 0);
                                }
                            };
                        }
                    });
                    case "hashCode" -> System.identityHashCode(proxy);
                    case "equals" -> proxy == args[0];
                    default -> throw new UnsupportedOperationException(m.getName());
                });
    }

    /** {@code n} zero bytes, made as they are read. */
    static java.io.InputStream zeros(long n) {
        return new java.io.InputStream() {
            private long left = n;

            @Override
            public int read() {
                return left-- > 0 ? 0 : -1;
            }

            @Override
            public int read(byte[] b, int off, int len) {
                if (left <= 0) {
                    return -1;
                }
                int r = (int) Math.min(len, left);
                java.util.Arrays.fill(b, off, off + r, (byte) 0);
                left -= r;
                return r;
            }
        };
    }

    /** The zip without its end of central directory record: only its entries, as they come, tell. */
    static byte[] headless(byte[] zip) {
        return java.util.Arrays.copyOf(zip, zip.length - 22);
    }

    /** What a call allocated on this thread, in bytes, and its outcome. */
    record Measured<T>(long allocated, T value, Exception thrown) {
    }

    static <T> Measured<T> allocation(Callable<T> call) {
        com.sun.management.ThreadMXBean mx = (com.sun.management.ThreadMXBean) ManagementFactory.getThreadMXBean();
        long id = Thread.currentThread().getId();
        long before = mx.getThreadAllocatedBytes(id);
        T value = null;
        Exception thrown = null;
        try {
            value = call.call();
        } catch (Exception e) {
            thrown = e;
        }
        return new Measured<>(mx.getThreadAllocatedBytes(id) - before, value, thrown);
    }
}
