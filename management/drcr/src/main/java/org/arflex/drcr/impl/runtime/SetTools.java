package org.arflex.drcr.impl.runtime;

import java.util.function.Consumer;

/** What the parts of a change set's apply work with: the cell and its helpers (D35). */
record SetTools(Cell cell, Stops stops, Segments segments, Starter starter, PlanExecutor plans, Failures failures,
                Consumer<String> log) {
}
