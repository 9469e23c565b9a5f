package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/** Every control block offset and constant the Java side relies on, checked against control.h. */
class ControlBlockLayoutTest {

    @Test
    void javaConstantsMatchTheCLayout() throws Exception {
        Map<String, Long> expect = new LinkedHashMap<>();
        expect.put("sizeof(struct arflex_ctl)", (long) ControlBlock.SIZE);
        expect.put("ARFLEX_CTL_SIZE", (long) ControlBlock.SIZE);
        expect.put("ARFLEX_CTL_MAGIC", ControlBlock.MAGIC);
        expect.put("ARFLEX_ABI_MAJOR", (long) ControlBlock.ABI_MAJOR);
        expect.put("ARFLEX_ABI_MINOR", (long) ControlBlock.ABI_MINOR);
        expect.put("offsetof(struct arflex_ctl, magic)", (long) ControlBlock.OFF_MAGIC);
        expect.put("offsetof(struct arflex_ctl, abi_major)", (long) ControlBlock.OFF_ABI_MAJOR);
        expect.put("offsetof(struct arflex_ctl, abi_minor)", (long) ControlBlock.OFF_ABI_MINOR);
        expect.put("offsetof(struct arflex_ctl, header_size)", (long) ControlBlock.OFF_HEADER_SIZE);
        expect.put("offsetof(struct arflex_ctl, size)", (long) ControlBlock.OFF_SIZE);
        expect.put("offsetof(struct arflex_ctl, state)", (long) ControlBlock.OFF_STATE);
        expect.put("offsetof(struct arflex_ctl, flags)", (long) ControlBlock.OFF_FLAGS);
        expect.put("offsetof(struct arflex_ctl, pid)", (long) ControlBlock.OFF_PID);
        expect.put("offsetof(struct arflex_ctl, exit_status)", (long) ControlBlock.OFF_EXIT_STATUS);
        expect.put("offsetof(struct arflex_ctl, runtime_hb_ns)", (long) ControlBlock.OFF_RUNTIME_HB);
        expect.put("offsetof(struct arflex_ctl, rt_hb_ns)", (long) ControlBlock.OFF_RT_HB);
        expect.put("offsetof(struct arflex_ctl, config.period_ns)", (long) ControlBlock.OFF_CFG_PERIOD);
        expect.put("offsetof(struct arflex_ctl, config.deadline_ns)", (long) ControlBlock.OFF_CFG_DEADLINE);
        expect.put("offsetof(struct arflex_ctl, config.hb_timeout_ns)", (long) ControlBlock.OFF_CFG_HB_TIMEOUT);
        expect.put("offsetof(struct arflex_ctl, config.cpu_mask)", (long) ControlBlock.OFF_CFG_CPU_MASK);
        expect.put("offsetof(struct arflex_ctl, config.priority)", (long) ControlBlock.OFF_CFG_PRIORITY);
        expect.put("offsetof(struct arflex_ctl, config.task_type)", (long) ControlBlock.OFF_CFG_TASK_TYPE);
        expect.put("offsetof(struct arflex_ctl, config.safe_mode)", (long) ControlBlock.OFF_CFG_SAFE_MODE);
        expect.put("offsetof(struct arflex_ctl, config.cfg_flags)", (long) ControlBlock.OFF_CFG_FLAGS);
        expect.put("offsetof(struct arflex_ctl, config.param_count)", (long) ControlBlock.OFF_CFG_PARAM_COUNT);
        expect.put("offsetof(struct arflex_ctl, config.orphan_hold_ns)", (long) ControlBlock.OFF_CFG_ORPHAN_HOLD);
        expect.put("offsetof(struct arflex_ctl, warnings)", (long) ControlBlock.OFF_WARNINGS);
        expect.put("ARFLEX_WARN_KINDS", (long) ControlBlock.WARN_KINDS);
        expect.put("ARFLEX_WARN_FORGED", (long) ControlBlock.WARN_FORGED);
        expect.put("offsetof(struct arflex_ctl, stats.seq)", (long) ControlBlock.OFF_STATS_SEQ);
        expect.put("offsetof(struct arflex_ctl, stats.cycles)", (long) ControlBlock.OFF_STATS_CYCLES);
        expect.put("offsetof(struct arflex_ctl, stats.overruns)", (long) ControlBlock.OFF_STATS_OVERRUNS);
        expect.put("offsetof(struct arflex_ctl, stats.missed_periods)", (long) ControlBlock.OFF_STATS_MISSED);
        expect.put("offsetof(struct arflex_ctl, stats.deadline_misses)", (long) ControlBlock.OFF_STATS_DEADLINE_MISSES);
        expect.put("offsetof(struct arflex_ctl, stats.safe_cycles)", (long) ControlBlock.OFF_STATS_SAFE_CYCLES);
        expect.put("offsetof(struct arflex_ctl, stats.last_release_ns)", (long) ControlBlock.OFF_STATS_LAST_RELEASE);
        expect.put("offsetof(struct arflex_ctl, stats.latency)", (long) ControlBlock.OFF_STATS_LATENCY);
        expect.put("offsetof(struct arflex_ctl, stats.exec)", (long) ControlBlock.OFF_STATS_EXEC);
        expect.put("sizeof(struct arflex_metric)", (long) ControlBlock.METRIC_SIZE);
        expect.put("offsetof(struct arflex_metric, count)", (long) ControlBlock.METRIC_COUNT);
        expect.put("offsetof(struct arflex_metric, min_ns)", (long) ControlBlock.METRIC_MIN);
        expect.put("offsetof(struct arflex_metric, max_ns)", (long) ControlBlock.METRIC_MAX);
        expect.put("offsetof(struct arflex_metric, sum_ns)", (long) ControlBlock.METRIC_SUM);
        expect.put("offsetof(struct arflex_metric, hist)", (long) ControlBlock.METRIC_HIST);
        expect.put("ARFLEX_HIST_BIN_NS", (long) ControlBlock.HIST_BIN_NS);
        expect.put("ARFLEX_HIST_BINS", (long) ControlBlock.HIST_BINS);
        expect.put("offsetof(struct arflex_ctl, params)", (long) ControlBlock.OFF_PARAMS);
        expect.put("offsetof(struct arflex_ctl, inputs)", (long) ControlBlock.OFF_INPUTS);
        expect.put("ARFLEX_CTL_INPUTS", (long) ControlBlock.INPUT_SLOTS);
        expect.put("sizeof(struct arflex_input_count)", 8L);
        expect.put("ARFLEX_PARAM_SLOTS", (long) ControlBlock.PARAM_SLOTS);
        expect.put("sizeof(struct arflex_param_slot)", (long) ControlBlock.SLOT_SIZE);
        expect.put("ARFLEX_NAME_SIZE", (long) ControlBlock.NAME_SIZE);
        expect.put("offsetof(struct arflex_param_slot, type)", (long) ControlBlock.SLOT_TYPE);
        expect.put("offsetof(struct arflex_param_slot, flags)", (long) ControlBlock.SLOT_FLAGS);
        expect.put("offsetof(struct arflex_param_slot, min_bits)", (long) ControlBlock.SLOT_MIN);
        expect.put("offsetof(struct arflex_param_slot, max_bits)", (long) ControlBlock.SLOT_MAX);
        expect.put("offsetof(struct arflex_param_slot, default_bits)", (long) ControlBlock.SLOT_DEFAULT);
        expect.put("offsetof(struct arflex_param_slot, req_seq)", (long) ControlBlock.SLOT_REQ_SEQ);
        expect.put("offsetof(struct arflex_param_slot, req_value)", (long) ControlBlock.SLOT_REQ_VALUE);
        expect.put("offsetof(struct arflex_param_slot, applied_seq)", (long) ControlBlock.SLOT_APPLIED_SEQ);
        expect.put("offsetof(struct arflex_param_slot, applied_value)", (long) ControlBlock.SLOT_APPLIED_VALUE);
        expect.put("offsetof(struct arflex_param_slot, applied_status)", (long) ControlBlock.SLOT_APPLIED_STATUS);
        expect.put("ARFLEX_STATE_READY", (long) ControlBlock.STATE_READY);
        expect.put("ARFLEX_STATE_RUNNING", (long) ControlBlock.STATE_RUNNING);
        expect.put("ARFLEX_STATE_EXITED", (long) ControlBlock.STATE_EXITED);
        expect.put("ARFLEX_STATE_FAILED", (long) ControlBlock.STATE_FAILED);
        expect.put("ARFLEX_FLAG_SAFE_ACTIVE", (long) ControlBlock.FLAG_SAFE_ACTIVE);
        expect.put("ARFLEX_FLAG_RESET_REQUIRED", (long) ControlBlock.FLAG_RESET_REQUIRED);
        expect.put("ARFLEX_FLAG_SUPERVISOR_LOST", (long) ControlBlock.FLAG_SUPERVISOR_LOST);
        expect.put("ARFLEX_FLAG_READOPT", (long) ControlBlock.FLAG_READOPT);
        expect.put("ARFLEX_CFG_MOVES_HARDWARE", (long) ControlBlock.CFG_MOVES_HARDWARE);
        expect.put("ARFLEX_CFG_NO_MLOCK", (long) ControlBlock.CFG_NO_MLOCK);
        expect.put("ARFLEX_CFG_NO_DMA_LATENCY", (long) ControlBlock.CFG_NO_DMA_LATENCY);
        expect.put("ARFLEX_CFG_SUPERVISOR_PIPE", (long) ControlBlock.CFG_SUPERVISOR_PIPE);
        expect.put("ARFLEX_PARAM_BOOL", (long) ControlBlock.PARAM_BOOL);
        expect.put("ARFLEX_PARAM_INT64", (long) ControlBlock.PARAM_INT64);
        expect.put("ARFLEX_PARAM_DOUBLE", (long) ControlBlock.PARAM_DOUBLE);
        expect.put("ARFLEX_PARAM_MUTABLE", (long) ControlBlock.PARAM_MUTABLE);
        Map<String, Long> c = CLayout.probe("control.h", List.copyOf(expect.keySet()));
        for (var e : expect.entrySet()) {
            assertEquals(c.get(e.getKey()), e.getValue(), e.getKey());
        }
    }
}
