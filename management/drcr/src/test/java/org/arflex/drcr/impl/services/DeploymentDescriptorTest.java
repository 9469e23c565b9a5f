package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.util.List;
import org.junit.jupiter.api.Test;

/** The deployment-set descriptor (D45): what it reads, and a clear error for every bad input. */
class DeploymentDescriptorTest {

    static final URI SOURCE = URI.create("file:/srv/sets/cell-2.xml");
    static final String SHA = "ab".repeat(32);
    static final String HEAD = "<deployment xmlns=\"urn:arflex:deployment:1\" name=\"cell-2\">\n";

    private static DeploymentDescriptor parse(String xml) {
        return DeploymentDescriptor.parse(xml.getBytes(StandardCharsets.UTF_8), SOURCE);
    }

    /** The message of the refusal of {@code body} inside a valid root. */
    private static String error(String body) {
        return errorOf(HEAD + body + "\n</deployment>\n");
    }

    private static String errorOf(String doc) {
        return assertThrows(IllegalArgumentException.class, () -> parse(doc)).getMessage();
    }

    @Test
    void readsInstallsAndUpdatesWithTheirOptionsInOrder() {
        DeploymentDescriptor d = parse("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- a cell -->\n" + HEAD
                + "  <install jar=\"tool-gripper-1.0.0.jar\" sha256=\"" + SHA.toUpperCase() + "\"/>\n"
                + "  <update component=\"tcp-correction\" jar=\"https://repo.example/tc/1.0.1.jar\" signed=\"true\"\n"
                + "          window=\"500\" shadow=\"0\">\n"
                + "    <envelope port=\"corrected\" field=\"q\" min=\"-3.2\" max=\"3.2\"/>\n"
                + "    <tolerance port=\"corrected\" field=\"q\" max=\"0.001\"/>\n"
                + "  </update>\n"
                + "  <install jar=\"../other/vision.jar\" signed=\"true\"></install>\n"
                + "</deployment>\n");
        assertEquals("cell-2", d.name());
        assertEquals(3, d.entries().size());
        DeploymentDescriptor.Entry g = d.entries().get(0);
        assertEquals(DeploymentDescriptor.Kind.INSTALL, g.kind());
        assertEquals(URI.create("file:/srv/sets/tool-gripper-1.0.0.jar"), g.jar(), "relative to the descriptor");
        assertEquals(SHA, g.sha256(), "the pin, lower case");
        assertEquals(4, g.line());
        DeploymentDescriptor.Entry u = d.entries().get(1);
        assertEquals("tcp-correction", u.component());
        assertNull(u.sha256(), "signed");
        assertEquals(500L, u.window());
        assertEquals(0L, u.shadow());
        assertEquals("update tcp-correction https://repo.example/tc/1.0.1.jar window 500 shadow 0 "
                + "envelope corrected.q -3.2 3.2 tolerance corrected.q 0.001", u.updateAction());
        assertEquals(URI.create("file:/srv/other/vision.jar"), d.entries().get(2).jar());
        assertEquals(2, d.installs().size());
        assertEquals(List.of(u), d.updates());
        // the update action is what arflex:change reads
        assertEquals(List.of("update tcp-correction https://repo.example/tc/1.0.1.jar  500 0 "
                        + "envelope corrected.q -3.2 3.2 tolerance corrected.q 0.001"),
                ChangeSets.parse(List.of(u.updateAction())).stream().map(a -> String.join(" ", a)).toList());
        DeploymentDescriptor pinned = parse(HEAD + "<update component=\"c\" jar=\"c.jar\" sha256=\"" + SHA + "\"/></deployment>");
        assertEquals("update c file:/srv/sets/c.jar " + SHA, pinned.entries().get(0).updateAction());
        assertEquals(List.of("update c file:/srv/sets/c.jar " + SHA + "  "),
                ChangeSets.parse(List.of(pinned.entries().get(0).updateAction())).stream()
                        .map(a -> String.join(" ", a)).toList());
        assertNull(parse("<deployment xmlns=\"urn:arflex:deployment:1\"><install jar=\"a.jar\" signed=\"true\"/>"
                + "</deployment>").name(), "the name is optional");
    }

    @Test
    void theDocumentItselfIsCheckedFirst() {
        assertEquals("file:/srv/sets/cell-2.xml:1:1: (document): not well-formed XML: Premature end of file.",
                errorOf(""));
        String unclosed = errorOf(HEAD + "<install jar=\"a.jar\" signed=\"true\">\n</deployment>");
        assertTrue(unclosed.startsWith("file:/srv/sets/cell-2.xml:3:") && unclosed.contains(": (document): not well-formed "
                + "XML: ") && unclosed.contains("install"), "the line of the end tag that does not match: " + unclosed);
        assertEquals("file:/srv/sets/cell-2.xml:1: (document): a DOCTYPE is not allowed",
                errorOf("<!DOCTYPE deployment [<!ENTITY x \"y\">]>" + HEAD + "</deployment>"));
        assertTrue(errorOf("<?xml version=\"1.0\"?>\n<?evil x?>" + HEAD + "</deployment>")
                .endsWith("(document): processing instruction <?evil?> is not allowed"));
        assertEquals("file:/srv/sets/cell-2.xml: (document): larger than 1048576 bytes; refused before parsing",
                errorOf(HEAD + " ".repeat(DeploymentDescriptor.MAX_BYTES) + "</deployment>"));
        String ns = errorOf("<deployment name=\"x\"><install jar=\"a.jar\" signed=\"true\"/></deployment>");
        assertTrue(ns.startsWith("file:/srv/sets/cell-2.xml:1:") && ns.endsWith("<deployment>: not in namespace "
                + "urn:arflex:deployment:1 (it is in no namespace)"), ns);
        assertTrue(errorOf("<set xmlns=\"urn:arflex:deployment:1\"/>")
                .endsWith("<set>: the root element must be <deployment>"));
        assertEquals("file:/srv/sets/cell-2.xml: <deployment>: names no action (an <install>, <update>, <uninstall> or <set> "
                + "element)",
                errorOf(HEAD + "</deployment>"));
        assertTrue(errorOf(HEAD.replace("cell-2", "cell 2") + "</deployment>")
                .endsWith("<deployment>: name 'cell 2' is not a set name ([A-Za-z0-9][A-Za-z0-9._-]{0,63})"));
        assertTrue(errorOf(HEAD.replace("name=", "owner=\"x\" name=") + "</deployment>")
                .endsWith("<deployment>: unknown attribute 'owner' (allowed: name)"));
    }

    @Test
    void unknownElementsAttributesAndTextAreRefusedWithTheirLine() {
        String unknown = error("<stop component=\"trajectory\"/>");
        assertTrue(unknown.startsWith("file:/srv/sets/cell-2.xml:2:") && unknown.endsWith("<stop>: unknown element in "
                + "<deployment> (expected <install>, <update>, <uninstall> or <set> in namespace urn:arflex:deployment:1)"),
                unknown);
        assertTrue(error("<x:install xmlns:x=\"urn:other\" jar=\"a.jar\" signed=\"true\"/>")
                .contains("<install>: unknown element in <deployment>"));
        assertTrue(error("<install jar=\"a.jar\" signed=\"true\" start=\"true\"/>")
                .endsWith("<install>: unknown attribute 'start' (allowed: jar, sha256, signed)"));
        assertTrue(error("<install jar=\"a.jar\" signed=\"true\" xmlns:x=\"urn:x\" x:jar=\"b.jar\"/>")
                .endsWith("<install>: unknown attribute 'x:jar' (allowed: jar, sha256, signed)"));
        assertTrue(error("hello <install jar=\"a.jar\" signed=\"true\"/>")
                .endsWith("<deployment>: text 'hello' is not allowed here"));
        assertTrue(error("<install jar=\"a.jar\" signed=\"true\">now</install>")
                .endsWith("<install>: text 'now' is not allowed here"));
        assertTrue(error("<install jar=\"a.jar\" signed=\"true\"><envelope/></install>")
                .endsWith("<envelope>: <install> has no child elements"));
        assertTrue(error("<update component=\"c\" jar=\"c.jar\" signed=\"true\"><window>5</window></update>")
                .endsWith("<window>: unknown element in <update> (expected <envelope> or <tolerance>)"));
    }

    @Test
    void everyJarIsPinnedOrSignedNeverBothNeverNeither() {
        String line = "file:/srv/sets/cell-2.xml:2:";
        String neither = error("<install jar=\"a.jar\"/>");
        assertTrue(neither.startsWith(line) && neither.endsWith("<install>: neither sha256 nor signed=\"true\": every jar "
                + "is pinned by its SHA-256 or signed by a key of the trust store"), neither);
        assertTrue(error("<install jar=\"a.jar\" sha256=\"" + SHA + "\" signed=\"true\"/>")
                .endsWith("<install>: both sha256 and signed: a jar is admitted by one of them"));
        assertTrue(error("<install jar=\"a.jar\" sha256=\"abc\"/>")
                .endsWith("<install>: sha256 'abc' is not a SHA-256 (64 hex digits)"));
        assertTrue(error("<install jar=\"a.jar\" signed=\"yes\"/>")
                .endsWith("<install>: signed 'yes': only signed=\"true\" (or give sha256)"));
        assertTrue(error("<update component=\"c\" jar=\"c.jar\" signed=\"false\"/>")
                .endsWith("<update>: signed 'false': only signed=\"true\" (or give sha256)"));
    }

    @Test
    void jarUrlsAreResolvedAndHttpsOrFileOnly() {
        assertTrue(error("<install signed=\"true\"/>").endsWith("<install>: attribute 'jar' is required"));
        assertTrue(error("<install jar=\"http://repo/a.jar\" signed=\"true\"/>")
                .endsWith("<install>: jar 'http://repo/a.jar': scheme 'http' refused: only https and file URLs are allowed"));
        assertTrue(error("<install jar=\"a b.jar\" signed=\"true\"/>")
                .endsWith("<install>: jar 'a b.jar': a URL without white space, ',' or ';'"));
        assertTrue(error("<install jar=\"a,b.jar\" signed=\"true\"/>")
                .endsWith("<install>: jar 'a,b.jar': a URL without white space, ',' or ';'"));
        assertTrue(error("<install jar=\"a%zz.jar\" signed=\"true\"/>")
                .contains("<install>: jar 'a%zz.jar' is not a URL: "));
        assertTrue(error("<install jar=\"a.jar#x\" signed=\"true\"/>")
                .endsWith("<install>: jar 'a.jar#x': a fragment (#...) names no jar"));
        String https = new String(("<deployment xmlns=\"urn:arflex:deployment:1\"><install jar=\"a.jar\" signed=\"true\"/>"
                + "</deployment>").getBytes(StandardCharsets.UTF_8), StandardCharsets.UTF_8);
        assertEquals(URI.create("https://repo.example/sets/a.jar"), DeploymentDescriptor.parse(
                https.getBytes(StandardCharsets.UTF_8), URI.create("https://repo.example/sets/s.xml")).entries().get(0).jar());
        String twice = error("<install jar=\"a.jar\" signed=\"true\"/>\n<install jar=\"./a.jar\" signed=\"true\"/>");
        assertEquals("file:/srv/sets/cell-2.xml:3: <install>: jar file:/srv/sets/a.jar is named twice in the set", twice);
    }

    @Test
    void updatesNameARunningComponentAndWellFormedOptions() {
        assertTrue(error("<update jar=\"c.jar\" signed=\"true\"/>")
                .endsWith("<update>: attribute 'component' is required (the running component it updates)"));
        assertTrue(error("<update component=\"Tcp\" jar=\"c.jar\" signed=\"true\"/>")
                .endsWith("<update>: component 'Tcp' is not a component name ([a-z][a-z0-9-]{0,47})"));
        assertTrue(error("<update component=\"c\" jar=\"c.jar\" signed=\"true\" window=\"-1\"/>")
                .endsWith("<update>: window '-1' is not a number of cycles (0..999999999)"));
        assertTrue(error("<update component=\"c\" jar=\"c.jar\" signed=\"true\" window=\"0\"/>")
                .endsWith("<update>: window '0': a rollback window is at least 1 cycle"));
        assertTrue(error("<update component=\"c\" jar=\"c.jar\" signed=\"true\" shadow=\"1e3\"/>")
                .endsWith("<update>: shadow '1e3' is not a number of cycles (0..999999999)"));
        assertTrue(error("<update component=\"c\" jar=\"c.jar\" signed=\"true\" shadow=\"1000000000\"/>")
                .endsWith("<update>: shadow '1000000000' is not a number of cycles (0..999999999)"));
        String env = "<update component=\"c\" jar=\"c.jar\" signed=\"true\">%s</update>";
        assertTrue(error(env.formatted("<envelope port=\"corrected\" min=\"0\" max=\"1\"/>"))
                .endsWith("<envelope>: attribute 'field' is required"));
        assertTrue(error(env.formatted("<envelope port=\"Corrected\" field=\"q\" min=\"0\" max=\"1\"/>"))
                .endsWith("<envelope>: port 'Corrected' is not a port name ([a-z][a-z0-9_]{0,31})"));
        assertTrue(error(env.formatted("<envelope port=\"corrected\" field=\"q.x\" min=\"0\" max=\"1\"/>"))
                .endsWith("<envelope>: field 'q.x' is not a field name ([a-z][a-z0-9_]{0,31})"));
        assertTrue(error(env.formatted("<envelope port=\"corrected\" field=\"q\" min=\"NaN\" max=\"1\"/>"))
                .endsWith("<envelope>: min 'NaN' is not a finite decimal number"));
        assertTrue(error(env.formatted("<envelope port=\"corrected\" field=\"q\" min=\"0\" max=\"1d\"/>"))
                .endsWith("<envelope>: max '1d' is not a finite decimal number"));
        assertTrue(error(env.formatted("<envelope port=\"corrected\" field=\"q\" min=\"2\" max=\"1\"/>"))
                .endsWith("<envelope>: min 2 is above max 1"));
        assertTrue(error(env.formatted("<tolerance port=\"corrected\" field=\"q\" max=\"-0.5\"/>"))
                .endsWith("<tolerance>: max -0.5 is negative (a largest difference is >= 0)"));
        assertTrue(error(env.formatted("<tolerance port=\"corrected\" field=\"q\" min=\"0\" max=\"1\"/>"))
                .endsWith("<tolerance>: unknown attribute 'min' (allowed: field, max, port)"));
        String twice = error("<update component=\"c\" jar=\"c1.jar\" signed=\"true\"/>\n"
                + "<update component=\"c\" jar=\"c2.jar\" signed=\"true\"/>");
        assertEquals("file:/srv/sets/cell-2.xml:3: <update>: component 'c' is named twice in the set (also <update> on line 2)", twice);
    }

    @Test
    void atMostSixtyFourBundles() {
        StringBuilder sb = new StringBuilder();
        for (int i = 0; i <= DeploymentDescriptor.MAX_ENTRIES; i++) {
            sb.append("<install jar=\"b").append(i).append(".jar\" signed=\"true\"/>\n");
        }
        String e = error(sb.toString());
        assertTrue(e.startsWith("file:/srv/sets/cell-2.xml:66:") && e.endsWith("<install>: more than 64 actions in one set"), e);
    }

    @Test
    void readsUninstallsAndParameterWritesAsChangeSetActions() {
        DeploymentDescriptor d = parse(HEAD
                + "  <install jar=\"tool-gripper.jar\" sha256=\"" + SHA + "\"/>\n"
                + "  <uninstall component=\"teach\"/>\n"
                + "  <set component=\"tcp-correction\" parameter=\"gain\" value=\"0.5\"/>\n"
                + "  <set component=\"tcp-correction\" parameter=\"enable\" value=\"false\"></set>\n"
                + "</deployment>\n");
        assertEquals(4, d.entries().size());
        assertEquals(1, d.bundles().size());
        List<DeploymentDescriptor.Entry> c = d.changes();
        assertEquals(List.of("uninstall teach", "set tcp-correction gain 0.5", "set tcp-correction enable false"),
                c.stream().map(DeploymentDescriptor.Entry::action).toList());
        assertEquals(List.of(3, 4, 5), c.stream().map(DeploymentDescriptor.Entry::line).toList());
        assertEquals(DeploymentDescriptor.Kind.UNINSTALL, c.get(0).kind());
        assertNull(c.get(0).jar());
        // what ChangeSets reads back is what the descriptor says
        List<String[]> parsed = ChangeSets.parse(c.stream().map(DeploymentDescriptor.Entry::action).toList());
        assertEquals(List.of("uninstall teach", "set tcp-correction gain 0.5", "set tcp-correction enable false"),
                parsed.stream().map(a -> String.join(" ", a)).toList());
        // a set of changes only, without a jar
        assertEquals(1, parse(HEAD + "<uninstall component=\"teach\"/></deployment>").entries().size());
    }

    @Test
    void everyBadUninstallOrWriteIsNamedWithItsLine() {
        String u = error("<uninstall/>");
        assertTrue(u.matches("file:/srv/sets/cell-2.xml:2:\\d+: <uninstall>: attribute 'component' is required "
                + "\\(the running component it stops and removes\\)"), u);
        assertTrue(error("<uninstall component=\"teach\" jar=\"a.jar\"/>")
                .matches("file:/srv/sets/cell-2.xml:2:\\d+: <uninstall>: unknown attribute 'jar' \\(allowed: component\\)"));
        assertTrue(error("<uninstall component=\"Teach\"/>")
                .endsWith("<uninstall>: component 'Teach' is not a component name ([a-z][a-z0-9-]{0,47})"));
        assertTrue(error("<uninstall component=\"teach\"><envelope/></uninstall>")
                .endsWith("<envelope>: <uninstall> has no child elements"));
        assertTrue(error("<uninstall component=\"teach\">now</uninstall>").endsWith("<uninstall>: text 'now' is not allowed here"));
        String s = error("\n\n<set component=\"c\" parameter=\"gain\"/>");
        assertTrue(s.matches("file:/srv/sets/cell-2.xml:4:\\d+: <set>: attribute 'value' is required"), s);
        assertTrue(error("<set component=\"c\" value=\"1\"/>").endsWith("<set>: attribute 'parameter' is required"));
        assertTrue(error("<set parameter=\"gain\" value=\"1\"/>").endsWith("<set>: attribute 'component' is required "
                + "(the component whose parameter it writes)"));
        assertTrue(error("<set component=\"c\" parameter=\"Gain\" value=\"1\"/>")
                .endsWith("<set>: parameter 'Gain' is not a parameter name ([a-z][a-z0-9_.]{0,30})"));
        for (String v : new String[] {"1 2", "1;uninstall x", "1,2", "", "\u00e9", "x".repeat(65)}) {
            assertTrue(error("<set component=\"c\" parameter=\"gain\" value=\"" + v + "\"/>")
                    .endsWith("<set>: value '" + v + "': 1 to 64 printable characters without blanks, ';' or ','"), v);
        }
        assertTrue(error("<set component=\"c\" parameter=\"gain\" value=\"1\" unit=\"1\"/>")
                .endsWith("<set>: unknown attribute 'unit' (allowed: component, parameter, value)"));
        assertEquals("file:/srv/sets/cell-2.xml:3: <set>: parameter c.gain is written twice in the set",
                error("<set component=\"c\" parameter=\"gain\" value=\"1\"/>\n<set component=\"c\" parameter=\"gain\" value=\"2\"/>"));
        assertEquals("file:/srv/sets/cell-2.xml:3: <uninstall>: component 'c' is named twice in the set (also <update> on line 2)",
                error("<update component=\"c\" jar=\"c1.jar\" signed=\"true\"/>\n<uninstall component=\"c\"/>"));
        assertTrue(error("<remove component=\"c\"/>").endsWith("<remove>: unknown element in <deployment> (expected "
                + "<install>, <update>, <uninstall> or <set> in namespace urn:arflex:deployment:1)"));
    }
}
