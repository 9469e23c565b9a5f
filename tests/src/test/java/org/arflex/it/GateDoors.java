package org.arflex.it;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.OutputStream;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.zip.CRC32;
import java.util.zip.Deflater;
import java.util.zip.ZipEntry;
import java.util.zip.ZipInputStream;

/**
 * The code gate's own doors (issue 30, D78): a zip bomb (the sample counter with 8 entries of
 * 1 GiB of zeros, 8 MB on disk) through {@code arflex:deploy} without a pin and through
 * {@code install} + {@code start}, while a counter from the trusted folder runs as the
 * witness; and a jar signed by a trusted key with an unsigned signature-like file added
 * ({@code META-INF/EVIL.EC}, {@code SIG-EVIL}, {@code EVIL.RSA}). A bomb's attempt
 * <em>succeeded</em> when the bomb was admitted, when its refusal took longer than
 * {@link #QUICK_MS}, or when the witness entered safe mode, awaits a reset or lost its process;
 * a signed jar's when it was installed. A control shows the signed jar without the added file
 * is installed. Used by the attack benchmark ({@link AttackBench}) and {@link GateDoorsIT}.
 */
final class GateDoors {

    /** Longest a refusal of the bomb may take (it took 20 s and stalled the cell before D78). */
    static final long QUICK_MS = 5_000;
    private static final Pattern BUNDLE_ID = Pattern.compile("Bundle ID: (\\d+)");
    private static final String COMPONENT = CodeDoors.COMPONENT;

    private final Runtime rt;
    private final Path outside;
    final List<CodeDoors.Attempt> attempts = new ArrayList<>();
    final List<String> controls = new ArrayList<>();

    /** @param rt a runtime whose code gate trusts only its own folders; @param outside a folder outside them */
    GateDoors(Runtime rt, Path outside) throws IOException {
        this.rt = rt;
        this.outside = Files.createDirectories(outside);
    }

    /** Every door: the signed ones first (no counter runs), then the bomb with the witness running. */
    void tryAll() throws Exception {
        signatureLikeFiles();
        Path bomb = bomb(Components.jar(COMPONENT), outside.resolve("bomb.jar"), 8, 1L << 30);
        Path witness = Files.copy(Components.jar(COMPONENT), Files.createDirectories(rt.dir.resolve("tools"))
                .resolve("gate-witness.jar"), java.nio.file.StandardCopyOption.REPLACE_EXISTING);
        long id = rt.installAndStart(witness);
        rt.awaitState("ACTIVE", CellIT.T, COMPONENT);
        long pid = rt.pid(COMPONENT);
        String size = String.format(Locale.ROOT, "%.1f MB on disk", Files.size(bomb) / 1e6);
        bombDoor("deploy (no pin) of a zip bomb (8 x 1 GiB of zeros, " + size + ")", bomb, pid, () -> {
            String out = rt.cmd("arflex:deploy " + bomb.toUri());
            return new String[] {out, null};
        });
        bombDoor("install + start of a zip bomb (8 x 1 GiB of zeros, " + size + ")", bomb, pid, () -> {
            int mark = rt.logMark();
            String out = rt.cmd("install " + bomb.toUri());
            Matcher m = BUNDLE_ID.matcher(out);
            if (!m.find()) {
                return new String[] {out, null};
            }
            String b = m.group(1);
            rt.cmd("start " + b);
            String tag = "code gate: bundle " + b + " ";
            rt.waitUntil("the code gate's decision on the bomb", 60_000,
                    () -> rt.logSince(mark).stream().anyMatch(l -> l.contains(tag)));
            String decision = rt.logSince(mark).stream().filter(l -> l.contains(tag)).findFirst().orElse("");
            return new String[] {decision.substring(decision.indexOf(tag)), b};
        });
        rt.cmd("uninstall " + id);
        rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
    }

    private interface Door {
        /** What the runtime said, and the id of a bundle installed (or null). */
        String[] run() throws Exception;
    }

    private void bombDoor(String door, Path bomb, long witnessPid, Door d) throws Exception {
        long t0 = System.nanoTime();
        String[] said = d.run();
        long ms = (System.nanoTime() - t0) / 1_000_000;
        String out = said[0];
        boolean admitted = out.contains("Bundle ID") && said[1] == null || out.contains(" admitted");
        Map<String, Object> w = rt.instance(COMPONENT);
        boolean hurt = w == null || !"ACTIVE".equals(w.get("state")) || Boolean.TRUE.equals(w.get("safeMode"))
                || Boolean.TRUE.equals(w.get("awaitingReset")) || ((Number) w.get("pid")).longValue() != witnessPid;
        List<String> others = new ArrayList<>();
        for (Map<String, Object> i : Runtime.list(rt.dto(), "instances")) {
            if (Boolean.TRUE.equals(i.get("safeMode")) || Boolean.TRUE.equals(i.get("awaitingReset"))) {
                others.add((String) i.get("name"));
            }
        }
        String line = out.strip().lines().findFirst().orElse("").replace(bomb.toUri().toString(), "bomb.jar");
        attempts.add(new CodeDoors.Attempt(door, admitted || hurt || !others.isEmpty() || ms > QUICK_MS,
                String.format(Locale.ROOT, "%s after %d ms; witness %s%s: %s", admitted ? "ADMITTED" : "refused", ms,
                        hurt ? "HURT (" + w + ")" : "ACTIVE, same process, no safe mode",
                        others.isEmpty() ? "" : "; in safe mode or awaiting a reset: " + others,
                        line.length() > 220 ? line.substring(0, 220) + "..." : line)));
        if (said[1] != null) {
            rt.cmd("uninstall " + said[1]);
        }
    }

    /** Finding 10: signature-like files added to a trusted-signed jar, each deployed without a pin. */
    private void signatureLikeFiles() throws Exception {
        Path ks = outside.resolve("gate-key.p12");
        Files.deleteIfExists(ks);
        CodeDoors.jdk("keytool", "-genkeypair", "-alias", "gate", "-keyalg", "EC", "-groupname", "secp256r1",
                "-validity", "30", "-dname", "CN=ARFLEX gate doors", "-keystore", ks.toString(), "-storetype", "PKCS12",
                "-storepass", "changeit-test");
        Path trust = Files.createDirectories(rt.dir.resolve("trust"));
        Files.setPosixFilePermissions(trust, PosixFilePermissions.fromString("rwxr-xr-x"));
        Path crt = trust.resolve("gate-doors.crt");
        Files.deleteIfExists(crt);
        CodeDoors.jdk("keytool", "-exportcert", "-rfc", "-alias", "gate", "-keystore", ks.toString(), "-storetype",
                "PKCS12", "-storepass", "changeit-test", "-file", crt.toString());
        Files.setPosixFilePermissions(crt, PosixFilePermissions.fromString("rw-r--r--"));
        Path signed = Files.copy(Components.jar(COMPONENT), outside.resolve("gate-signed.jar"),
                java.nio.file.StandardCopyOption.REPLACE_EXISTING);
        CodeDoors.jdk("jarsigner", "-keystore", ks.toString(), "-storetype", "PKCS12", "-storepass", "changeit-test",
                "-digestalg", "SHA-256", signed.toString(), "gate");

        String out = rt.cmd("arflex:deploy " + signed.toUri());
        Matcher m = BUNDLE_ID.matcher(out);
        if (!m.find()) {
            throw new AssertionError("control failed: a trusted-signed jar was not deployed: " + out + "\n" + rt.tail());
        }
        controls.add("trusted-signed jar deployed without a pin: installed (bundle " + m.group(1) + ")");
        rt.cmd("uninstall " + m.group(1));
        rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
        for (String added : List.of("META-INF/EVIL.EC", "META-INF/SIG-EVIL", "META-INF/EVIL.RSA")) {
            Path jar = outside.resolve("gate-signed-" + added.substring(9).replace('.', '-') + ".jar");
            Files.write(jar, withEntry(Files.readAllBytes(signed), added));
            String said = rt.cmd("arflex:deploy " + jar.toUri());
            Matcher id = BUNDLE_ID.matcher(said);
            boolean installed = id.find();
            if (installed) {
                rt.cmd("uninstall " + id.group(1));
                rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
            }
            String line = said.strip().lines().findFirst().orElse("");
            attempts.add(new CodeDoors.Attempt("deploy (no pin) of a trusted-signed jar with " + added + " added",
                    installed, (installed ? "INSTALLED: " : "") + (line.length() > 220 ? line.substring(0, 220) + "..." : line)));
        }
    }

    /** The jar's entries as they are, and one more, {@code name}, unsigned. */
    private static byte[] withEntry(byte[] jar, String name) throws IOException {
        List<Entry> entries = new ArrayList<>();
        try (ZipInputStream in = new ZipInputStream(new java.io.ByteArrayInputStream(jar))) {
            for (ZipEntry e = in.getNextEntry(); e != null; e = in.getNextEntry()) {
                entries.add(Entry.of(e.getName(), in.readAllBytes()));
            }
        }
        entries.add(Entry.of(name, "evil".getBytes(StandardCharsets.UTF_8)));
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        write(entries, b);
        return b.toByteArray();
    }

    /**
     * {@code jar}'s entries and {@code n} entries {@code bomb-<i>} of {@code each} zero bytes,
     * each deflated as one compressed 1 MiB of zeros repeated: written in well under a second
     * (a deflater would take seconds per GiB), with true sizes and CRCs.
     */
    static Path bomb(Path jar, Path out, int n, long each) throws IOException {
        List<Entry> entries = new ArrayList<>();
        try (ZipInputStream in = new ZipInputStream(Files.newInputStream(jar))) {
            for (ZipEntry e = in.getNextEntry(); e != null; e = in.getNextEntry()) {
                byte[] data = in.readAllBytes();
                if (e.getName().equals(java.util.jar.JarFile.MANIFEST_NAME)) {
                    // a name of its own: Felix installs it beside the witness, and the gate decides
                    java.util.jar.Manifest m = new java.util.jar.Manifest(new java.io.ByteArrayInputStream(data));
                    m.getMainAttributes().putValue("Bundle-SymbolicName",
                            m.getMainAttributes().getValue("Bundle-SymbolicName").split(";")[0] + ".bomb");
                    ByteArrayOutputStream b = new ByteArrayOutputStream();
                    m.write(b);
                    data = b.toByteArray();
                }
                entries.add(Entry.of(e.getName(), data));
            }
        }
        byte[] mib = new byte[1 << 20];
        Deflater d = new Deflater(Deflater.BEST_COMPRESSION, true);
        d.setInput(mib);
        byte[] block = deflate(d, Deflater.FULL_FLUSH); // self-contained: may be repeated
        d.finish();
        byte[] last = deflate(d, Deflater.NO_FLUSH); // the final (empty) block
        d.end();
        CRC32 crc = new CRC32();
        for (long k = 0; k < each; k += mib.length) {
            crc.update(mib, 0, (int) Math.min(mib.length, each - k));
        }
        long pieces = each / mib.length;
        for (int i = 0; i < n; i++) {
            entries.add(new Entry("bomb-" + i, crc.getValue(), each, pieces * block.length + last.length, o -> {
                for (long k = 0; k < pieces; k++) {
                    o.write(block);
                }
                o.write(last);
            }));
        }
        try (OutputStream o = new java.io.BufferedOutputStream(Files.newOutputStream(out))) {
            write(entries, o);
        }
        return out;
    }

    private static byte[] deflate(Deflater d, int flush) {
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        byte[] buf = new byte[64 << 10];
        int r;
        do {
            r = d.deflate(buf, 0, buf.length, flush);
            b.write(buf, 0, r);
        } while (r == buf.length || (flush == Deflater.NO_FLUSH && !d.finished()));
        return b.toByteArray();
    }

    private interface Body {
        void write(OutputStream o) throws IOException;
    }

    /** One deflated entry: its name, CRC, inflated and compressed sizes, and how its compressed bytes are written. */
    private record Entry(String name, long crc, long size, long csize, Body body) {
        static Entry of(String name, byte[] data) {
            CRC32 c = new CRC32();
            c.update(data);
            Deflater d = new Deflater(Deflater.DEFAULT_COMPRESSION, true);
            d.setInput(data);
            d.finish();
            byte[] z = deflate(d, Deflater.NO_FLUSH);
            d.end();
            return new Entry(name, c.getValue(), data.length, z.length, o -> o.write(z));
        }
    }

    /** A zip of deflated entries (local headers, data, central directory), sizes in the headers. */
    private static void write(List<Entry> entries, OutputStream o) throws IOException {
        ByteArrayOutputStream cd = new ByteArrayOutputStream();
        long at = 0;
        for (Entry e : entries) {
            byte[] name = e.name().getBytes(StandardCharsets.UTF_8);
            ByteBuffer h = header(30 + name.length, 0x04034b50);
            h.putShort((short) 20).putShort((short) 0x0800).putShort((short) 8).putInt(0).putInt((int) e.crc())
                    .putInt((int) e.csize()).putInt((int) e.size()).putShort((short) name.length).putShort((short) 0)
                    .put(name);
            o.write(h.array());
            e.body().write(o);
            ByteBuffer c = header(46 + name.length, 0x02014b50);
            c.putShort((short) 20).putShort((short) 20).putShort((short) 0x0800).putShort((short) 8).putInt(0)
                    .putInt((int) e.crc()).putInt((int) e.csize()).putInt((int) e.size()).putShort((short) name.length)
                    .putShort((short) 0).putShort((short) 0).putShort((short) 0).putShort((short) 0).putInt(0)
                    .putInt((int) at).put(name);
            cd.write(c.array());
            at += 30 + name.length + e.csize();
        }
        o.write(cd.toByteArray());
        ByteBuffer end = header(22, 0x06054b50);
        end.putShort((short) 0).putShort((short) 0).putShort((short) entries.size()).putShort((short) entries.size())
                .putInt(cd.size()).putInt((int) at).putShort((short) 0);
        o.write(end.array());
    }

    private static ByteBuffer header(int size, int signature) {
        return ByteBuffer.allocate(size).order(ByteOrder.LITTLE_ENDIAN).putInt(signature);
    }
}
