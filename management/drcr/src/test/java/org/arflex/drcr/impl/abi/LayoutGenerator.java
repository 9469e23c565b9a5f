package org.arflex.drcr.impl.abi;

import java.io.IOException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

/**
 * Generates {@link Layout} from rt-core's headers: the C compiler prints every offsetof/sizeof/constant listed in
 * {@link #SPEC} (CLayout), so no number is written by hand. The list names only C members and
 * constants; a misspelt one fails to compile. LayoutTest checks that the checked-in files are
 * what this gives now, and writes them with {@code -Darflex.layout.write=true} (DECISIONS.md
 * D22).
 *
 * <p>Naming, mechanical: {@code OFF_<S>_<M>} is {@code offsetof(struct arflex_<s>, <m>)} (a
 * nested member's {@code .} becomes {@code _}), {@code SIZEOF_<S>} is
 * {@code sizeof(struct arflex_<s>)}, any other name {@code N} is {@code ARFLEX_<N>}.
 */
final class LayoutGenerator {

    /** System property of LayoutTest that writes the files instead of checking them. */
    static final String WRITE = "arflex.layout.write";
    static final String COMMAND = "mvn -B -q -o -Darflex.native.skip=true -pl management/drcr test -Dtest=LayoutTest "
            + "-D" + WRITE + "=true";
    /** Relative to the drcr module, where surefire runs. */
    static final Path JAVA = Path.of("src/main/java/org/arflex/drcr/impl/abi/Layout.java");

    /**
     * Per header: {@code const} lines (names without ARFLEX_), {@code struct} lines (struct
     * name without arflex_, then its members).
     */
    static final String SPEC = """
            control.h
            const ABI_MAJOR ABI_MINOR CTL_MAGIC CTL_SIZE ID_MAX NAME_SIZE OBJ_NAME_SIZE PARAM_SLOTS
            const HIST_BIN_NS HIST_BINS WARN_KINDS CTL_INPUTS
            const STATE_CREATED STATE_CONFIGURING STATE_READY STATE_RUNNING STATE_STOPPING STATE_EXITED STATE_FAILED
            const FLAG_SCHED_FIFO FLAG_MLOCKALL FLAG_SAFE_ACTIVE FLAG_RESET_REQUIRED FLAG_AFFINITY FLAG_DMA_LATENCY
            const FLAG_SUPERVISOR_LOST FLAG_READOPT
            const CFG_MOVES_HARDWARE CFG_NO_MLOCK CFG_NO_DMA_LATENCY CFG_SUPERVISOR_PIPE
            const SAFE_HOLD SAFE_ZERO TASK_PERIODIC TASK_SPORADIC TASK_SERVICE
            const WARN_SCHED WARN_AFFINITY WARN_MLOCK WARN_DMA_LATENCY WARN_OVERRUN WARN_DEADLINE WARN_SLEEP
            const WARN_UPDATE WARN_PARAM WARN_INPUT WARN_SAFE WARN_FORGED
            const HOLD_NONE HOLD_SAFETY_INPUT HOLD_AWAIT_COMMAND HOLD_REFERENCE HOLD_REF_NOT_MET HOLD_REF_INVALID
            const PARAM_UNUSED PARAM_BOOL PARAM_INT64 PARAM_DOUBLE PARAM_MUTABLE
            struct ctl magic abi_major abi_minor header_size size state flags pid exit_status runtime_hb_ns rt_hb_ns hold
            struct ctl config config.period_ns config.deadline_ns config.hb_timeout_ns config.cpu_mask config.priority
            struct ctl config.task_type config.safe_mode config.cfg_flags config.param_count config.orphan_hold_ns
            struct ctl warnings stats stats.seq stats.cycles stats.overruns stats.missed_periods stats.deadline_misses
            struct ctl stats.update_errors stats.safe_cycles stats.last_release_ns stats.latency stats.exec params inputs
            struct metric count min_ns max_ns sum_ns sum_absdev_ns hist
            struct param_slot name type flags min_bits max_bits default_bits req_seq req_value applied_seq
            struct param_slot applied_value applied_status
            struct input_count name_hash rejects
            port.h
            const PORT_MAGIC PORT_HDR_SIZE SLOT_HDR_SIZE TYPE_NAME_SIZE STATE_READ_RETRIES PORT_MAX_ELEM PORT_MAX_DEPTH
            const PORT_ABI_MAJOR PORT_ABI_MINOR SLOT_ALIGN SLOT_INLINE_MAX
            const PORT_STATE PORT_STREAM PORT_FRAME OVERFLOW_NONE OVERFLOW_DROP_OLDEST OVERFLOW_DROP_NEWEST
            struct port_hdr magic abi_major abi_minor header_size size method elem_size depth overflow slot_stride
            struct port_hdr type_major type_minor type_hash type_name head written dropped writer_pid tail delivered lost
            struct port_hdr reader_pid
            struct slot_hdr seq stamp_ns length
            mailbox.h
            const MSG_MAGIC MSG_SIZE MQ_MAXMSG MSG_PAYLOAD MSG_REPLY
            const CMD_START CMD_STOP CMD_SET_PARAM CMD_GET_PARAM CMD_BIND CMD_UNBIND CMD_GET_STATE CMD_GET_STATS
            const CMD_RESET CMD_SHUTDOWN CMD_PING CMD_ADOPT CMD_READOPT
            struct msg magic abi_major abi_minor seq cmd flags status payload_len token u
            struct msg_param index type value applied_seq name
            struct msg_bind port shm_name
            struct msg_state state flags pid bound_inputs cycles
            """;

    /** One generated constant: its name, the C expression and the header it is listed under. */
    record Entry(String header, String name, String expr) {
    }

    private LayoutGenerator() {
    }

    static List<Entry> entries() {
        List<Entry> out = new ArrayList<>();
        Map<String, String> seen = new LinkedHashMap<>();
        String header = null;
        String lastStruct = null;
        for (String line : SPEC.strip().split("\n")) {
            String[] w = line.strip().split("\\s+");
            if (w.length == 1 && w[0].endsWith(".h")) {
                header = w[0];
                continue;
            }
            List<String[]> add = new ArrayList<>();
            if (w[0].equals("const")) {
                for (int i = 1; i < w.length; i++) {
                    add.add(new String[] {w[i], "ARFLEX_" + w[i]});
                }
            } else if (w[0].equals("struct")) {
                String s = w[1];
                if (!s.equals(lastStruct)) {
                    add.add(new String[] {"SIZEOF_" + upper(s), "sizeof(struct arflex_" + s + ")"});
                    lastStruct = s;
                }
                for (int i = 2; i < w.length; i++) {
                    add.add(new String[] {"OFF_" + upper(s) + "_" + upper(w[i]),
                        "offsetof(struct arflex_" + s + ", " + w[i] + ")"});
                }
            } else {
                throw new IllegalStateException("LayoutGenerator.SPEC: cannot read '" + line + "'");
            }
            for (String[] a : add) {
                String before = seen.put(a[0], a[1]);
                if (before != null) {
                    throw new IllegalStateException("LayoutGenerator.SPEC: " + a[0] + " for both " + before + " and " + a[1]);
                }
                out.add(new Entry(header, a[0], a[1]));
            }
        }
        return out;
    }

    private static String upper(String member) {
        return member.replace('.', '_').toUpperCase(java.util.Locale.ROOT);
    }

    /** The generated files' contents, by path relative to the drcr module. */
    static Map<Path, String> generate() throws IOException, InterruptedException {
        List<Entry> entries = entries();
        List<String> headers = entries.stream().map(Entry::header).distinct().toList();
        Map<String, Long> values = CLayout.probe(headers, entries.stream().map(Entry::expr).toList());
        StringBuilder java = new StringBuilder();
        java.append("// Generated by LayoutGenerator (management/drcr/src/test/java/org/arflex/drcr/impl/abi) from\n")
                .append("// rt-core/include/arflex/").append(String.join(", ", headers))
                .append(".\n// Do not edit: regenerate from the repository root with\n//   ").append(COMMAND).append("\n")
                .append("package org.arflex.drcr.impl.abi;\n\n")
                .append("/**\n")
                .append(" * The byte layout of rt-core's shared objects and messages as the C compiler lays out its\n")
                .append(" * headers (x86-64, little endian): the one Java source of these numbers (DECISIONS.md D22).\n")
                .append(" * {@code OFF_<S>_<M>} is {@code offsetof(struct arflex_<s>, <m>)} (a nested member's {@code .}\n")
                .append(" * as {@code _}), {@code SIZEOF_<S>} is {@code sizeof(struct arflex_<s>)}, any other name\n")
                .append(" * {@code N} is the value of {@code ARFLEX_<N>}. LayoutTest fails when this file is not what\n")
                .append(" * the headers give.\n")
                .append(" */\n")
                .append("public final class Layout {\n\n")
                .append("    private Layout() {\n    }\n");
        String header = null;
        String group = null;
        for (Entry e : entries) {
            Long v = values.get(e.expr());
            if (v == null) {
                throw new IOException("the C probe printed no value for " + e.expr());
            }
            String g = e.expr().startsWith("ARFLEX_") ? "" : e.expr().replaceAll("^\\w+\\(struct (\\w+).*", "$1");
            if (!e.header().equals(header)) {
                java.append("\n    // ---- ").append(e.header()).append('\n');
                header = e.header();
                group = null;
            }
            if (!g.equals(group)) {
                if (!g.isEmpty()) {
                    java.append("\n    // struct ").append(g).append('\n');
                }
                group = g;
            }
            boolean isInt = v >= Integer.MIN_VALUE && v <= Integer.MAX_VALUE;
            String literal = e.name().endsWith("MAGIC") && !e.name().startsWith("OFF_") ? "0x" + Long.toHexString(v) : Long.toString(v);
            java.append("    public static final ").append(isInt ? "int " : "long ").append(e.name()).append(" = ")
                    .append(literal).append(isInt ? "" : "L").append(";\n");
        }
        java.append("}\n");
        return Map.of(JAVA, java.toString());
    }
}
