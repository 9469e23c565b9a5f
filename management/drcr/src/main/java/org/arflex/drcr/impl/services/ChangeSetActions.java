package org.arflex.drcr.impl.services;

import java.util.ArrayList;
import java.util.List;
import org.arflex.drcr.impl.runtime.ChangeSet;

/**
 * The actions of a change set as typed (D35, D38, D42), parsed into one array per action:
 * {@code install n}, {@code uninstall n}, {@code set n p v}, and an update as
 * {@code update n url sha|"" window|"" shadow|""} followed by its {@code envelope ...} and
 * {@code tolerance ...} options; every malformed action named with what it needs.
 */
final class ChangeSetActions {

    /** The usage of the actions. */
    static final String ACTIONS = "actions: install <component>, uninstall <component>, set <component> <parameter> "
            + "<value>, update <component> <jar URL> [<sha256>] [window <cycles>] [shadow <cycles>] [envelope <port>.<field> "
            + "<min> <max>]... [tolerance <port>.<field> <max difference>]...";

    private ChangeSetActions() {
    }

    /**
     * The actions, parsed: {@code install n}, {@code uninstall n}, {@code set n p v},
     * {@code update n <url> [<sha256>] [window <cycles>]} (as {@code update n url sha|"" cycles|""}),
     * also as one token list.
     *
     * @throws IllegalArgumentException naming the action and what is wrong with it
     */
    static List<String[]> parse(List<String> actions) {
        List<String> tokens = new ArrayList<>();
        for (String a : actions) {
            for (String t : a.trim().split("[\\s;,]+")) {
                if (!t.isEmpty()) {
                    tokens.add(t);
                }
            }
        }
        List<String[]> out = new ArrayList<>();
        for (int i = 0; i < tokens.size(); ) {
            String verb = tokens.get(i);
            int n = switch (verb) {
                case "install", "uninstall" -> 2;
                case "set" -> 4;
                case "update" -> 3;
                default -> throw new IllegalArgumentException("unknown action '" + verb + "' (" + ACTIONS + ")");
            };
            if (i + n > tokens.size()) {
                throw new IllegalArgumentException("'" + String.join(" ", tokens.subList(i, tokens.size()))
                        + "' is incomplete (" + verb + switch (verb) {
                            case "set" -> " <component> <parameter> <value>";
                            case "update" -> " <component> <jar URL> [<sha256>] [window <cycles>] [shadow <cycles>] "
                                    + "[envelope <port>.<field> <min> <max>]... [tolerance <port>.<field> <max difference>]...";
                            default -> " <component>";
                        } + ")");
            }
            if (!verb.equals("update")) {
                out.add(tokens.subList(i, i + n).toArray(String[]::new));
                i += n;
                continue;
            }
            List<String> u = new ArrayList<>(List.of(verb, tokens.get(i + 1), tokens.get(i + 2), "", "", ""));
            i += 3;
            if (i < tokens.size() && tokens.get(i).matches("[0-9a-fA-F]{64}")) {
                u.set(3, tokens.get(i++));
            }
            while (i < tokens.size() && List.of("window", "shadow", "envelope", "tolerance").contains(tokens.get(i))) {
                if (tokens.get(i).equals("window") || tokens.get(i).equals("shadow")) {
                    if (i + 1 >= tokens.size() || !tokens.get(i + 1).matches("[0-9]{1,9}")) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": " + tokens.get(i)
                                + " needs a number of cycles");
                    }
                    u.set(tokens.get(i).equals("window") ? 4 : 5, tokens.get(i + 1));
                    i += 2;
                } else if (tokens.get(i).equals("tolerance")) {
                    if (i + 2 >= tokens.size() || !tokens.get(i + 1).matches("[a-z][a-z0-9_]*\\.[a-z][a-z0-9_]*")) {
                        throw new IllegalArgumentException("update " + u.get(1)
                                + ": tolerance needs <port>.<field> <max difference>");
                    }
                    try {
                        new ChangeSet.Tolerance("p", "f", Double.parseDouble(tokens.get(i + 2)));
                    } catch (IllegalArgumentException e) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": tolerance " + tokens.get(i + 1)
                                + ": " + tokens.get(i + 2) + " is not a tolerance (a finite number >= 0)");
                    }
                    u.add("tolerance " + tokens.get(i + 1) + " " + tokens.get(i + 2));
                    i += 3;
                } else {
                    if (i + 3 >= tokens.size() || !tokens.get(i + 1).matches("[a-z][a-z0-9_]*\\.[a-z][a-z0-9_]*")) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": envelope needs <port>.<field> <min> <max>");
                    }
                    try {
                        new ChangeSet.Envelope("p", "f", Double.parseDouble(tokens.get(i + 2)),
                                Double.parseDouble(tokens.get(i + 3)));
                    } catch (IllegalArgumentException e) {
                        throw new IllegalArgumentException("update " + u.get(1) + ": envelope " + tokens.get(i + 1)
                                + ": " + tokens.get(i + 2) + " " + tokens.get(i + 3) + " is not a range (<min> <max>)");
                    }
                    u.add("envelope " + tokens.get(i + 1) + " " + tokens.get(i + 2) + " " + tokens.get(i + 3));
                    i += 4;
                }
            }
            out.add(u.toArray(String[]::new));
        }
        return out;
    }

    /**
     * The actions as one text per action, in the words the shell takes ({@code update c file:/c.jar
     * <sha256> window 1000 shadow 200 tolerance corrected.q 1e-6}), whether they came as Gogo's
     * words or one string per action: what a set's progress and history record. Actions that do
     * not parse are returned as given (their refusal names them).
     */
    static List<String> normalized(List<String> actions) {
        List<String[]> parsed;
        try {
            parsed = parse(actions);
        } catch (IllegalArgumentException e) {
            return actions;
        }
        List<String> out = new ArrayList<>();
        for (String[] p : parsed) {
            if (!p[0].equals("update")) {
                out.add(String.join(" ", p));
                continue;
            }
            StringBuilder sb = new StringBuilder("update ").append(p[1]).append(' ').append(p[2]);
            if (!p[3].isEmpty()) {
                sb.append(' ').append(p[3]);
            }
            if (!p[4].isEmpty()) {
                sb.append(" window ").append(p[4]);
            }
            if (!p[5].isEmpty()) {
                sb.append(" shadow ").append(p[5]);
            }
            for (int k = 6; k < p.length; k++) {
                sb.append(' ').append(p[k]);
            }
            out.add(sb.toString());
        }
        return out;
    }
}
