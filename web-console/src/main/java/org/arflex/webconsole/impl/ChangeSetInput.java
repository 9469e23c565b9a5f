package org.arflex.webconsole.impl;

import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.regex.Pattern;

/**
 * The actions of a change set as typed on the Change sets page (D46): one action per line, blank
 * lines and lines starting with {@code #} ignored. Each line is checked before the DRCR sees it,
 * and a bad one is refused naming its line number, its text and what is wrong; the DRCR's own
 * checks (the component exists, the parameter is in range, the jar is pinned, ...) come after,
 * and {@link #lineOf} finds the line its refusal is about.
 *
 * @param lines  the actions, in order, trimmed, whitespace collapsed
 * @param number each action's line number in the text (1-based)
 */
record ChangeSetInput(List<String> lines, List<Integer> number) {
    /** Most actions in one set. */
    static final int MAX_ACTIONS = 32;
    /** Longest line (an update with its URL, pin, envelopes and tolerances). */
    static final int MAX_LINE = 1024;
    /** Largest text accepted. */
    static final int MAX_TEXT = 64 * 1024;
    static final String USAGE = "install <component> | uninstall <component> | set <component> <parameter> <value> | "
            + "update <component> <jar URL> [<sha256>] [window N] [shadow K] [envelope <port>.<field> <min> <max>]... "
            + "[tolerance <port>.<field> <max>]...";
    private static final Pattern COMPONENT = Pattern.compile("[a-z][a-z0-9-]{0,47}");
    private static final Pattern PARAMETER = Pattern.compile("[a-z][a-z0-9_.]{0,30}");
    /** Printable ASCII and blanks: what an action can hold (component names, numbers, URLs). */
    private static final Pattern PRINTABLE = Pattern.compile("[\\x20-\\x7e\\t]*");

    /** Parses the page's text; a bad line is a 400 naming it. */
    static ChangeSetInput parse(String text) throws HttpError {
        if (text == null || text.isBlank()) {
            throw new HttpError(400, "actions: no action given (one per line: " + USAGE + ")");
        }
        if (text.length() > MAX_TEXT) {
            throw new HttpError(413, "actions: " + text.length() + " characters, at most " + MAX_TEXT);
        }
        List<String> out = new ArrayList<>();
        List<Integer> at = new ArrayList<>();
        String[] raw = text.split("\r\n|\r|\n", -1);
        for (int i = 0; i < raw.length; i++) {
            String line = raw[i].strip();
            int n = i + 1;
            if (line.isEmpty() || line.startsWith("#")) {
                continue;
            }
            if (out.size() == MAX_ACTIONS) {
                throw new HttpError(400, "line " + n + ": more than " + MAX_ACTIONS + " actions in one set");
            }
            out.add(check(n, line));
            at.add(n);
        }
        if (out.isEmpty()) {
            throw new HttpError(400, "actions: only blank or comment lines (one action per line: " + USAGE + ")");
        }
        return new ChangeSetInput(List.copyOf(out), List.copyOf(at));
    }

    private static String check(int n, String line) throws HttpError {
        String shown = line.length() > 80 ? line.substring(0, 77) + "..." : line;
        String where = "line " + n + " ('" + shown + "'): ";
        if (line.length() > MAX_LINE) {
            throw new HttpError(400, "line " + n + ": " + line.length() + " characters, at most " + MAX_LINE);
        }
        if (!PRINTABLE.matcher(line).matches()) {
            throw new HttpError(400, "line " + n + ": a character that is not printable ASCII (at column "
                    + (firstBad(line) + 1) + ")");
        }
        if (line.indexOf(';') >= 0 || line.indexOf(',') >= 0) {
            throw new HttpError(400, where + "one action per line: ';' and ',' separate actions for the DRCR, "
                    + "put the next action on its own line");
        }
        String[] t = line.split("\\s+");
        String verb = t[0];
        switch (verb) {
            case "install", "uninstall" -> {
                if (t.length != 2) {
                    throw new HttpError(400, where + verb + " takes one component (" + verb + " <component>), got "
                            + (t.length - 1) + " words");
                }
                component(where, t[1]);
            }
            case "set" -> {
                if (t.length != 4) {
                    throw new HttpError(400, where + "set takes <component> <parameter> <value>, got " + (t.length - 1)
                            + " words");
                }
                component(where, t[1]);
                if (!PARAMETER.matcher(t[2]).matches()) {
                    throw new HttpError(400, where + "'" + t[2] + "' is not a parameter name (a lower-case letter, then a-z 0-9 _ .; up to 31)");
                }
            }
            case "update" -> {
                if (t.length < 3) {
                    throw new HttpError(400, where + "update takes <component> <jar URL> [<sha256>] [window N] [shadow K] "
                            + "[envelope ..] [tolerance ..]");
                }
                component(where, t[1]);
                String scheme = t[2].toLowerCase(Locale.ROOT);
                if (!scheme.startsWith("https:") && !scheme.startsWith("file:")) {
                    throw new HttpError(400, where + "the jar URL '" + t[2] + "' is not https: or file:");
                }
            }
            default -> throw new HttpError(400, where + "unknown action '" + verb + "' (" + USAGE + ")");
        }
        return String.join(" ", t);
    }

    private static void component(String where, String name) throws HttpError {
        if (!COMPONENT.matcher(name).matches()) {
            throw new HttpError(400, where + "'" + name + "' is not a component name (a lower-case letter, then "
                    + "a-z 0-9 -; up to 48, contracts/SPEC.md)");
        }
    }

    private static int firstBad(String s) {
        for (int i = 0; i < s.length(); i++) {
            char c = s.charAt(i);
            if (c != '\t' && (c < 0x20 || c > 0x7e)) {
                return i;
            }
        }
        return -1;
    }

    /**
     * The line a DRCR refusal is about: the first action whose verb and component start it
     * ({@code install lonely: ...}, {@code update c: ...}) or whose component it names in
     * quotes; 0 when none.
     */
    int lineOf(String refusal) {
        if (refusal == null) {
            return 0;
        }
        for (int i = 0; i < lines.size(); i++) {
            String[] t = lines.get(i).split(" ");
            if (refusal.startsWith(t[0] + " " + t[1] + ":") || refusal.contains(": " + t[0] + " " + t[1] + ":")) {
                return number.get(i);
            }
        }
        for (int i = 0; i < lines.size(); i++) {
            String[] t = lines.get(i).split(" ");
            if (refusal.contains("'" + t[1] + "'")) {
                return number.get(i);
            }
        }
        return 0;
    }
}
