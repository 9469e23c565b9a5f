package org.arflex.webconsole.impl;

import java.nio.charset.StandardCharsets;
import java.security.GeneralSecurityException;
import java.security.MessageDigest;
import java.util.Arrays;
import java.util.Base64;
import javax.crypto.SecretKeyFactory;
import javax.crypto.spec.PBEKeySpec;

/**
 * The console's stored password: a salted slow hash, {@code {pbkdf2-sha256}<iterations>$<salt>$<hash>}
 * (salt and hash standard Base64, the hash 32 bytes of PBKDF2-HMAC-SHA256), as
 * {@code scripts/console-login.sh} writes it with Python's {@code hashlib.pbkdf2_hmac}. The
 * unsalted {@code {sha-256}} form of the Web Console, which earlier versions of that script
 * wrote, is refused with a message saying how to make a new one (docs/decisions/D81).
 */
final class PasswordHash {
    /** The prefix of a stored value. */
    static final String PREFIX = "{pbkdf2-sha256}";
    /** Fewest iterations accepted. */
    static final int MIN_ITERATIONS = 100_000;
    /** Most iterations accepted (one check must stay under a few seconds). */
    static final int MAX_ITERATIONS = 10_000_000;
    /** Shortest salt accepted, in bytes. */
    static final int MIN_SALT = 16;
    private static final int HASH_BYTES = 32;

    private final int iterations;
    private final byte[] salt;
    private final byte[] hash;

    private PasswordHash(int iterations, byte[] salt, byte[] hash) {
        this.iterations = iterations;
        this.salt = salt;
        this.hash = hash;
    }

    /**
     * Reads a stored value; {@code where} names where it came from in the error.
     *
     * @throws IllegalArgumentException naming what is wrong with it (never echoing the hash)
     */
    static PasswordHash parse(String stored, String where) {
        if (stored == null || stored.isBlank()) {
            throw new IllegalArgumentException(where + ": no console password is configured; run scripts/console-login.sh");
        }
        String s = stored.trim();
        if (!s.startsWith(PREFIX)) {
            String form = s.startsWith("{") && s.indexOf('}') > 0 ? s.substring(0, s.indexOf('}') + 1) : "plain text";
            throw new IllegalArgumentException(where + ": the stored console password is " + form + ", not " + PREFIX
                    + " (an unsalted fast hash is refused since issue 30): remove the file and start again to generate"
                    + " a new password, or set ARFLEX_CONSOLE_PASSWORD (scripts/console-login.sh)");
        }
        String[] parts = s.substring(PREFIX.length()).split("\\$", -1);
        if (parts.length != 3) {
            throw new IllegalArgumentException(where + ": " + PREFIX + " value must be <iterations>$<salt>$<hash>, found "
                    + parts.length + " part(s)");
        }
        int iterations;
        try {
            iterations = Integer.parseInt(parts[0]);
        } catch (NumberFormatException e) {
            throw new IllegalArgumentException(where + ": iterations '" + cut(parts[0]) + "' is not a number");
        }
        if (iterations < MIN_ITERATIONS || iterations > MAX_ITERATIONS) {
            throw new IllegalArgumentException(where + ": " + iterations + " iterations is outside " + MIN_ITERATIONS
                    + ".." + MAX_ITERATIONS);
        }
        byte[] salt = base64(parts[1], "salt", where);
        byte[] hash = base64(parts[2], "hash", where);
        if (salt.length < MIN_SALT) {
            throw new IllegalArgumentException(where + ": a salt of " + salt.length + " bytes is too short (at least "
                    + MIN_SALT + ")");
        }
        if (hash.length != HASH_BYTES) {
            throw new IllegalArgumentException(where + ": the hash has " + hash.length + " bytes, not " + HASH_BYTES);
        }
        return new PasswordHash(iterations, salt, hash);
    }

    /** The stored form of {@code password} with this salt and number of iterations. */
    static String format(String password, byte[] salt, int iterations) {
        Base64.Encoder b = Base64.getEncoder();
        return PREFIX + iterations + "$" + b.encodeToString(salt) + "$" + b.encodeToString(derive(password, salt, iterations));
    }

    /** Whether {@code password} is the stored one (compared in constant time). */
    boolean matches(String password) {
        return MessageDigest.isEqual(hash, derive(password == null ? "" : password, salt, iterations));
    }

    int iterations() {
        return iterations;
    }

    private static byte[] derive(String password, byte[] salt, int iterations) {
        // PBEKeySpec takes chars; the JDK's PBKDF2 encodes them as UTF-8, as hashlib is given them.
        char[] pw = password.toCharArray();
        PBEKeySpec spec = new PBEKeySpec(pw, salt, iterations, HASH_BYTES * 8);
        try {
            return SecretKeyFactory.getInstance("PBKDF2WithHmacSHA256").generateSecret(spec).getEncoded();
        } catch (GeneralSecurityException e) {
            throw new IllegalStateException("PBKDF2WithHmacSHA256 is not available in this JDK", e);
        } finally {
            spec.clearPassword();
            Arrays.fill(pw, '\0');
        }
    }

    private static byte[] base64(String s, String what, String where) {
        try {
            return Base64.getDecoder().decode(s.getBytes(StandardCharsets.US_ASCII));
        } catch (IllegalArgumentException e) {
            throw new IllegalArgumentException(where + ": the " + what + " is not Base64 (" + e.getMessage() + ")");
        }
    }

    private static String cut(String s) {
        return s.length() <= 20 ? s : s.substring(0, 20) + "…";
    }
}
