package org.arflex.contract.internal;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.charset.StandardCharsets;
import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.Problem;
import org.junit.jupiter.api.Test;

/**
 * The binder on its own (without the prescan in front of it) turns every parser failure into a
 * located problem: a text node past Woodstox's limit surfaces during binding as an unchecked
 * WstxLazyException, which must not escape (issue 16, finding 7).
 */
class BinderLimitsTest {
    private static final String NS = "urn:arflex:contract:1";

    private static byte[] doc(String body) {
        return ("<component xmlns=\"" + NS + "\" name=\"huge\" version=\"1.0.0\">\n" + body + "\n</component>")
                .getBytes(StandardCharsets.UTF_8);
    }

    /** Binds in a thread of its own: Woodstox's recycled buffers are per thread, so these are fresh. */
    private static List<Problem> bindInFreshThread(byte[] doc, Object[] model) throws InterruptedException {
        List<Problem> problems = new ArrayList<>();
        Thread t = new Thread(() -> model[0] = new Binder(SecureXml.newInputFactory()).bind(doc, ContractXml.class,
                "huge.xml", problems));
        t.start();
        t.join(30_000);
        assertTrue(!t.isAlive(), "binding did not finish");
        return problems;
    }

    @Test
    void aTextNodePastTheLimitIsALocatedProblemNotAnException() throws InterruptedException {
        Object[] model = {"unset"};
        List<Problem> problems = bindInFreshThread(doc("<description>" + "x".repeat(100_000) + "</description>"),
                model);
        assertNull(model[0], "binding went on: " + problems);
        assertEquals(1, problems.size(), problems.toString());
        assertLimitProblem(problems.get(0));
    }

    @Test
    void aTextNodePastTheLimitIsRefusedWhenBuffersAreRecycled() throws InterruptedException {
        byte[] huge = doc("<description>" + "x".repeat(100_000) + "</description>");
        Object[] model = new Object[1];
        List<Problem> problems = new ArrayList<>();
        Thread t = new Thread(() -> {
            // the prescan fails on the text and closes its reader, which leaves a text buffer
            // larger than the limit for the next reader of this thread
            SecureXml.prescan(SecureXml.newInputFactory(), huge, "warm-up.xml", NS, "component", "2.3",
                    new ArrayList<>());
            model[0] = new Binder(SecureXml.newInputFactory()).bind(huge, ContractXml.class, "huge.xml", problems);
        });
        t.start();
        t.join(30_000);
        assertTrue(!problems.isEmpty(), "a text of 100000 characters was bound");
        assertLimitProblem(problems.get(0));
    }

    private static void assertLimitProblem(Problem p) {
        assertEquals("2.1", p.section());
        assertEquals("(document)", p.field());
        assertTrue(p.message().contains("parser limit"), p.message());
        assertTrue(p.line() > 0 && p.column() > 0, "no location: " + p);
    }

    @Test
    void malformedXmlDuringBindingIsALocatedProblem() {
        List<Problem> problems = new ArrayList<>();
        Binder b = new Binder(SecureXml.newInputFactory());
        ContractXml x = b.bind(doc("<description>a</descr>"), ContractXml.class, "bad.xml", problems);
        assertNull(x);
        assertEquals(1, problems.size(), problems.toString());
        assertEquals("2.1", problems.get(0).section());
        assertTrue(problems.get(0).line() > 0, "no line: " + problems.get(0));
    }

    @Test
    void prescanReportsATextNodePastTheLimitWithItsLocation() {
        List<Problem> problems = new ArrayList<>();
        boolean ok = SecureXml.prescan(SecureXml.newInputFactory(),
                doc("<description>" + "y".repeat(100_000) + "</description>"), "huge.xml", NS, "component", "2.3",
                problems);
        assertTrue(!ok);
        assertEquals(1, problems.size(), problems.toString());
        assertTrue(problems.get(0).message().contains("parser limit"), problems.get(0).message());
        assertTrue(problems.get(0).line() > 0 && problems.get(0).column() > 0, "no location: " + problems.get(0));
    }
}
