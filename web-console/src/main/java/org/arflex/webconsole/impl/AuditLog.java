package org.arflex.webconsole.impl;

import com.fasterxml.jackson.core.JsonProcessingException;
import com.fasterxml.jackson.databind.ObjectMapper;
import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.channels.FileChannel;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.nio.file.StandardOpenOption;
import java.nio.file.attribute.PosixFilePermission;
import java.nio.file.attribute.PosixFilePermissions;
import java.time.Clock;
import java.time.Instant;
import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Collections;
import java.util.Deque;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Set;

/**
 * The console's audit log: one JSON object per line for every state-changing request that
 * reached the console (who, from where, what, when, the HTTP status it got and, when refused
 * or failed, why), cross-site refusals included.
 *
 * <p>The file is {@code <ARFLEX_HOME>/console-audit.log}, created on the first entry (a
 * console nobody changes anything through leaves no file), opened for appending only, mode
 * 0600 set explicitly after creation so the umask does not matter, in a folder made 0700 when
 * this log creates it. It is bounded: before an entry would take it past {@link #maxBytes}
 * it is renamed to {@code .1} (older ones shift to {@code .2} ... {@code .<keep>}, the
 * oldest dropped), so the log never holds more than {@code (keep + 1) * maxBytes}. Each line
 * is written with one append and forced to disk. Values are JSON-escaped, so a newline or
 * quote in a path or parameter cannot forge another entry.
 */
final class AuditLog {
    /** The file name under the home folder. */
    static final String FILE = "console-audit.log";
    /** Default size at which the current file is rotated. */
    static final long DEFAULT_MAX_BYTES = 1 << 20;
    /** Default number of rotated files kept. */
    static final int DEFAULT_KEEP = 3;
    /** Longest value kept per field; longer ones are cut and marked. */
    static final int MAX_VALUE = 256;

    private static final Set<PosixFilePermission> FILE_MODE = PosixFilePermissions.fromString("rw-------");
    private static final Set<PosixFilePermission> DIR_MODE = PosixFilePermissions.fromString("rwx------");

    /**
     * One audited request.
     *
     * @param time    when it was answered (ISO-8601, UTC)
     * @param user    the authenticated console user (null when unknown)
     * @param remote  the client address
     * @param method  the HTTP method
     * @param path    the request path, normalised as the cross-site guard reads it
     * @param params  the parameters that say what was asked (action, name, ...)
     * @param status  the HTTP status answered
     * @param reason  why it was refused or failed, else null
     */
    record Entry(String time, String user, String remote, String method, String path, Map<String, String> params,
            int status, String reason) {
    }

    private final Path file;
    private final long maxBytes;
    private final int keep;
    private final Clock clock;
    private final ObjectMapper json = new ObjectMapper();

    AuditLog(Path file) {
        this(file, DEFAULT_MAX_BYTES, DEFAULT_KEEP, Clock.systemUTC());
    }

    AuditLog(Path file, long maxBytes, int keep, Clock clock) {
        if (maxBytes < 256 || keep < 1) {
            throw new IllegalArgumentException("audit log: maxBytes >= 256 and keep >= 1 required");
        }
        this.file = file.toAbsolutePath().normalize();
        this.maxBytes = maxBytes;
        this.keep = keep;
        this.clock = clock;
    }

    Path file() {
        return file;
    }

    /**
     * Appends one entry (time taken now). Never throws: a log that cannot be written is
     * reported on standard error with the entry, and the request it describes is not failed
     * because of it.
     */
    Entry record(String user, String remote, String method, String path, Map<String, String> params, int status,
            String reason) {
        Map<String, String> p = new LinkedHashMap<>();
        if (params != null) {
            params.forEach((k, v) -> {
                if (k != null && v != null) {
                    p.put(cut(k), cut(v));
                }
            });
        }
        Entry e = new Entry(Instant.now(clock).toString(), cut(user), cut(remote), cut(method), cut(path),
                Collections.unmodifiableMap(p), status, cut(reason));
        try {
            append(json.writeValueAsString(e) + "\n");
        } catch (IOException | RuntimeException x) {
            System.err.println("arflex console: cannot write the audit log " + file + " (" + x + "): " + e);
        }
        return e;
    }

    private synchronized void append(String line) throws IOException {
        byte[] b = line.getBytes(StandardCharsets.UTF_8);
        Path dir = file.getParent();
        if (!Files.isDirectory(dir)) {
            Files.createDirectories(dir);
            Files.setPosixFilePermissions(dir, DIR_MODE);
        }
        if (Files.exists(file) && Files.size(file) > 0 && Files.size(file) + b.length > maxBytes) {
            rotate();
        }
        boolean fresh = !Files.exists(file);
        try (FileChannel ch = FileChannel.open(file, StandardOpenOption.CREATE, StandardOpenOption.APPEND,
                StandardOpenOption.WRITE)) {
            if (fresh || !Files.getPosixFilePermissions(file).equals(FILE_MODE)) {
                // Explicitly, whatever the umask made of the creation mode.
                Files.setPosixFilePermissions(file, FILE_MODE);
            }
            ByteBuffer buf = ByteBuffer.wrap(b);
            while (buf.hasRemaining()) {
                ch.write(buf);
            }
            ch.force(false);
        }
    }

    private void rotate() throws IOException {
        Files.deleteIfExists(rotated(keep));
        for (int i = keep - 1; i >= 1; i--) {
            if (Files.exists(rotated(i))) {
                Files.move(rotated(i), rotated(i + 1), StandardCopyOption.REPLACE_EXISTING);
            }
        }
        Files.move(file, rotated(1), StandardCopyOption.REPLACE_EXISTING);
    }

    Path rotated(int i) {
        return file.resolveSibling(file.getFileName() + "." + i);
    }

    /**
     * The newest {@code max} entries, newest first, from the current and the rotated files. A
     * line that is not an entry (a damaged file) is returned as an entry with method
     * {@code "?"} and the line as its reason, so it is seen rather than hidden.
     */
    synchronized List<Entry> recent(int max) throws IOException {
        Deque<Entry> out = new ArrayDeque<>();
        for (int i = 0; i <= keep && out.size() < max; i++) {
            Path p = i == 0 ? file : rotated(i);
            if (!Files.isRegularFile(p)) {
                continue;
            }
            List<String> lines = Files.readAllLines(p, StandardCharsets.UTF_8);
            for (int k = lines.size() - 1; k >= 0 && out.size() < max; k--) {
                String line = lines.get(k);
                if (!line.isBlank()) {
                    out.addLast(parse(line));
                }
            }
        }
        return new ArrayList<>(out);
    }

    private Entry parse(String line) {
        try {
            return json.readValue(line, Entry.class);
        } catch (JsonProcessingException e) {
            return new Entry(null, null, null, "?", null, Map.of(), 0, "unreadable audit line: " + cut(line));
        }
    }

    private static String cut(String s) {
        if (s == null || s.length() <= MAX_VALUE) {
            return s;
        }
        return s.substring(0, MAX_VALUE) + "…(" + s.length() + " chars)";
    }
}
