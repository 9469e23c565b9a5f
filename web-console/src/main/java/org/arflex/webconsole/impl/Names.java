package org.arflex.webconsole.impl;

import java.util.ArrayList;
import java.util.List;
import java.util.regex.Pattern;

/** Component and port names as the console's endpoints accept them; a refusal names what is wrong. */
final class Names {
    private static final Pattern NAME = Pattern.compile("[A-Za-z0-9][A-Za-z0-9._-]{0,63}");
    private static final Pattern PORT = Pattern.compile("[a-z0-9_]{1,31}");

    private Names() {
    }

    static void checkName(String name) throws HttpError {
        if (name == null || !NAME.matcher(name).matches()) {
            throw new HttpError(400, "name: '" + name + "' is not a component name (letters, digits, . _ -; up to 64)");
        }
    }

    /** Checks a port name as the ABI allows it ({@code [a-z0-9_]{1,31}}). */
    static void checkPort(String port) throws HttpError {
        if (port == null || !PORT.matcher(port).matches()) {
            throw new HttpError(400, "port: '" + port + "' is not a port name (a-z, 0-9, _; up to 31)");
        }
    }

    /** {@code p1,p2} to a list of checked port names (none when absent). */
    static List<String> portList(String text) throws HttpError {
        if (text == null || text.isBlank()) {
            return List.of();
        }
        String[] parts = text.split(",");
        if (parts.length > Sampler.MAX_PORTS) {
            throw new HttpError(400, "ports: at most " + Sampler.MAX_PORTS + " ports per stream, got " + parts.length);
        }
        List<String> out = new ArrayList<>();
        for (String p : parts) {
            checkPort(p.trim());
            out.add(p.trim());
        }
        return out;
    }
}
