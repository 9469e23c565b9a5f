package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayOutputStream;
import java.io.OutputStream;
import java.io.StringWriter;
import java.nio.charset.StandardCharsets;
import org.junit.jupiter.api.Test;

/** Every script tag the server writes gets the response's nonce; nothing else changes. */
class ScriptNonceTest {
    @Test
    void scriptStartTagsGetTheNonce() {
        assertEquals("<script nonce=N>a()</script>", ScriptNonce.rewrite("<script>a()</script>", "N"));
        assertEquals("<script nonce=N type=\"text/javascript\">", ScriptNonce.rewrite("<script type=\"text/javascript\">", "N"));
        assertEquals("<SCRIPT nonce=N\nsrc='x.js'></SCRIPT>", ScriptNonce.rewrite("<SCRIPT\nsrc='x.js'></SCRIPT>", "N"));
        assertEquals("<<script nonce=N>", ScriptNonce.rewrite("<<script>", "N"));
        assertEquals("<p>1</p><script nonce=N src=a></script><script nonce=N>b</script>",
                ScriptNonce.rewrite("<p>1</p><script src=a></script><script>b</script>", "N"));
    }

    @Test
    void otherTagsAndTextStayAsTheyAre() {
        for (String s : new String[] {"<scripts>", "<scriptx>", "<noscript>x</noscript>", "<scrip", "<script",
                "&lt;script&gt;", "a < b > c", "<img src=x onerror=alert(1)>", "üñí <sçript>", ""}) {
            assertEquals(s, ScriptNonce.rewrite(s, "N"), s);
        }
    }

    @Test
    void aScriptTagInsideAScriptStringStaysValidScript() {
        // Unquoted: a double-quoted JavaScript string that holds a tag is not broken open.
        assertEquals("<script nonce=N>var t = \"<script nonce=N>\";</script>",
                ScriptNonce.rewrite("<script>var t = \"<script>\";</script>", "N"));
    }

    @Test
    void aTagSplitAcrossWritesIsStillFound() throws Exception {
        StringWriter out = new StringWriter();
        ScriptNonce.Chars w = new ScriptNonce.Chars(out, () -> true, "N");
        w.write("<p><scr");
        w.flush();
        assertEquals("<p>", out.toString(), "a possible tag start is held back, even over a flush");
        w.write("ipt>x</script><scr");
        w.close();
        assertEquals("<p><script nonce=N>x</script><scr", out.toString());
    }

    @Test
    void aBodyThatIsNotHtmlPassesUntouched() throws Exception {
        StringWriter out = new StringWriter();
        ScriptNonce.Chars w = new ScriptNonce.Chars(out, () -> false, "N");
        w.write("<script>x</script>");
        w.close();
        assertEquals("<script>x</script>", out.toString());
    }

    @Test
    void bytesInUtf8AreRewrittenTheSame() throws Exception {
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        try (OutputStream o = ScriptNonce.bytes(b, "N")) {
            o.write("é<script>ü</script><Script src=x>".getBytes(StandardCharsets.UTF_8));
        }
        assertEquals("é<script nonce=N>ü</script><Script nonce=N src=x>", b.toString(StandardCharsets.UTF_8));
    }

    @Test
    void noncesAreFreshAndNeedNoQuoting() {
        String a = ScriptNonce.fresh();
        assertNotEquals(a, ScriptNonce.fresh());
        assertTrue(a.matches("[A-Za-z0-9_-]{22}"), a);
    }
}
