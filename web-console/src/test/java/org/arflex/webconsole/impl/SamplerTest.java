package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Map;
import java.util.function.BooleanSupplier;
import org.junit.jupiter.api.Test;

/** The shared sampler: frames keep their order across restarts of its thread. */
class SamplerTest {

    private static void await(String what, long timeoutMs, BooleanSupplier c) throws InterruptedException {
        long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
        while (!c.getAsBoolean()) {
            assertTrue(System.nanoTime() < deadline, "timed out waiting for " + what);
            Thread.sleep(10);
        }
    }

    @Test
    void aStreamAfterTheThreadRestartedGetsTheNextFrameAtOnce() throws Exception {
        Sampler s = new Sampler(name -> "a".equals(name) ? Map.of("state", "ACTIVE") : null, (n, p) -> Map.of());
        try {
            Sampler.Key a = new Sampler.Key("a", List.of());
            s.subscribe(a);
            // Run long enough for the frame numbers to be well past what a new thread would start at.
            long seq = 0;
            Sampler.Frame f = null;
            while (seq < 12) {
                f = s.awaitAfter(seq, 1000);
                assertNotNull(f, "a frame every period");
                seq = f.seq();
            }
            assertTrue(f.sampled().contains(a));
            assertEquals("ACTIVE", f.byKey().get(a).get("state"));
            s.unsubscribe(a);
            await("the sampler thread to end without subscribers", 2000, () -> !s.running());

            // A new stream (the page opened again) saw the last frame; the restarted thread's
            // first frame is the next one, not frame 1 (which left the stream waiting ~seq periods).
            Sampler.Key gone = new Sampler.Key("b", List.of());
            s.subscribe(gone);
            s.subscribe(a);
            Sampler.Frame next = s.awaitAfter(seq, 1000);
            assertNotNull(next, "the restarted sampler's frames reach a stream that saw frame " + seq);
            assertTrue(next.seq() > seq, next.seq() + " > " + seq);
            // A sampled subscription without a sample is gone; both were sampled.
            await("a frame read for both subscriptions", 2000, () -> {
                try {
                    Sampler.Frame x = s.awaitAfter(0, 1000);
                    return x != null && x.sampled().contains(a) && x.sampled().contains(gone);
                } catch (InterruptedException e) {
                    throw new IllegalStateException(e);
                }
            });
            Sampler.Frame both = s.awaitAfter(0, 1000);
            assertNotNull(both.byKey().get(a));
            assertFalse(both.byKey().containsKey(gone), "b has no sample: the stream says gone");
        } finally {
            s.close();
        }
    }
}
