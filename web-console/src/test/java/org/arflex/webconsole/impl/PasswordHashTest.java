package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import org.junit.jupiter.api.Test;

/** The stored console password: PBKDF2 as console-login.sh writes it, and what is refused. */
class PasswordHashTest {
    /** Written by Python's hashlib.pbkdf2_hmac("sha256", "pässwörd".encode(), bytes(range(16)), 100000). */
    static final String PYTHON = "{pbkdf2-sha256}100000$AAECAwQFBgcICQoLDA0ODw==$trmn14eaJqetmcWSJJwUWVLKUOyf765hiEQzeYnvalM=";

    @Test
    void checksWhatPythonWroteAndNothingElse() {
        PasswordHash h = PasswordHash.parse(PYTHON, "test");
        assertTrue(h.matches("pässwörd"));
        assertFalse(h.matches("passwörd"));
        assertFalse(h.matches(""));
        assertFalse(h.matches(null));
        assertEquals(100_000, h.iterations());
    }

    @Test
    void formatsWhatItChecks() {
        byte[] salt = new byte[16];
        salt[3] = 7;
        String stored = PasswordHash.format("s3cret", salt, 100_000);
        assertTrue(stored.startsWith("{pbkdf2-sha256}100000$"), stored);
        assertTrue(PasswordHash.parse(stored, "x").matches("s3cret"));
        assertEquals(PYTHON, PasswordHash.format("pässwörd", new byte[] {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15},
                100_000));
    }

    @Test
    void theOldUnsaltedFormIsRefusedSayingWhatToDo() {
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> PasswordHash.parse(
                "{sha-256}jGl25bVBBBW96Qi9Te4V37Fnqchz/Eu4qB9vKrRIqRg=", "console.properties"));
        assertTrue(e.getMessage().startsWith("console.properties: "), e.getMessage());
        assertTrue(e.getMessage().contains("{sha-256}") && e.getMessage().contains("ARFLEX_CONSOLE_PASSWORD")
                && e.getMessage().contains("remove the file"), e.getMessage());
        assertFalse(e.getMessage().contains("jGl25"), "the hash is not echoed: " + e.getMessage());
        assertTrue(assertThrows(IllegalArgumentException.class, () -> PasswordHash.parse("admin", "p")).getMessage()
                .contains("plain text"));
        assertTrue(assertThrows(IllegalArgumentException.class, () -> PasswordHash.parse(null, "p")).getMessage()
                .contains("no console password"));
    }

    @Test
    void badValuesAreNamed() {
        String salt = "AAECAwQFBgcICQoLDA0ODw==";
        String hash = "trmn14eaJqetmcWSJJwUWVLKUOyf765hiEQzeYnvalM=";
        assertMessage("{pbkdf2-sha256}100000$" + salt, "found 2 part(s)");
        assertMessage("{pbkdf2-sha256}many$" + salt + "$" + hash, "iterations 'many' is not a number");
        assertMessage("{pbkdf2-sha256}1000$" + salt + "$" + hash, "1000 iterations is outside 100000..");
        assertMessage("{pbkdf2-sha256}100000$AAEC$" + hash, "a salt of 3 bytes is too short");
        assertMessage("{pbkdf2-sha256}100000$" + salt + "$AAEC", "the hash has 3 bytes, not 32");
        assertMessage("{pbkdf2-sha256}100000$" + salt + "$not base64!", "the hash is not Base64");
    }

    private static void assertMessage(String stored, String part) {
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> PasswordHash.parse(stored, "where"));
        assertTrue(e.getMessage().startsWith("where: ") && e.getMessage().contains(part), e.getMessage());
    }
}
