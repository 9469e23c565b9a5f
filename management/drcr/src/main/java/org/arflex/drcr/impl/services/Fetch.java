package org.arflex.drcr.impl.services;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.InputStream;
import java.net.HttpURLConnection;
import java.net.URI;
import java.net.URLConnection;

/**
 * Every download of code by the DRCR (issue 16 finding 4: a URL read without timeouts held the
 * shell for minutes). Only https: and file: URLs; connect and read timeouts; a redirect is
 * refused by name (pin the final URL); at most {@link #MAX_JAR} bytes.
 */
final class Fetch {

    static final int CONNECT_MS = 10_000;
    static final int READ_MS = 30_000;
    /** Largest bundle accepted. */
    static final int MAX_JAR = 64 << 20;

    private Fetch() {
    }

    /** Why a URL is refused before anything is opened, or null. */
    static String refusal(URI uri) {
        String scheme = uri.getScheme() == null ? "" : uri.getScheme().toLowerCase();
        if (!scheme.equals("file") && !scheme.equals("https")) {
            return "scheme '" + scheme + "' refused: only https and file URLs are allowed";
        }
        return null;
    }

    /** Reads the whole resource. */
    static byte[] read(URI uri) throws IOException {
        return read(uri, CONNECT_MS, READ_MS);
    }

    static byte[] read(URI uri, int connectMs, int readMs) throws IOException {
        String why = refusal(uri);
        if (why != null) {
            throw new IOException(why);
        }
        URLConnection conn = uri.toURL().openConnection();
        conn.setConnectTimeout(connectMs);
        conn.setReadTimeout(readMs);
        if (conn instanceof HttpURLConnection http) {
            http.setInstanceFollowRedirects(false);
            int code = http.getResponseCode();
            if (code >= 300 && code < 400) {
                throw new IOException("redirect (" + code + ") to '" + http.getHeaderField("Location")
                        + "' refused: pin the final URL");
            }
            if (code != 200) {
                throw new IOException("HTTP " + code);
            }
        }
        long declared = conn.getContentLengthLong(); // a file's size, an HTTP Content-Length: refused unread
        if (declared > MAX_JAR) {
            throw new IOException(declared + " bytes, larger than the limit of " + MAX_JAR + " bytes per jar");
        }
        try (InputStream in = conn.getInputStream()) {
            ByteArrayOutputStream out = new ByteArrayOutputStream();
            byte[] buf = new byte[65536];
            int n;
            while ((n = in.read(buf)) > 0) {
                out.write(buf, 0, n);
                if (out.size() > MAX_JAR) {
                    throw new IOException("larger than the limit of " + MAX_JAR + " bytes per jar");
                }
            }
            return out.toByteArray();
        }
    }
}
