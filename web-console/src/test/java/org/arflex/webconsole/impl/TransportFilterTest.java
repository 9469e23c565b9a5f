package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import org.junit.jupiter.api.Test;

/** Plain HTTP only on loopback; anything else only over TLS. */
class TransportFilterTest {

    @Test
    void plainHttpOnLoopbackOnly() {
        for (String lo : new String[] {"127.0.0.1", "127.8.9.10", "::1", "0:0:0:0:0:0:0:1", "[::1]"}) {
            assertNull(TransportFilter.refusal(false, lo), lo);
        }
        for (String remote : new String[] {"192.168.1.20", "10.0.0.1", "0.0.0.0", "fe80::1%eth0", "2001:db8::1", "", null,
            "localhost", "evil.example"}) {
            String why = TransportFilter.refusal(false, remote);
            assertNotNull(why, "plain HTTP on " + remote);
            assertTrue(why.contains("HTTPS"), why);
        }
    }

    @Test
    void tlsEverywhere() {
        assertNull(TransportFilter.refusal(true, "192.168.1.20"));
        assertNull(TransportFilter.refusal(true, "127.0.0.1"));
    }
}
