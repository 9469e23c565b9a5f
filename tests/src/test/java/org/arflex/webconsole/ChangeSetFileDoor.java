package org.arflex.webconsole;

import java.net.http.HttpResponse;
import java.util.List;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * Issue 30 finding 9 as an attacker with the console's login tries it: an update on the Change
 * sets page whose {@code file:} URL names a file outside the staging folders (the DRCR read it
 * as root and answered with its SHA-256, or "No such file"). The attempt succeeded when an
 * answer is not a refusal, names a SHA-256 other than the pin sent, or says whether the file
 * exists. The control: a jar inside a staging folder with a wrong pin gets the DRCR's answer
 * with the jar's SHA-256 (the check sees a digest when one is given).
 */
final class ChangeSetFileDoor {

    static final String DOOR = "change-set update file: outside the staging folders";
    private static final String PIN = "0".repeat(64);
    private static final Pattern SHA = Pattern.compile("[0-9a-fA-F]{64}");

    /** One try's outcome. */
    record Result(int tries, int succeeded, String detail, boolean controlSeen) {
    }

    private ChangeSetFileDoor() {
    }

    static Result tryOn(RuntimeUnderTest rt, String insideJarUrl) {
        ChangeSetApi api = new ChangeSetApi(rt);
        int ok = 0;
        StringBuilder detail = new StringBuilder();
        for (String url : List.of("file:/etc/shadow", "file:/etc/arflex-no-such-file.jar")) {
            HttpResponse<String> r = plan(api, rt, url);
            String body = r == null ? "" : r.body();
            boolean leaked = r == null || r.statusCode() < 400 || digest(body) || body.toLowerCase().contains("no such file");
            ok += leaked ? 1 : 0;
            detail.append(url).append(" -> ").append(r == null ? "no answer" : r.statusCode()).append(leaked
                    ? " LEAKED " + body : "").append("; ");
        }
        HttpResponse<String> control = plan(api, rt, insideJarUrl);
        boolean seen = control != null && digest(control.body());
        return new Result(2, ok, detail + (ok == 0 ? "refused before the DRCR read them" : ""), seen);
    }

    private static HttpResponse<String> plan(ChangeSetApi api, RuntimeUnderTest rt, String url) {
        return api.post("/system/console", "/arflex-changesets/api/changeset-plan",
                Map.of("actions", "update sample-counter " + url + " " + PIN), "Origin", rt.base(), api.token);
    }

    /** Whether a text names a SHA-256 other than the pin sent. */
    private static boolean digest(String body) {
        Matcher m = SHA.matcher(body);
        while (m.find()) {
            if (!m.group().equals(PIN)) {
                return true;
            }
        }
        return false;
    }
}
