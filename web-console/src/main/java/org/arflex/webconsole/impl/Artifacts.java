package org.arflex.webconsole.impl;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.net.URI;
import java.net.URISyntaxException;
import java.net.http.HttpClient;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.security.DigestOutputStream;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.time.Duration;
import java.util.HexFormat;
import java.util.Locale;
import java.util.jar.JarFile;
import java.util.jar.Manifest;
import java.util.zip.ZipEntry;
import java.util.zip.ZipFile;
import java.util.regex.Pattern;

/**
 * Bringing a component bundle in: from a URL under the DRCR's update rules (https or file only,
 * SHA-256 pinned and checked before anything is installed; file only inside the configured
 * {@link StagingSources} folders; no redirect) or from an upload, into a private staging
 * directory. Every refusal names what is wrong.
 */
final class Artifacts {
    /** Largest bundle accepted. */
    static final long MAX_BYTES = 64L << 20;
    private static final Pattern SHA256 = Pattern.compile("[0-9a-f]{64}");

    private Artifacts() {
    }

    /** A bundle copied into staging, with its digest and symbolic name. */
    record Staged(Path file, String sha256, String symbolicName, String version, String origin) {
    }

    /** Checks a URL and pinned hash against the rules; returns the URI. */
    static URI checkUrl(String url, String sha256) throws HttpError {
        if (url == null || url.isBlank()) {
            throw new HttpError(400, "url: missing");
        }
        URI u;
        try {
            u = new URI(url.trim());
        } catch (URISyntaxException e) {
            throw new HttpError(400, "url: not a URL (" + e.getReason() + ")");
        }
        String scheme = u.getScheme() == null ? "" : u.getScheme().toLowerCase(Locale.ROOT);
        if (!scheme.equals("https") && !scheme.equals("file")) {
            throw new HttpError(400, "url: scheme '" + scheme + "' refused; only https or file are allowed");
        }
        if (scheme.equals("https") && (u.getHost() == null || u.getUserInfo() != null)) {
            throw new HttpError(400, "url: an https URL needs a host and no user info");
        }
        checkSha(sha256);
        return u;
    }

    /** Checks the pinned hash syntax. */
    static String checkSha(String sha256) throws HttpError {
        if (sha256 == null || sha256.isBlank()) {
            throw new HttpError(400, "sha256: missing; a URL install needs the pinned SHA-256 of the jar");
        }
        String s = sha256.trim().toLowerCase(Locale.ROOT);
        if (!SHA256.matcher(s).matches()) {
            throw new HttpError(400, "sha256: '" + sha256 + "' is not 64 hexadecimal digits");
        }
        return s;
    }

    /**
     * Downloads the URL into staging and checks the pinned hash; the file is removed on any
     * failure. A {@code file:} URL must name a file in one of {@code sources}' folders.
     */
    static Staged fetch(URI u, String pinned, Path stagingDir, StagingSources sources) throws HttpError, IOException {
        String expected = checkSha(pinned);
        // opened before the staging file is made: a refused source leaves nothing behind
        InputStream source = open(u, sources);
        Path tmp;
        try {
            tmp = Files.createTempFile(Files.createDirectories(stagingDir), "fetch-", ".jar");
        } catch (IOException e) {
            source.close();
            throw e;
        }
        boolean ok = false;
        try {
            try (InputStream in = source) {
                String actual = copyBounded(in, tmp);
                if (!actual.equals(expected)) {
                    throw new HttpError(400, "sha256: the jar at " + u + " has SHA-256 " + actual
                            + ", not the pinned " + expected + "; nothing installed");
                }
            }
            Staged s = inspect(tmp, expected, u.toString());
            ok = true;
            return s;
        } finally {
            if (!ok) {
                Files.deleteIfExists(tmp);
            }
        }
    }

    /** Copies an uploaded body into staging; the digest is computed here. */
    static Staged upload(InputStream body, String name, Path stagingDir) throws HttpError, IOException {
        Path tmp = Files.createTempFile(Files.createDirectories(stagingDir), "upload-", ".jar");
        boolean ok = false;
        try {
            String sha = copyBounded(body, tmp);
            Staged s = inspect(tmp, sha, "upload " + (name == null ? "(unnamed)" : name));
            ok = true;
            return s;
        } finally {
            if (!ok) {
                Files.deleteIfExists(tmp);
            }
        }
    }

    /** Moves a staged jar to its final place, named by its digest. */
    static Path keep(Staged s, Path dir) throws IOException {
        Path target = Files.createDirectories(dir).resolve(s.sha256() + ".jar");
        return Files.move(s.file(), target, StandardCopyOption.REPLACE_EXISTING);
    }

    private static InputStream open(URI u, StagingSources sources) throws HttpError, IOException {
        if ("file".equalsIgnoreCase(u.getScheme())) {
            return Files.newInputStream(sources.file(u));
        }
        try {
            HttpResponse<InputStream> r = client().send(HttpRequest.newBuilder(u).timeout(Duration.ofSeconds(60))
                    .GET().build(), HttpResponse.BodyHandlers.ofInputStream());
            if (r.statusCode() / 100 == 3) {
                r.body().close();
                throw new HttpError(400, "url: redirect refused: " + u + " answered HTTP " + r.statusCode()
                        + " to " + r.headers().firstValue("Location").orElse("(no Location)")
                        + "; give the final https URL");
            }
            if (r.statusCode() != 200) {
                r.body().close();
                throw new HttpError(502, "url: " + u + " answered HTTP " + r.statusCode());
            }
            return r.body();
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IOException("interrupted while downloading " + u, e);
        }
    }

    /**
     * The download client. Redirects are never followed: the pinned URL is the one fetched, and
     * a redirect is refused by name rather than reported as a hash mismatch of its body.
     */
    static HttpClient client() {
        return HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(10)).followRedirects(HttpClient.Redirect.NEVER)
                .build();
    }

    private static String copyBounded(InputStream in, Path to) throws IOException, HttpError {
        MessageDigest md;
        try {
            md = MessageDigest.getInstance("SHA-256");
        } catch (NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
        long total = 0;
        try (OutputStream out = new DigestOutputStream(Files.newOutputStream(to), md)) {
            byte[] buf = new byte[65536];
            for (int n; (n = in.read(buf)) > 0;) {
                total += n;
                if (total > MAX_BYTES) {
                    throw new HttpError(413, "jar larger than " + (MAX_BYTES >> 20) + " MiB refused");
                }
                out.write(buf, 0, n);
            }
        }
        if (total == 0) {
            throw new HttpError(400, "empty file: no jar received");
        }
        return HexFormat.of().formatHex(md.digest());
    }

    private static Staged inspect(Path jar, String sha, String origin) throws HttpError {
        try (ZipFile zf = new ZipFile(jar.toFile())) {
            var mf = manifest(zf, origin);
            String bsn = mf == null ? null : mf.getMainAttributes().getValue("Bundle-SymbolicName");
            if (bsn == null) {
                throw new HttpError(400, origin + ": not an OSGi bundle (no Bundle-SymbolicName in the manifest)");
            }
            String version = mf.getMainAttributes().getValue("Bundle-Version");
            return new Staged(jar, sha, bsn.split(";")[0].trim(), version == null ? "0.0.0" : version, origin);
        } catch (IOException e) {
            throw new HttpError(400, origin + ": not a jar (" + e.getMessage() + ")");
        }
    }

    /** Largest manifest read (the runtime's largest bundle has one of about 30 KiB). */
    static final int MAX_MANIFEST = 1 << 20;

    /**
     * The manifest, read within {@link #MAX_MANIFEST} bytes whatever the jar declares (issue 30,
     * finding 1: a zip bomb in place of a manifest fills the heap); null when there is none.
     */
    private static Manifest manifest(ZipFile zf, String origin) throws IOException, HttpError {
        ZipEntry e = zf.getEntry(JarFile.MANIFEST_NAME);
        if (e == null) {
            return null;
        }
        try (InputStream in = zf.getInputStream(e)) {
            byte[] b = in.readNBytes(MAX_MANIFEST + 1);
            if (b.length > MAX_MANIFEST) {
                throw new HttpError(400, origin + ": entry " + JarFile.MANIFEST_NAME + " inflates past the limit of "
                        + MAX_MANIFEST + " bytes per manifest");
            }
            return new Manifest(new ByteArrayInputStream(b));
        }
    }
}
