package org.arflex.shell;

import java.io.IOException;
import java.io.PrintStream;
import java.io.Reader;
import org.apache.felix.service.command.CommandSession;
import org.apache.felix.service.command.Converter;

/**
 * The read-execute-print loop of the console, as Gogo's own shell console behaves (prompt from
 * the session's {@code prompt} variable, else {@code "g! "}; an empty line prompts again;
 * {@code \r} ignored; end of input or ^D ends it; a result is printed formatted unless
 * {@code .Gogo.format} is false; an error prints {@code gogo: <Exception>: <message>} and is kept
 * in {@code $exception}; {@code $_} holds the last result), with one difference that is the
 * reason this class exists: it runs in a thread that has no current Gogo job, so each line is a
 * top-level job that Gogo forgets when it is done. Gogo's console runs inside the job of the
 * {@code gosh} command, and Gogo 1.1.6 adds every line's job to that job's children and never
 * removes it: each command kept its pipes and their buffered streams (about 66 KB) for the life
 * of the runtime (issue 17 finding 2; docs/DECISIONS.md D28). Characters are read as UTF-8.
 */
final class LineConsole {

    private final CommandSession session;
    private final Reader in;
    private final PrintStream out;

    LineConsole(CommandSession session, Reader in, PrintStream out) {
        this.session = session;
        this.in = in;
        this.out = out;
    }

    /** Runs until the end of input (or ^D); returns normally then. */
    void run() throws IOException {
        while (!Thread.currentThread().isInterrupted()) {
            String line = readLine();
            if (line == null) {
                return;
            }
            execute(line);
        }
    }

    private void execute(String line) {
        try {
            Object result = session.execute(line);
            session.put("_", result);
            if (result != null && !Boolean.FALSE.equals(session.get(".Gogo.format"))) {
                out.println(session.format(result, Converter.INSPECT));
            }
        } catch (Exception e) {
            session.put("exception", e);
            Object loc = session.get(".location");
            out.println((loc == null || !loc.toString().contains(":") ? "gogo" : loc) + ": " + e.getClass().getSimpleName()
                    + ": " + e.getMessage());
        }
    }

    private String prompt() {
        Object p = session.get("prompt");
        return p == null ? "g! " : p.toString();
    }

    /** The next non-empty line, or null at the end of input. */
    private String readLine() throws IOException {
        StringBuilder sb = new StringBuilder();
        String prompt = prompt();
        out.print(prompt);
        while (true) {
            out.flush();
            int c = in.read();
            switch (c) {
                case -1, 4 -> {
                    return null;
                }
                case '\r' -> {
                    // ignored, as Gogo's console does
                }
                case '\n' -> {
                    if (sb.length() > 0) {
                        return sb.toString();
                    }
                    out.print(prompt);
                }
                default -> sb.append((char) c);
            }
        }
    }
}
