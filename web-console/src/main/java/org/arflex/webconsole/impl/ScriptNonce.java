package org.arflex.webconsole.impl;

import jakarta.servlet.ServletOutputStream;
import jakarta.servlet.WriteListener;
import java.io.IOException;
import java.io.OutputStream;
import java.io.Writer;
import java.security.SecureRandom;
import java.util.Base64;
import java.util.function.BooleanSupplier;

/**
 * Gives every {@code <script} start tag of an HTML page the response's CSP nonce, as the page
 * streams out (no buffering of the page): {@code <script>} becomes {@code <script nonce=N>},
 * {@code <script src=...>} becomes {@code <script nonce=N src=...>}.
 *
 * <p>Why: the Web Console's own templates carry inline scripts (the page frame sets
 * {@code appRoot}, the bundles page its data) whose text changes with every response, so they
 * cannot be allowed by hash, and {@code 'unsafe-inline'} would let injected markup run too.
 * A nonce allows exactly the scripts this server wrote into the page. What it does not allow:
 * inline event handlers ({@code onerror=...}) and {@code javascript:} URLs, whatever their
 * origin, and {@code <script>} elements created by a script at run time (markup put into the
 * page through {@code innerHTML}, as Felix's bundle details do with manifest headers), which
 * are the injections this defends against. A {@code <script} that a server-side template wrote
 * from unescaped data would also be given the nonce; the Web Console writes its data as JSON
 * with {@code </} escaped, and {@link MarkupGate} keeps markup out of the headers.
 *
 * <p>The nonce is written unquoted (base64url has no character that needs quoting), so a
 * {@code "<script>"} inside a double-quoted script string stays valid script.
 */
final class ScriptNonce {
    private static final SecureRandom RANDOM = new SecureRandom();
    private static final String TAG = "<script";

    private ScriptNonce() {
    }

    /** A fresh nonce: 128 random bits, base64url. */
    static String fresh() {
        byte[] b = new byte[16];
        RANDOM.nextBytes(b);
        return Base64.getUrlEncoder().withoutPadding().encodeToString(b);
    }

    /** Where the rewriter sends its output, one char (or byte) at a time. */
    interface Sink {
        void put(int c) throws IOException;
    }

    /**
     * The streaming matcher over chars or bytes (the tag is ASCII, and no byte of a UTF-8
     * multi-byte sequence is ASCII, so bytes work as they are).
     */
    static final class Rewriter {
        private final int[] pending = new int[TAG.length()];
        private final String insert;
        private int matched;

        Rewriter(String nonce) {
            this.insert = " nonce=" + nonce;
        }

        void put(int c, Sink out) throws IOException {
            if (matched == TAG.length()) {
                emit(out, isDelimiter(c));
            } else if (matched > 0 && lower(c) == TAG.charAt(matched)) {
                pending[matched++] = c;
                return;
            } else if (matched > 0) {
                emit(out, false);
            }
            if (c == '<') {
                pending[0] = c;
                matched = 1;
            } else {
                out.put(c);
            }
        }

        /** Writes what is held back (a possible tag start) as it is: the end of the page. */
        void finish(Sink out) throws IOException {
            if (matched > 0) {
                emit(out, false);
            }
        }

        /** Forgets what is held back (the response buffer was reset). */
        void reset() {
            matched = 0;
        }

        private void emit(Sink out, boolean withNonce) throws IOException {
            for (int i = 0; i < matched; i++) {
                out.put(pending[i]);
            }
            matched = 0;
            if (withNonce) {
                for (int i = 0; i < insert.length(); i++) {
                    out.put(insert.charAt(i));
                }
            }
        }

        private static int lower(int c) {
            return c >= 'A' && c <= 'Z' ? c + ('a' - 'A') : c;
        }

        private static boolean isDelimiter(int c) {
            return c == '>' || c == '/' || c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f';
        }
    }

    /** The whole of {@code html} rewritten (for tests and small pages). */
    static String rewrite(String html, String nonce) {
        StringBuilder b = new StringBuilder(html.length() + 64);
        Rewriter r = new Rewriter(nonce);
        try {
            Sink s = c -> b.append((char) c);
            for (int i = 0; i < html.length(); i++) {
                r.put(html.charAt(i), s);
            }
            r.finish(s);
        } catch (IOException e) {
            throw new IllegalStateException(e);
        }
        return b.toString();
    }

    /**
     * A writer that rewrites when {@code active} says so at its first write (the content type
     * is known by then), and passes everything through otherwise.
     */
    static final class Chars extends Writer {
        private final Writer out;
        private final BooleanSupplier active;
        private final Rewriter rewriter;
        private final Sink sink;
        private Boolean on;

        Chars(Writer out, BooleanSupplier active, String nonce) {
            this.out = out;
            this.active = active;
            this.rewriter = new Rewriter(nonce);
            this.sink = out::write;
        }

        private boolean on() {
            if (on == null) {
                on = active.getAsBoolean();
            }
            return on;
        }

        @Override
        public void write(int c) throws IOException {
            if (on()) {
                rewriter.put(c, sink);
            } else {
                out.write(c);
            }
        }

        @Override
        public void write(char[] cbuf, int off, int len) throws IOException {
            if (!on()) {
                out.write(cbuf, off, len);
                return;
            }
            for (int i = off; i < off + len; i++) {
                rewriter.put(cbuf[i], sink);
            }
        }

        @Override
        public void write(String s, int off, int len) throws IOException {
            if (!on()) {
                out.write(s, off, len);
                return;
            }
            for (int i = off; i < off + len; i++) {
                rewriter.put(s.charAt(i), sink);
            }
        }

        void finish() throws IOException {
            rewriter.finish(sink);
        }

        void reset() {
            rewriter.reset();
        }

        @Override
        public void flush() throws IOException {
            out.flush();
        }

        @Override
        public void close() throws IOException {
            finish();
            out.close();
        }
    }

    /** The same for a servlet output stream. */
    static final class Bytes extends ServletOutputStream {
        private final ServletOutputStream out;
        private final BooleanSupplier active;
        private final Rewriter rewriter;
        private final Sink sink;
        private Boolean on;

        Bytes(ServletOutputStream out, BooleanSupplier active, String nonce) {
            this.out = out;
            this.active = active;
            this.rewriter = new Rewriter(nonce);
            this.sink = out::write;
        }

        private boolean on() {
            if (on == null) {
                on = active.getAsBoolean();
            }
            return on;
        }

        @Override
        public void write(int b) throws IOException {
            if (on()) {
                rewriter.put(b & 0xff, sink);
            } else {
                out.write(b);
            }
        }

        @Override
        public void write(byte[] b, int off, int len) throws IOException {
            if (!on()) {
                out.write(b, off, len);
                return;
            }
            for (int i = off; i < off + len; i++) {
                rewriter.put(b[i] & 0xff, sink);
            }
        }

        void finish() throws IOException {
            rewriter.finish(sink);
        }

        void reset() {
            rewriter.reset();
        }

        @Override
        public void flush() throws IOException {
            out.flush();
        }

        @Override
        public void close() throws IOException {
            finish();
            out.close();
        }

        @Override
        public boolean isReady() {
            return out.isReady();
        }

        @Override
        public void setWriteListener(WriteListener listener) {
            out.setWriteListener(listener);
        }
    }

    /** For tests: a byte stream over a plain output stream. */
    static OutputStream bytes(OutputStream target, String nonce) {
        Rewriter r = new Rewriter(nonce);
        return new OutputStream() {
            @Override
            public void write(int b) throws IOException {
                r.put(b & 0xff, target::write);
            }

            @Override
            public void close() throws IOException {
                r.finish(target::write);
                target.close();
            }
        };
    }
}
