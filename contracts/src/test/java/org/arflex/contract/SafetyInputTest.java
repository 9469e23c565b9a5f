package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.junit.jupiter.api.Test;

/**
 * SPEC §6.8 (issue 15): a motion component declares the safety input that permits its motion;
 * it starts without a guard (and holds), and the attribute survives the writer.
 */
class SafetyInputTest {

    private static final ContractParser PARSER = ContractParser.create();

    private static String trajectory() throws Exception {
        return ContractParserTest.resource("/good/joint-trajectory.xml");
    }

    @Test
    void aSafetyInputIsParsedImpliesOptionalAndRoundTrips() throws Exception {
        Contract c = PARSER.parse(trajectory(), "t.xml");
        PortSpec s = c.port("safety").orElseThrow();
        assertTrue(s.safety());
        assertTrue(s.optional(), "a safety input never keeps its component from starting");
        assertFalse(c.port("state").orElseThrow().safety());
        String written = ContractWriter.create().write(c);
        assertTrue(written.contains("safety=\"true\""), written);
        assertEquals(c, PARSER.parse(written, "t.xml"));
    }

    @Test
    void aMotionComponentWithoutASafetyInputIsRefused() throws Exception {
        String xml = trajectory().replaceAll("<in name=\"safety\"[^>]*/>", "");
        List<Problem> p = PARSER.validate(xml, "t.xml");
        assertEquals(1, p.size(), p.toString());
        assertEquals("6.8", p.get(0).section());
        assertEquals("implementation/@movesHardware", p.get(0).field());
        assertTrue(p.get(0).message().contains("safety input") && p.get(0).line() > 0, p.get(0).toString());
        // ... as one whose only guard input is an ordinary optional one
        List<Problem> q = PARSER.validate(trajectory().replace("safety=\"true\"", "optional=\"true\""), "t.xml");
        assertTrue(q.stream().anyMatch(x -> x.field().equals("implementation/@movesHardware")), q.toString());
        // A component that does not move needs none.
        assertEquals(List.of(), PARSER.validate(xml.replace("movesHardware=\"true\" motionThrough=\"outputs\"",
                "movesHardware=\"false\""), "t.xml"));
    }

    @Test
    void aSafetyInputCarriesSafetyStateIsNeverRequiredAndNeverAnOutput() throws Exception {
        String wrongType = trajectory().replace("<in name=\"safety\" type=\"arflex.SafetyState\"",
                "<in name=\"safety\" type=\"arflex.Wrench\"");
        assertTrue(PARSER.validate(wrongType, "t.xml").stream().anyMatch(x -> x.field().equals("ports/in[safety]/@safety")
                && x.message().contains("carries arflex.SafetyState")), PARSER.validate(wrongType, "t.xml").toString());
        String required = trajectory().replace("safety=\"true\"", "safety=\"true\" optional=\"false\"");
        assertTrue(PARSER.validate(required, "t.xml").stream().anyMatch(x -> x.field().equals("ports/in[safety]/@optional")
                && x.message().contains("never required")), PARSER.validate(required, "t.xml").toString());
        String onOutput = trajectory().replace("</ports>",
                "<out name=\"guard\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\" safety=\"true\"/></ports>");
        assertTrue(PARSER.validate(onOutput, "t.xml").stream().anyMatch(x -> x.field().equals("ports/out[guard]/@safety")),
                PARSER.validate(onOutput, "t.xml").toString());
        String notBool = trajectory().replace("safety=\"true\"", "safety=\"yes\"");
        assertTrue(PARSER.validate(notBool, "t.xml").stream().anyMatch(x -> x.message().contains("not a bool")),
                PARSER.validate(notBool, "t.xml").toString());
    }
}
