package org.arflex.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayOutputStream;
import java.io.PrintStream;
import java.io.StringReader;
import java.lang.reflect.Proxy;
import java.nio.charset.StandardCharsets;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import org.apache.felix.service.command.CommandSession;
import org.junit.jupiter.api.Test;

/** The console loop behaves as Gogo's console: prompts, results, errors, variables, end of input. */
class LineConsoleTest {

    private final List<String> executed = new ArrayList<>();
    private final Map<String, Object> vars = new HashMap<>();

    private CommandSession session() {
        return (CommandSession) Proxy.newProxyInstance(getClass().getClassLoader(), new Class<?>[] {CommandSession.class},
                (p, m, a) -> switch (m.getName()) {
                    case "execute" -> {
                        String line = a[0].toString();
                        executed.add(line);
                        if (line.startsWith("fail")) {
                            throw new IllegalArgumentException("no such thing: " + line);
                        }
                        yield line.startsWith("quiet") ? null : "result of " + line;
                    }
                    case "format" -> "<" + a[0] + ">";
                    case "get" -> vars.get((String) a[0]);
                    case "put" -> vars.put((String) a[0], a[1]);
                    default -> throw new UnsupportedOperationException(m.getName());
                });
    }

    private String run(String input) throws Exception {
        ByteArrayOutputStream bytes = new ByteArrayOutputStream();
        new LineConsole(session(), new StringReader(input), new PrintStream(bytes, true, StandardCharsets.UTF_8)).run();
        return bytes.toString(StandardCharsets.UTF_8);
    }

    @Test
    void linesRunInOrderWithPromptsResultsAndErrors() throws Exception {
        String out = run("lb\r\n\nquiet x\nfail y\nécho ü\n");
        assertEquals(List.of("lb", "quiet x", "fail y", "écho ü"), executed);
        assertEquals("g! <result of lb>\ng! g! g! gogo: IllegalArgumentException: no such thing: fail y\ng! <result of écho ü>\ng! ", out);
        assertTrue(vars.get("exception") instanceof IllegalArgumentException);
        assertEquals("result of écho ü", vars.get("_"));
    }

    @Test
    void theSessionsPromptAndFormatSwitchAreHonoured() throws Exception {
        vars.put("prompt", "cell> ");
        vars.put(".Gogo.format", false);
        assertEquals("cell> cell> ", run("lb\n"));
    }

    @Test
    void endOfTransmissionEndsTheConsoleLikeTheEndOfInput() throws Exception {
        run("lb\n\u0004never\n");
        assertEquals(List.of("lb"), executed);
    }
}
