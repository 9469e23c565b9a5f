package org.arflex.drcr.impl.services;

import java.nio.charset.StandardCharsets;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.ArrayList;
import java.util.HexFormat;
import java.util.List;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;

/**
 * The change-set history's file format (D66): text, one field a line ({@code <field> <value>}),
 * values escaped ({@code \\ \n \r \t}, other control characters {@code \}{@code uXXXX}), so the
 * plan's many lines stay on one. A header with the format's version, a {@code set} line per record
 * (newest first) followed by its fields, an {@code update} line per update followed by its
 * {@code u.} fields, and a last line {@code end <records> <sha256>} over every byte before it:
 * a file cut short or changed anywhere is refused whole, never half read. A field absent is null
 * (or 0, false). Every error names the line and the field.
 */
final class HistoryFormat {

    static final String HEADER = "arflex change-set history";
    static final int VERSION = 1;

    /** What is wrong with a file, and where. */
    static final class Bad extends Exception {
        private static final long serialVersionUID = 1L;

        Bad(String what) {
            super(what);
        }
    }

    private HistoryFormat() {
    }

    /** The records (newest first) as the file's bytes. */
    static byte[] write(List<ChangeSetDTO> records) {
        StringBuilder sb = new StringBuilder();
        sb.append(HEADER).append(' ').append(VERSION).append('\n');
        for (ChangeSetDTO d : records) {
            sb.append("set ").append(d.finishedMillis).append('\n');
            field(sb, "outcome", d.outcome);
            sb.append("admitted ").append(d.admitted).append('\n');
            sb.append("applied ").append(d.applied).append('\n');
            field(sb, "refusal", d.refusal);
            field(sb, "text", d.text);
            sb.append("prepare-ms ").append(d.prepareMs).append('\n');
            sb.append("switch-us ").append(d.switchUs).append('\n');
            for (String a : d.actions == null ? new String[0] : d.actions) {
                field(sb, "action", a);
            }
            for (UpdateProgressDTO u : d.updates == null ? new UpdateProgressDTO[0] : d.updates) {
                field(sb, "update", u.component == null ? "" : u.component);
                field(sb, "u.phase", u.phase);
                field(sb, "u.step", u.step);
                sb.append("u.cycle ").append(u.cycle).append('\n');
                sb.append("u.cycles ").append(u.cycles).append('\n');
                field(sb, "u.worst-field", u.worstField);
                sb.append("u.worst-deviation ").append(u.worstDeviation).append('\n');
                sb.append("u.tolerance ").append(u.tolerance).append('\n');
                field(sb, "u.verdict", u.verdict);
                field(sb, "u.why", u.why);
            }
        }
        byte[] body = sb.toString().getBytes(StandardCharsets.UTF_8);
        sb.append("end ").append(records.size()).append(' ').append(sha256(body)).append('\n');
        return sb.toString().getBytes(StandardCharsets.UTF_8);
    }

    /**
     * The records of a file's bytes, newest first.
     *
     * @throws Bad naming the line and the field that is wrong (or that the end line is missing)
     */
    static List<ChangeSetDTO> read(byte[] bytes) throws Bad {
        String all;
        try {
            all = StandardCharsets.UTF_8.newDecoder().decode(java.nio.ByteBuffer.wrap(bytes)).toString();
        } catch (java.nio.charset.CharacterCodingException e) {
            throw new Bad("not UTF-8 text");
        }
        if (all.isEmpty()) {
            throw new Bad("empty (line 1: no header)");
        }
        String[] lines = all.split("\n", -1);
        String first = lines[0];
        if (!first.startsWith(HEADER + " ")) {
            throw new Bad("line 1: not a change-set history (expected '" + HEADER + " " + VERSION + "', found '"
                    + shorten(first) + "')");
        }
        if (!first.equals(HEADER + " " + VERSION)) {
            throw new Bad("line 1: version '" + shorten(first.substring(HEADER.length() + 1)) + "' is not one this DRCR "
                    + "reads (" + VERSION + ")");
        }
        List<ChangeSetDTO> out = new ArrayList<>();
        ChangeSetDTO d = null;
        List<String> actions = new ArrayList<>();
        List<UpdateProgressDTO> updates = new ArrayList<>();
        UpdateProgressDTO u = null;
        int offset = first.length() + 1;
        for (int i = 1; i < lines.length; i++) {
            String line = lines[i];
            int no = i + 1;
            if (i == lines.length - 1) {
                // the text after the last newline: a complete file ends with its end line's newline
                throw new Bad("truncated: line " + no + (line.isEmpty() ? " is past the last record and no end line"
                        : " '" + shorten(line) + "' has no newline") + " (" + (out.size() + (d != null ? 1 : 0)) + " records read)");
            }
            int sp = line.indexOf(' ');
            String key = sp < 0 ? line : line.substring(0, sp);
            String raw = sp < 0 ? null : line.substring(sp + 1);
            if (raw == null) {
                throw new Bad("line " + no + ": field '" + shorten(key) + "' has no value");
            }
            if (key.equals("end")) {
                finish(d, actions, updates, out);
                String[] p = raw.split(" ");
                if (p.length != 2) {
                    throw new Bad("line " + no + ": end: expected '<records> <sha256>', found '" + shorten(raw) + "'");
                }
                if (integer(p[0], no, "end") != out.size()) {
                    throw new Bad("line " + no + ": end: says " + p[0] + " records, the file has " + out.size());
                }
                byte[] body = all.substring(0, offset).getBytes(StandardCharsets.UTF_8);
                if (!sha256(body).equals(p[1])) {
                    throw new Bad("line " + no + ": end: SHA-256 " + shorten(p[1]) + " does not match the "
                            + "lines before it (" + sha256(body) + "): changed after it was written");
                }
                if (i != lines.length - 2 || !lines[lines.length - 1].isEmpty()) {
                    throw new Bad("line " + (no + 1) + ": text after the end line");
                }
                return out;
            }
            if (key.equals("set")) {
                finish(d, actions, updates, out);
                d = new ChangeSetDTO();
                d.finishedMillis = integer(raw, no, "set");
                u = null;
            } else if (d == null) {
                throw new Bad("line " + no + ": field '" + shorten(key) + "' before the first 'set' line");
            } else if (key.startsWith("u.")) {
                if (u == null) {
                    throw new Bad("line " + no + ": field '" + shorten(key) + "' before an 'update' line");
                }
                update(u, key, raw, no);
            } else {
                switch (key) {
                    case "outcome" -> d.outcome = text(raw, no, key);
                    case "admitted" -> d.admitted = bool(raw, no, key);
                    case "applied" -> d.applied = bool(raw, no, key);
                    case "refusal" -> d.refusal = text(raw, no, key);
                    case "text" -> d.text = text(raw, no, key);
                    case "prepare-ms" -> d.prepareMs = real(raw, no, key);
                    case "switch-us" -> d.switchUs = real(raw, no, key);
                    case "action" -> actions.add(text(raw, no, key));
                    case "update" -> {
                        u = new UpdateProgressDTO();
                        u.component = text(raw, no, key);
                        updates.add(u);
                    }
                    default -> throw new Bad("line " + no + ": unknown field '" + shorten(key) + "'");
                }
            }
            offset += line.length() + 1;
        }
        throw new Bad("truncated: no end line");
    }

    private static void update(UpdateProgressDTO u, String key, String raw, int no) throws Bad {
        switch (key) {
            case "u.phase" -> u.phase = text(raw, no, key);
            case "u.step" -> u.step = text(raw, no, key);
            case "u.cycle" -> u.cycle = integer(raw, no, key);
            case "u.cycles" -> u.cycles = integer(raw, no, key);
            case "u.worst-field" -> u.worstField = text(raw, no, key);
            case "u.worst-deviation" -> u.worstDeviation = real(raw, no, key);
            case "u.tolerance" -> u.tolerance = real(raw, no, key);
            case "u.verdict" -> u.verdict = text(raw, no, key);
            case "u.why" -> u.why = text(raw, no, key);
            default -> throw new Bad("line " + no + ": unknown field '" + shorten(key) + "'");
        }
    }

    private static void finish(ChangeSetDTO d, List<String> actions, List<UpdateProgressDTO> updates,
                               List<ChangeSetDTO> out) {
        if (d == null) {
            return;
        }
        d.actions = actions.toArray(new String[0]);
        d.updates = updates.toArray(new UpdateProgressDTO[0]);
        actions.clear();
        updates.clear();
        out.add(d);
    }

    private static void field(StringBuilder sb, String key, String value) {
        if (value == null) {
            return;
        }
        sb.append(key).append(' ');
        for (int i = 0; i < value.length(); i++) {
            char c = value.charAt(i);
            switch (c) {
                case '\\' -> sb.append("\\\\");
                case '\n' -> sb.append("\\n");
                case '\r' -> sb.append("\\r");
                case '\t' -> sb.append("\\t");
                default -> {
                    if (c < 0x20 || c == 0x7f || c == '\u2028' || c == '\u2029') {
                        sb.append(String.format("\\u%04x", (int) c));
                    } else {
                        sb.append(c);
                    }
                }
            }
        }
        sb.append('\n');
    }

    private static String text(String raw, int no, String key) throws Bad {
        StringBuilder sb = new StringBuilder(raw.length());
        for (int i = 0; i < raw.length(); i++) {
            char c = raw.charAt(i);
            if (c < 0x20 || c == 0x7f) {
                throw new Bad("line " + no + ": field " + key + ": a raw control character at column " + (i + 1));
            }
            if (c != '\\') {
                sb.append(c);
                continue;
            }
            if (++i >= raw.length()) {
                throw new Bad("line " + no + ": field " + key + ": a lone '\\' at its end");
            }
            char e = raw.charAt(i);
            switch (e) {
                case '\\' -> sb.append('\\');
                case 'n' -> sb.append('\n');
                case 'r' -> sb.append('\r');
                case 't' -> sb.append('\t');
                case 'u' -> {
                    if (i + 5 > raw.length()) {
                        throw new Bad("line " + no + ": field " + key + ": '\\u' without four hex digits at column " + i);
                    }
                    try {
                        sb.append((char) Integer.parseInt(raw.substring(i + 1, i + 5), 16));
                    } catch (NumberFormatException x) {
                        throw new Bad("line " + no + ": field " + key + ": '\\u" + shorten(raw.substring(i + 1, i + 5))
                                + "' is not four hex digits (column " + i + ")");
                    }
                    i += 4;
                }
                default -> throw new Bad("line " + no + ": field " + key + ": unknown escape '\\" + e + "' at column " + i);
            }
        }
        return sb.toString();
    }

    private static long integer(String raw, int no, String key) throws Bad {
        try {
            return Long.parseLong(raw);
        } catch (NumberFormatException e) {
            throw new Bad("line " + no + ": field " + key + ": '" + shorten(raw) + "' is not a whole number");
        }
    }

    private static double real(String raw, int no, String key) throws Bad {
        try {
            if (!raw.matches("-?(NaN|Infinity|[0-9]+(\\.[0-9]+)?(E-?[0-9]+)?)")) {
                throw new NumberFormatException(raw);
            }
            return Double.parseDouble(raw);
        } catch (NumberFormatException e) {
            throw new Bad("line " + no + ": field " + key + ": '" + shorten(raw) + "' is not a number");
        }
    }

    private static boolean bool(String raw, int no, String key) throws Bad {
        if (raw.equals("true") || raw.equals("false")) {
            return raw.equals("true");
        }
        throw new Bad("line " + no + ": field " + key + ": '" + shorten(raw) + "' is not true or false");
    }

    private static String shorten(String s) {
        String t = s.length() > 80 ? s.substring(0, 80) + "..." : s;
        StringBuilder sb = new StringBuilder();
        for (char c : t.toCharArray()) {
            sb.append(c < 0x20 || c == 0x7f ? '?' : c);
        }
        return sb.toString();
    }

    static String sha256(byte[] b) {
        try {
            return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-256").digest(b));
        } catch (NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }
}
