package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.Map;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.CsvSource;

class FilterTest {
    private static final Map<String, String> ROBOT = Map.of("role", "robot", "sim", "true", "Vendor", "ACME Robotics",
            "rate", "1000", "name", "arm-left-2", "paren", "a(b)c");

    @ParameterizedTest(name = "{0} -> {1}")
    @CsvSource(delimiter = ';', value = {
        "(role=robot); true",
        "(role=Robot); false",
        "(ROLE=robot); true",
        "(role=camera); false",
        "(missing=x); false",
        "(role=*); true",
        "(missing=*); false",
        "(&(role=robot)(sim=true)); true",
        "(&(role=robot)(sim=false)); false",
        "(|(role=camera)(sim=true)); true",
        "(|(role=camera)(sim=false)); false",
        "(!(role=camera)); true",
        "(!(role=robot)); false",
        "(vendor~=acmerobotics); true",
        "(vendor~= ACME  robotics ); true",
        "(vendor~=acme); false",
        "(rate>=999.5); true",
        "(rate>=1000); true",
        "(rate<=100); false",
        "(rate<=1e4); true",
        "(name>=arm); true",
        "(name=arm*); true",
        "(name=*left*); true",
        "(name=*-2); true",
        "(name=arm*right*); false",
        "(name=a*m*l*t-2); true",
        "(name=arm-left-2*); true",
        "(name=arm-left-2x*); false",
        "(paren=a\\(b\\)c); true",
        "( & (role=robot) ( ! (sim=false) ) ); true",
    })
    void matches(String filter, boolean expected) {
        assertEquals(expected, Filter.parse(filter).matches(ROBOT), filter);
    }

    @ParameterizedTest(name = "[{index}] {0}")
    @CsvSource(delimiter = ';', value = {
        "role=robot; expected '('",
        "(role=robot; not closed by ')'",
        "(role=robot)); unexpected ')'",
        "(&); needs at least one operand",
        "(|); needs at least one operand",
        "(!); expected '('",
        "(=robot); expected an attribute name",
        "(role); expected an operator",
        "(role>robot); expected an operator",
        "(role>=rob*); wildcards are only allowed with '='",
        "(role=a(b); must be escaped",
        "(role=abc\\; dangling backslash",
        "''; expected '(' but the filter ended",
    })
    void refusesBadSyntaxWithAReason(String filter, String fragment) {
        Filter.SyntaxException e = assertThrows(Filter.SyntaxException.class, () -> Filter.parse(filter));
        assertTrue(e.getMessage().contains(fragment), e.getMessage());
        assertTrue(e.position() >= 0);
    }

    @Test
    void nestingIsBounded() {
        String deep = "(!".repeat(40) + "(a=b)" + ")".repeat(40);
        assertThrows(Filter.SyntaxException.class, () -> Filter.parse(deep));
        String ok = "(!".repeat(20) + "(a=b)" + ")".repeat(20);
        assertFalse(Filter.parse(ok).matches(Map.of("a", "b")) == Filter.parse("(a=b)").matches(Map.of("a", "b")) == false);
    }

    @Test
    void canonicalTextRoundTrips() {
        Filter f = Filter.parse("( & (role=robot) (name=a\\*b*) (!(x=*)))");
        assertEquals("(&(role=robot)(name=a\\*b*)(!(x=*)))", f.toString());
        assertEquals(f, Filter.parse(f.toString()));
        assertTrue(f.matches(Map.of("role", "robot", "name", "a*bcd")));
        assertFalse(f.matches(Map.of("role", "robot", "name", "abcd")));
    }
}
