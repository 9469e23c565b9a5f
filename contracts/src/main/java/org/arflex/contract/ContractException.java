package org.arflex.contract;

import java.util.List;
import java.util.stream.Collectors;

/**
 * A contract was refused. Carries every problem found (at least one); the message lists them,
 * one per line, as {@link Problem#toString()} formats them.
 */
public class ContractException extends Exception {
    private static final long serialVersionUID = 1L;

    private final transient List<Problem> problems;

    /** A refusal with the given problems (must not be empty). */
    public ContractException(List<Problem> problems) {
        super(format(problems));
        if (problems.isEmpty()) {
            throw new IllegalArgumentException("a ContractException needs at least one problem");
        }
        this.problems = List.copyOf(problems);
    }

    /** Every problem found, in document order where known. */
    public List<Problem> problems() {
        return problems;
    }

    private static String format(List<Problem> problems) {
        return problems.stream().map(Problem::toString).collect(Collectors.joining("\n"));
    }
}
