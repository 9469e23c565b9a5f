package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/** Rejected values per input (ABI 1.2), as an RT half writes them into its control block. */
class ControlBlockInputsTest {

    private final String name = "/arflex.jt" + ProcessHandle.current().pid() + ".inputs.ctl";

    @Test
    void countsAreFoundByTheInputsNameWhateverItsSlot() throws Exception {
        try (ControlBlock cb = ControlBlock.create(name, new ControlBlock.Config(1_000_000, 0, 0, 0, 0, 0, 0, 0), List.of())) {
            ShmSegment s = cb.segment();
            assertEquals(Map.of(), cb.inputRejects(List.of("joint_ref", "safety")), "nothing declared yet");
            // the RT half declared safety first, joint_ref second (not the contract's order)
            s.setIntRelease(ControlBlock.OFF_INPUTS, ControlBlock.inputHash("safety"));
            s.setIntRelease(ControlBlock.OFF_INPUTS + 8, ControlBlock.inputHash("joint_ref"));
            s.setIntRelease(ControlBlock.OFF_INPUTS + 8 + 4, 3);
            s.setIntRelease(ControlBlock.OFF_INPUTS + 8 * 15, ControlBlock.inputHash("last"));
            s.setIntRelease(ControlBlock.OFF_INPUTS + 8 * 15 + 4, -1); // u32 max: not negative
            assertEquals(Map.of("joint_ref", 3L, "safety", 0L, "last", 4294967295L),
                    cb.inputRejects(List.of("joint_ref", "safety", "last", "undeclared")));
        }
    }

    @Test
    void theNameHashIsTheLowWordOfFnv1a64() {
        // FNV-1a 64 of "a" is 0xaf63dc4c8601ec8c (the C side: arflex_port_type_hash)
        assertEquals(0x8601ec8c, ControlBlock.inputHash("a"));
    }
}
