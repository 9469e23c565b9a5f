package org.arflex.planner;

import java.util.Collection;
import java.util.List;
import java.util.Optional;
import java.util.Set;
import java.util.SortedSet;
import org.arflex.contract.Contract;

/**
 * Incremental resolver: matches every input of the installed contracts to at most one output
 * and computes which components are satisfied.
 *
 * <p><b>Matching.</b> An output {@code p.o} can feed input {@code c.i} when the port type names
 * are equal, {@code o}'s type version {@link org.arflex.contract.TypeVersion#canFeed can feed}
 * {@code i}'s, the methods are equal and the binding rule of {@code i} accepts {@code p.o}: an
 * explicit {@code component.port} accepts exactly that port (it may name the consumer itself: a
 * self-binding); a filter (RFC 1960) accepts outputs of providers whose
 * {@link Contract#attributes()} match it; no rule accepts any provider. Without an explicit rule
 * a component never feeds itself. Exactly one candidate gives a wire; none is a missing provider,
 * several are an ambiguity, both reported by name.
 *
 * <p><b>Satisfaction</b> is the greatest fixpoint of: a component is satisfied when every
 * required (non-optional) input has a wire and the wire's provider is satisfied. Cycles through
 * required inputs are therefore legal (control loops): a cycle is satisfied as a whole when
 * nothing it needs from outside is missing. Optional inputs are wired when they can be but never
 * block.
 *
 * <p><b>Incrementality.</b> Outputs are indexed by port type and inputs by port type, and every
 * provider knows its dependents: a change re-matches only the inputs of the changed port types
 * and re-evaluates satisfaction only downstream of what changed ({@link ResolveDelta#touched()}
 * counts them). Results are equal to a resolve from scratch of the same contracts.
 *
 * <p>Not thread-safe.
 */
public final class Resolver {

    /** An empty resolver. */
    public Resolver() {
        throw new UnsupportedOperationException("API draft");
    }

    /**
     * Adds a contract, or replaces the installed contract of the same name.
     *
     * @return what changed
     */
    public ResolveDelta put(Contract contract) {
        throw new UnsupportedOperationException("API draft");
    }

    /**
     * Removes a component.
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public ResolveDelta remove(String name) {
        throw new UnsupportedOperationException("API draft");
    }

    /**
     * Applies several puts and removes as one change with one delta (removes first).
     *
     * @throws IllegalArgumentException naming the first name removed that is not installed;
     *                                  nothing is changed then
     */
    public ResolveDelta apply(Collection<Contract> puts, Collection<String> removes) {
        throw new UnsupportedOperationException("API draft");
    }

    /** The installed contract of that name. */
    public Optional<Contract> contract(String name) {
        throw new UnsupportedOperationException("API draft");
    }

    /** All installed contracts, by name. */
    public List<Contract> contracts() {
        throw new UnsupportedOperationException("API draft");
    }

    /** Installed component names, sorted. */
    public SortedSet<String> names() {
        throw new UnsupportedOperationException("API draft");
    }

    /** Number of installed components. */
    public int size() {
        throw new UnsupportedOperationException("API draft");
    }

    /** True when a component of that name is installed. */
    public boolean contains(String name) {
        throw new UnsupportedOperationException("API draft");
    }

    /** Every wire, sorted (whether or not its ends are satisfied). */
    public List<Wire> wires() {
        throw new UnsupportedOperationException("API draft");
    }

    /** The wires into the inputs of {@code consumer}, sorted; empty when not installed. */
    public List<Wire> inputWires(String consumer) {
        throw new UnsupportedOperationException("API draft");
    }

    /** The wires out of the outputs of {@code provider}, sorted; empty when not installed. */
    public List<Wire> outputWires(String provider) {
        throw new UnsupportedOperationException("API draft");
    }

    /** Components with a wire (required or optional) from {@code provider}, sorted. */
    public SortedSet<String> dependents(String provider) {
        throw new UnsupportedOperationException("API draft");
    }

    /** True when the component is installed and satisfied. */
    public boolean isSatisfied(String name) {
        throw new UnsupportedOperationException("API draft");
    }

    /** Satisfied component names, sorted. */
    public SortedSet<String> satisfied() {
        throw new UnsupportedOperationException("API draft");
    }

    /**
     * Satisfaction of one component with its reasons and notes.
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public Satisfaction satisfaction(String name) {
        throw new UnsupportedOperationException("API draft");
    }

    /**
     * Cycles through wires of required inputs: each strongly connected component of more than
     * one member, or a single member bound to itself, as its names sorted; the list sorted by
     * first name.
     */
    public List<List<String>> cycles() {
        throw new UnsupportedOperationException("API draft");
    }

    /** True when the input of that component is optional (false when unknown). */
    public boolean isOptionalInput(String consumer, String inPort) {
        throw new UnsupportedOperationException("API draft");
    }

    /** Names of the components {@code name} requires (providers of its required inputs). */
    public Set<String> requiredProviders(String name) {
        throw new UnsupportedOperationException("API draft");
    }
}
