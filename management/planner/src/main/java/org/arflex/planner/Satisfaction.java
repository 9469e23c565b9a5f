package org.arflex.planner;

import java.util.List;

/**
 * Whether a component's inputs are all served by satisfied providers, and why not.
 *
 * @param component the component name
 * @param satisfied true when every required input has exactly one matching provider and every
 *                  such provider is itself satisfied (greatest fixpoint: members of a cycle of
 *                  required inputs are satisfied together when nothing outside the cycle is
 *                  missing)
 * @param reasons   empty when satisfied; otherwise one human sentence per problem, naming the
 *                  input, the component and the providers, for example
 *                  {@code input 'x' of 'sample-scaler': no provider of arflex.Sample 1.x (state)},
 *                  {@code input 'x' of 'a': ambiguous: b.y, c.z} or
 *                  {@code input 'x' of 'a': provider 'b' is Unsatisfied}
 * @param notes     informative remarks that do not block, for example membership of a cycle
 *                  ({@code in cycle: robot -> vision -> correction -> robot}) or an optional
 *                  input without provider
 */
public record Satisfaction(String component, boolean satisfied, List<String> reasons, List<String> notes) {

    public Satisfaction {
        reasons = List.copyOf(reasons);
        notes = List.copyOf(notes);
    }

    /** The reasons joined with {@code "; "}, or {@code "satisfied"}. */
    public String summary() {
        return satisfied ? "satisfied" : String.join("; ", reasons);
    }
}
