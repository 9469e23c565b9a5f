package org.arflex.planner.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.Map;
import java.util.Optional;
import org.arflex.planner.impl.LdapFilter;
import org.junit.jupiter.api.Test;

class LdapFilterTest {

    private static final Map<String, String> ROBOT = Map.of("role", "robot", "Vendor", "ABB Robotics", "payload", "5.0");

    private static boolean m(String f) {
        return LdapFilter.parse(f).matches(ROBOT);
    }

    @Test
    void operators() {
        assertTrue(m("(role=robot)"));
        assertFalse(m("(role=camera)"));
        assertTrue(m("(vendor=ABB Robotics)"), "keys are case-insensitive");
        assertTrue(m("(&(role=robot)(payload>=4))"));
        assertFalse(m("(payload<=4.5)"));
        assertFalse(m("(payload=5)"), "= compares text exactly (spec 6.6)");
        assertTrue(m("(payload=5.0)"));
        assertTrue(m("(payload>=5)"), ">= compares numbers as numbers");
        assertTrue(m("(|(role=camera)(role=robot))"));
        assertTrue(m("(!(role=camera))"));
        assertTrue(m("(vendor=*)"));
        assertFalse(m("(sim=*)"));
        assertTrue(m("(vendor=ABB*)"));
        assertTrue(m("(vendor=*Rob*ics)"));
        assertFalse(m("(vendor=*KUKA*)"));
        assertTrue(m("(vendor~=abbrobotics)"));
        assertTrue(LdapFilter.parse("(name=a\\*b)").matches(Map.of("name", "a*b")));
        assertFalse(LdapFilter.parse("(name=a\\*b)").matches(Map.of("name", "axxb")));
    }

    @Test
    void equalityHintsAreOnlyNecessaryEqualities() {
        assertEquals(Optional.of("role=robot"), LdapFilter.parse("(Role=robot)").equalityHint());
        assertEquals(Optional.of("role=robot"), LdapFilter.parse("(&(sim=*)(role=robot))").equalityHint());
        assertEquals(Optional.empty(), LdapFilter.parse("(|(role=robot)(role=camera))").equalityHint());
        assertEquals(Optional.empty(), LdapFilter.parse("(!(role=robot))").equalityHint());
        assertEquals(Optional.empty(), LdapFilter.parse("(&(!(role=robot)))").equalityHint());
        assertEquals(Optional.of("payload=5"), LdapFilter.parse("(payload=5)").equalityHint());
        assertEquals(Optional.empty(), LdapFilter.parse("(name=cam*)").equalityHint());
    }

    @Test
    void syntaxErrorsSayWhere() {
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> LdapFilter.parse("(role=robot"));
        assertEquals("filter '(role=robot': expected ')' at character 12", e.getMessage());
        e = assertThrows(IllegalArgumentException.class, () -> LdapFilter.parse("(&)"));
        assertEquals("filter '(&)': '&' needs at least one operand at character 3", e.getMessage());
        assertThrows(IllegalArgumentException.class, () -> LdapFilter.parse("role=robot"));
        assertThrows(IllegalArgumentException.class, () -> LdapFilter.parse("(=robot)"));
        assertThrows(IllegalArgumentException.class, () -> LdapFilter.parse("(a=b)(c=d)"));
        assertThrows(IllegalArgumentException.class, () -> LdapFilter.parse("(" .repeat(40) + "a=b" + ")".repeat(40)));
    }
}
