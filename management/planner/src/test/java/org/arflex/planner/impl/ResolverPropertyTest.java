package org.arflex.planner.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Set;
import java.util.Optional;
import java.util.Random;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Binding;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec.Method;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.ValueSource;
import org.arflex.planner.Wire;

/** Incremental resolution equals resolution from scratch, on random change sequences. */
public class ResolverPropertyTest {

    private static final String[] TYPES = {"t.A", "t.B", "t.C", "t.D"};
    private static final String[] VERSIONS = {"1.0", "1.1", "2.0"};

    public static Contract random(Random rnd, String name, int pool) {
        C c = C.of(name).version("1." + rnd.nextInt(3) + ".0");
        if (rnd.nextInt(3) == 0) {
            c.attr("role", rnd.nextBoolean() ? "robot" : "camera");
        }
        int outs = rnd.nextInt(3);
        for (int i = 0; i < outs; i++) {
            c.out("o" + i, TYPES[rnd.nextInt(TYPES.length)], VERSIONS[rnd.nextInt(VERSIONS.length)],
                    rnd.nextInt(6) == 0 ? Method.STREAM : Method.STATE);
        }
        int ins = rnd.nextInt(3);
        for (int i = 0; i < ins; i++) {
            Optional<Binding> b = Optional.empty();
            int k = rnd.nextInt(6);
            if (k == 0) {
                b = Optional.of(Binding.explicit("c" + rnd.nextInt(pool), "o" + rnd.nextInt(2)));
            } else if (k == 1) {
                b = Optional.of(Binding.filter(rnd.nextBoolean() ? "(role=robot)" : "(!(role=camera))"));
            }
            c.in("i" + i, TYPES[rnd.nextInt(TYPES.length)], VERSIONS[rnd.nextInt(2)],
                    rnd.nextInt(6) == 0 ? Method.STREAM : Method.STATE, b, rnd.nextInt(5) == 0);
        }
        return c.build();
    }

    @ParameterizedTest
    @ValueSource(longs = {1, 2, 3, 4, 5, 6, 7, 8, 42, 1234})
    void incrementalEqualsFromScratch(long seed) {
        Random rnd = new Random(seed);
        int pool = 4 + rnd.nextInt(20);
        Resolver inc = new Resolver();
        TreeMap<String, Contract> current = new TreeMap<>();
        for (int step = 0; step < 300; step++) {
            String name = "c" + rnd.nextInt(pool);
            SortedSet<String> satBefore = new TreeSet<>(inc.satisfied());
            List<Wire> wiresBefore = inc.wires();
            ResolveDelta d;
            int op = rnd.nextInt(10);
            if (op < 2 && current.containsKey(name)) {
                d = inc.remove(name);
                current.remove(name);
            } else if (op < 4) {
                // A batch: a few puts and removes at once.
                List<Contract> puts = new ArrayList<>();
                List<String> removes = new ArrayList<>();
                TreeSet<String> used = new TreeSet<>();
                for (int k = 0; k < 3; k++) {
                    String n = "c" + rnd.nextInt(pool);
                    if (!used.add(n)) {
                        continue;
                    }
                    if (current.containsKey(n) && rnd.nextBoolean()) {
                        removes.add(n);
                    } else {
                        puts.add(random(rnd, n, pool));
                    }
                }
                d = inc.apply(puts, removes);
                removes.forEach(current::remove);
                puts.forEach(c -> current.put(c.name(), c));
            } else {
                Contract c = random(rnd, name, pool);
                d = inc.put(c);
                current.put(name, c);
            }
            Resolver fresh = new Resolver();
            fresh.apply(current.values(), List.of());
            String ctx = "seed " + seed + " step " + step;
            assertEquals(fresh.wires(), inc.wires(), ctx);
            assertEquals(fresh.satisfied(), inc.satisfied(), ctx);
            assertEquals(fresh.cycles(), inc.cycles(), ctx);
            for (String n : current.keySet()) {
                assertEquals(fresh.satisfaction(n), inc.satisfaction(n), ctx + " " + n);
            }
            // The delta describes exactly the difference.
            TreeSet<String> up = new TreeSet<>(inc.satisfied());
            up.removeAll(satBefore);
            assertEquals(up, d.becameSatisfied(), ctx);
            TreeSet<String> down = new TreeSet<>(satBefore);
            down.removeAll(inc.satisfied());
            down.retainAll(current.keySet());
            for (String a : d.added()) {
                if (!inc.isSatisfied(a)) {
                    down.add(a);
                }
            }
            assertEquals(down, d.becameUnsatisfied(), ctx);
            TreeSet<Wire> added = new TreeSet<>(inc.wires());
            added.removeAll(wiresBefore);
            assertEquals(List.copyOf(added), d.wiresAdded(), ctx);
            TreeSet<Wire> removed = new TreeSet<>(wiresBefore);
            removed.removeAll(inc.wires());
            assertEquals(List.copyOf(removed), d.wiresRemoved(), ctx);
        }
    }

    @Test
    void fromScratchDoesNotDependOnInsertionOrder() {
        Random rnd = new Random(99);
        List<Contract> cs = new ArrayList<>();
        for (int i = 0; i < 40; i++) {
            cs.add(random(rnd, "c" + i, 40));
        }
        Resolver a = new Resolver();
        cs.forEach(a::put);
        Resolver b = new Resolver();
        for (int i = cs.size() - 1; i >= 0; i--) {
            b.put(cs.get(i));
        }
        assertEquals(a.wires(), b.wires());
        assertEquals(a.satisfied(), b.satisfied());
    }

    @Test
    void aChangeFarFromTheRestTouchesLittle() {
        Resolver r = new Resolver();
        // A chain of 2,000: c0 -> c1 -> ... each with its own port type.
        for (int i = 0; i < 2000; i++) {
            C c = C.of("c" + i).out("o", "chain.T" + (i + 1));
            if (i > 0) {
                c.in("i", "chain.T" + i);
            }
            r.put(c.build());
        }
        assertEquals(2000, r.satisfied().size());
        ResolveDelta d = r.put(C.of("leaf").in("i", "chain.T2000").build());
        assertTrue(d.touched() <= 3, "touched " + d.touched());
        d = r.remove("leaf");
        assertTrue(d.touched() <= 3, "touched " + d.touched());
        // Replacing a middle link by an equivalent one touches it, not the chain below.
        d = r.put(C.of("c1000").version("1.0.1").in("i", "chain.T1000").out("o", "chain.T1001").build());
        assertTrue(d.touched() <= 4, "touched " + d.touched());
        // ... and it is the only component the change names: nothing below rewired or lost.
        assertEquals(Set.of("c1000"), d.changed(), d.toString());
        assertEquals(Set.of("c1000"), d.replaced(), d.toString());
        assertEquals(2000, r.satisfied().size());
        // Breaking the head takes the whole chain down (they all change).
        d = r.remove("c0");
        assertEquals(1999, d.becameUnsatisfied().size());
    }
}
