package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.util.List;
import org.junit.jupiter.api.Test;

/** The config words as the RT half reads them (ABI 1.1: orphan hold, supervisor pipe). */
class ControlBlockConfigTest {

    private final String name = "/arflex.jt" + ProcessHandle.current().pid() + ".cfg.ctl";

    @Test
    void orphanHoldAndSupervisorPipeAreEncodedWhereTheCSideReadsThem() throws Exception {
        ControlBlock.Config cfg = new ControlBlock.Config(1_000_000, 500_000, 100_000_000L, 2, 80, 0, 1,
                ControlBlock.CFG_MOVES_HARDWARE, 750_000_000L).withSupervisorPipe();
        try (ControlBlock cb = ControlBlock.create(name, cfg, List.of())) {
            ShmSegment s = cb.segment();
            assertEquals(ControlBlock.ABI_MINOR, s.buffer().getShort(ControlBlock.OFF_ABI_MINOR));
            org.junit.jupiter.api.Assertions.assertTrue(ControlBlock.ABI_MINOR >= 1, "orphan_hold_ns is an ABI 1.1 field");
            assertEquals(750_000_000L, s.getLong(ControlBlock.OFF_CFG_ORPHAN_HOLD));
            assertEquals(120, ControlBlock.OFF_CFG_ORPHAN_HOLD);
            assertEquals(ControlBlock.CFG_MOVES_HARDWARE | ControlBlock.CFG_SUPERVISOR_PIPE,
                    s.getInt(ControlBlock.OFF_CFG_FLAGS));
            assertEquals(8, ControlBlock.CFG_SUPERVISOR_PIPE);
            assertEquals(1_000_000, s.getLong(ControlBlock.OFF_CFG_PERIOD));
            assertEquals(100_000_000L, s.getLong(ControlBlock.OFF_CFG_HB_TIMEOUT));
            assertEquals(0, s.getInt(ControlBlock.OFF_CFG_PARAM_COUNT));
            assertEquals(0, s.getInt(116), "the word before orphan_hold_ns stays reserved");
            assertEquals(cfg, cb.config());
            // the RT half sets SUPERVISOR_LOST (bit 6) when its stdin reaches EOF
            assertEquals(64, ControlBlock.FLAG_SUPERVISOR_LOST);
            s.setIntRelease(ControlBlock.OFF_FLAGS, ControlBlock.FLAG_SUPERVISOR_LOST | ControlBlock.FLAG_SAFE_ACTIVE);
            assertEquals(ControlBlock.FLAG_SUPERVISOR_LOST, cb.flags() & ControlBlock.FLAG_SUPERVISOR_LOST);
        }
    }

    @Test
    void theShortConstructorUsesTheContractsDefaultHoldAndNoPipe() {
        ControlBlock.Config cfg = new ControlBlock.Config(1_000_000, 0, 0, 0, 0, 0, 0, 0);
        assertEquals(2_000_000_000L, cfg.orphanHoldNs());
        assertEquals(ControlBlock.DEFAULT_ORPHAN_HOLD_NS, cfg.orphanHoldNs());
        assertEquals(0, cfg.cfgFlags() & ControlBlock.CFG_SUPERVISOR_PIPE);
        assertEquals(ControlBlock.CFG_SUPERVISOR_PIPE, cfg.withSupervisorPipe().cfgFlags());
        assertEquals(cfg.orphanHoldNs(), cfg.withSupervisorPipe().orphanHoldNs());
    }
}
