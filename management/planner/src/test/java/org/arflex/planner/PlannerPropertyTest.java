package org.arflex.planner;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Random;
import org.arflex.contract.Contract;
import org.arflex.planner.impl.ResolverPropertyTest;
import org.arflex.contract.Resources;
import org.arflex.contract.Timing;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.ValueSource;

/**
 * On random sequences of installs, updates, uninstalls, capacity changes and blocks: the dry run
 * leaves the state untouched, the real run returns the very same plan, the state it leaves needs
 * no further action, and no Active component reads from a component that is not Active.
 */
class PlannerPropertyTest {

    @ParameterizedTest
    @ValueSource(longs = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10})
    void dryRunEqualsRealRunAndConverges(long seed) {
        Random rnd = new Random(seed);
        int pool = 3 + rnd.nextInt(15);
        Planner p = new Planner(Capacities.of(2, 0.9, 64L << 20, 1000));
        for (int step = 0; step < 60; step++) {
            String name = "c" + rnd.nextInt(pool);
            boolean has = p.contract(name).isPresent();
            int op = rnd.nextInt(10);
            Change ch;
            if (op < 2 && has) {
                ch = Change.uninstall(name);
            } else if (op < 3) {
                ch = Change.capacities(Capacities.of(1 + rnd.nextInt(3), 0.5 + rnd.nextInt(5) / 10.0,
                        (8L + rnd.nextInt(64)) << 20, 1000));
            } else if (op < 4 && has) {
                ch = p.blocked().containsKey(name) ? Change.unblock(name) : Change.block(name, "test");
            } else {
                Contract c = ResolverPropertyTest.random(rnd, name, pool);
                c = new Contract(c.name(), c.version(), "", "x", c.taskType(), false, c.attributes(), c.ports(),
                        List.of(), new Timing(10_000_000L, 10_000_000L, (1 + rnd.nextInt(40)) * 100_000L,
                                1 + rnd.nextInt(90), List.of()),
                        new Resources((1L + rnd.nextInt(16)) << 20, 0), rnd.nextInt(5), c.fault(), c.update(), "t");
                ch = Change.put(c);
            }
            String ctx = "seed " + seed + " step " + step + " " + ch;
            String before = p.current().toText();
            Plan dry = p.plan(ch);
            assertEquals(before, p.current().toText(), ctx);
            Plan real = p.apply(ch);
            assertEquals(dry.toText(), real.toText(), ctx);
            assertTrue(p.current().isEmpty(), ctx + "\n" + p.current().toText());
            assertEquals(real.activeAfter(), p.active(), ctx);
            for (String n : p.active()) {
                for (Wire w : real.wiringOf(n)) {
                    assertTrue(p.active().contains(w.provider()), ctx + ": " + w);
                }
                assertTrue(p.satisfaction(n).satisfied(), ctx + ": " + n);
            }
        }
    }
}
