package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.Dictionary;
import java.util.Hashtable;
import java.util.List;
import java.util.Properties;
import org.junit.jupiter.api.Test;

/** Markup in a human-readable manifest header keeps the bundle from resolving. */
class MarkupGateTest {
    private static Dictionary<String, String> headers(String... kv) {
        Hashtable<String, String> h = new Hashtable<>();
        h.put("Bundle-ManifestVersion", "2");
        h.put("Bundle-SymbolicName", "org.example.ok");
        h.put("Bundle-Version", "1.0.0");
        for (int i = 0; i < kv.length; i += 2) {
            h.put(kv[i], kv[i + 1]);
        }
        return h;
    }

    @Test
    void plainHeadersPass() {
        assertNull(MarkupGate.markup(headers("Bundle-Name", "Sample counter", "Bundle-Vendor", "ARFLEX",
                "Bundle-Description", "Counts; the 'x' port says \"how many\"", "Bundle-DocURL", "https://example.org/doc",
                "Bundle-License", "Apache-2.0;link=\"https://www.apache.org/licenses/LICENSE-2.0.txt\"",
                // filters elsewhere may compare: only the human-readable headers are checked
                "Require-Capability", "osgi.ee;filter:=\"(&(osgi.ee=JavaSE)(version>=17))\""), List.of()));
    }

    @Test
    void markupInAnyShownHeaderIsRefusedNamingIt() {
        for (String h : MarkupGate.HEADERS) {
            String why = MarkupGate.markup(headers(h, "x<img src=x onerror=alert(1)>"), List.of());
            assertTrue(why != null && why.contains(h) && why.contains("<img"), h + ": " + why);
        }
        assertTrue(MarkupGate.markup(headers("Bundle-Vendor", "a > b"), List.of()).contains("Bundle-Vendor"));
    }

    @Test
    void markupInALocalisationIsRefusedToo() {
        Properties de = new Properties();
        de.setProperty("vendor", "Firma <img src=x onerror=alert(1)>");
        Properties en = new Properties();
        en.setProperty("vendor", "Company");
        String why = MarkupGate.markup(headers("Bundle-Vendor", "%vendor"), List.of(en, de));
        assertTrue(why != null && why.contains("%vendor") && why.contains("Firma <img"), why);
        assertNull(MarkupGate.markup(headers("Bundle-Vendor", "%vendor"), List.of(en)));
    }

    @Test
    void longValuesAreCutInTheReason() {
        String why = MarkupGate.markup(headers("Bundle-Description", "<" + "x".repeat(1000)), List.of());
        assertTrue(why.length() < 300, why);
        assertEquals(-1, why.indexOf('\n'));
    }
}
