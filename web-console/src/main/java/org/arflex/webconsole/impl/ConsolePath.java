package org.arflex.webconsole.impl;

import jakarta.servlet.http.HttpServletRequest;
import java.io.ByteArrayOutputStream;
import java.nio.ByteBuffer;
import java.nio.charset.CharacterCodingException;
import java.nio.charset.CodingErrorAction;
import java.nio.charset.StandardCharsets;
import java.util.ArrayDeque;
import java.util.Deque;
import java.util.Locale;

/**
 * Decides whether a request may reach the console, from its path as the container routes it
 * rather than as the client spelled it (issue 16: {@code /%73ystem/console/...} reached the
 * console while the raw request URI did not start with the console root).
 *
 * <p>Decisions: every view of the path is consulted (the context the dispatcher chose, the
 * servlet path and path info it decoded, and the raw URI normalised here) and the request is
 * taken for the console when any one of them says so. The raw URI is normalised more
 * aggressively than Jetty does (repeated percent-decoding, path parameters dropped, backslash
 * read as slash, duplicate slashes collapsed, dot segments resolved, case ignored), because
 * reading too much as "console" only costs a same-origin check, while reading too little
 * skips it. A path that cannot be read unambiguously is {@link Verdict#UNREADABLE}, which the
 * caller treats as the console (fail closed).
 */
final class ConsolePath {
    /** Percent-decoding rounds before a path still holding '%' is called unreadable. */
    static final int MAX_DECODINGS = 3;

    /** Where a request goes. */
    enum Verdict {
        OUTSIDE, CONSOLE, UNREADABLE
    }

    /**
     * The verdict and, for {@link Verdict#UNREADABLE}, why.
     *
     * @param verdict where the request goes
     * @param why     why the path is unreadable, else null
     */
    record Result(Verdict verdict, String why) {
        /** True unless the request certainly stays outside the console. */
        boolean guarded() {
            return verdict != Verdict.OUTSIDE;
        }
    }

    private ConsolePath() {
    }

    /** Where {@code req} goes, relative to the console mounted at {@code root}. */
    static Result of(HttpServletRequest req, String root) {
        String context = nullToEmpty(req.getContextPath());
        String routed = nullToEmpty(req.getServletPath()) + nullToEmpty(req.getPathInfo());
        String[] views = {context, context + routed, routed};
        for (String view : views) {
            if (!view.isEmpty()) {
                try {
                    if (under(normalise(view), root)) {
                        return new Result(Verdict.CONSOLE, null);
                    }
                } catch (IllegalArgumentException e) {
                    return new Result(Verdict.UNREADABLE, e.getMessage());
                }
            }
        }
        String uri = req.getRequestURI();
        if (uri == null) {
            return new Result(Verdict.UNREADABLE, "no request URI");
        }
        try {
            return new Result(under(normalise(uri), root) ? Verdict.CONSOLE : Verdict.OUTSIDE, null);
        } catch (IllegalArgumentException e) {
            return new Result(Verdict.UNREADABLE, e.getMessage());
        }
    }

    /** True when {@code normalised} is the console root or below it (case ignored). */
    static boolean under(String normalised, String root) {
        return normalised.toLowerCase(Locale.ROOT).startsWith(root.toLowerCase(Locale.ROOT));
    }

    /**
     * The path with path parameters dropped, percent-encoding decoded (repeatedly), backslashes
     * read as slashes, duplicate slashes collapsed and dot segments resolved; always starts
     * with '/'.
     *
     * @throws IllegalArgumentException when that cannot be done unambiguously: malformed or
     *         still-present encoding after {@link #MAX_DECODINGS} rounds, bytes that are not
     *         UTF-8, control characters, or a ".." above the root
     */
    static String normalise(String path) {
        String p = path;
        for (int round = 0;; round++) {
            p = dropPathParameters(p.replace('\\', '/'));
            if (p.indexOf('%') < 0) {
                break;
            }
            if (round == MAX_DECODINGS) {
                throw new IllegalArgumentException("still percent-encoded after " + MAX_DECODINGS + " decodings");
            }
            p = percentDecode(p);
        }
        for (int i = 0; i < p.length(); i++) {
            char c = p.charAt(i);
            if (c < 0x20 || c == 0x7f) {
                throw new IllegalArgumentException("control character in the path");
            }
        }
        return resolveSegments(p);
    }

    /** Drops {@code ;...} up to the end of each segment, as the servlet container does. */
    private static String dropPathParameters(String p) {
        StringBuilder b = new StringBuilder(p.length());
        boolean skipping = false;
        for (int i = 0; i < p.length(); i++) {
            char c = p.charAt(i);
            if (c == '/') {
                skipping = false;
            } else if (c == ';') {
                skipping = true;
            }
            if (!skipping) {
                b.append(c);
            }
        }
        return b.toString();
    }

    private static String percentDecode(String p) {
        ByteArrayOutputStream bytes = new ByteArrayOutputStream(p.length());
        for (int i = 0; i < p.length(); i++) {
            char c = p.charAt(i);
            if (c == '%') {
                int hi = i + 2 < p.length() ? Character.digit(p.charAt(i + 1), 16) : -1;
                int lo = hi < 0 ? -1 : Character.digit(p.charAt(i + 2), 16);
                if (lo < 0) {
                    throw new IllegalArgumentException("malformed percent-encoding at character " + i);
                }
                bytes.write(hi * 16 + lo);
                i += 2;
            } else {
                byte[] b = String.valueOf(c).getBytes(StandardCharsets.UTF_8);
                bytes.write(b, 0, b.length);
            }
        }
        try {
            return StandardCharsets.UTF_8.newDecoder().onMalformedInput(CodingErrorAction.REPORT)
                    .onUnmappableCharacter(CodingErrorAction.REPORT)
                    .decode(ByteBuffer.wrap(bytes.toByteArray())).toString();
        } catch (CharacterCodingException e) {
            throw new IllegalArgumentException("percent-encoded bytes are not UTF-8");
        }
    }

    private static String resolveSegments(String p) {
        Deque<String> kept = new ArrayDeque<>();
        for (String segment : p.split("/", -1)) {
            if (segment.isEmpty() || segment.equals(".")) {
                continue;
            }
            if (segment.equals("..")) {
                if (kept.isEmpty()) {
                    throw new IllegalArgumentException("'..' above the root");
                }
                kept.removeLast();
            } else {
                kept.addLast(segment);
            }
        }
        StringBuilder b = new StringBuilder();
        for (String segment : kept) {
            b.append('/').append(segment);
        }
        // a trailing slash is kept so that "/system/console/" stays below the root
        if (p.endsWith("/") && !kept.isEmpty()) {
            b.append('/');
        }
        return b.length() == 0 ? "/" : b.toString();
    }

    private static String nullToEmpty(String s) {
        return s == null ? "" : s;
    }
}
