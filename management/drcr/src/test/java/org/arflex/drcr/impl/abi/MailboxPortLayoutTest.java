package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/** Mailbox message and port header offsets, checked against mailbox.h and port.h. */
class MailboxPortLayoutTest {

    @Test
    void mailboxConstantsMatchTheCLayout() throws Exception {
        Map<String, Long> e = new LinkedHashMap<>();
        e.put("sizeof(struct arflex_msg)", (long) Mailbox.MSG_SIZE);
        e.put("ARFLEX_MSG_MAGIC", (long) Mailbox.MSG_MAGIC);
        e.put("ARFLEX_MQ_MAXMSG", (long) Mailbox.MQ_MAXMSG);
        e.put("offsetof(struct arflex_msg, abi_major)", (long) Mailbox.OFF_ABI_MAJOR);
        e.put("offsetof(struct arflex_msg, abi_minor)", (long) Mailbox.OFF_ABI_MINOR);
        e.put("offsetof(struct arflex_msg, seq)", (long) Mailbox.OFF_SEQ);
        e.put("offsetof(struct arflex_msg, cmd)", (long) Mailbox.OFF_CMD);
        e.put("offsetof(struct arflex_msg, flags)", (long) Mailbox.OFF_FLAGS);
        e.put("offsetof(struct arflex_msg, status)", (long) Mailbox.OFF_STATUS);
        e.put("offsetof(struct arflex_msg, payload_len)", (long) Mailbox.OFF_PAYLOAD_LEN);
        e.put("offsetof(struct arflex_msg, token)", (long) Mailbox.OFF_TOKEN);
        e.put("offsetof(struct arflex_msg, u)", (long) Mailbox.OFF_PAYLOAD);
        e.put("ARFLEX_MSG_REPLY", (long) Mailbox.FLAG_REPLY);
        e.put("offsetof(struct arflex_msg_param, index)", (long) Mailbox.PARAM_INDEX);
        e.put("offsetof(struct arflex_msg_param, type)", (long) Mailbox.PARAM_TYPE);
        e.put("offsetof(struct arflex_msg_param, value)", (long) Mailbox.PARAM_VALUE);
        e.put("offsetof(struct arflex_msg_param, applied_seq)", (long) Mailbox.PARAM_APPLIED_SEQ);
        e.put("offsetof(struct arflex_msg_param, name)", (long) Mailbox.PARAM_NAME);
        e.put("sizeof(struct arflex_msg_param)", (long) Mailbox.PARAM_SIZE);
        e.put("offsetof(struct arflex_msg_bind, port)", (long) Mailbox.BIND_PORT);
        e.put("offsetof(struct arflex_msg_bind, shm_name)", (long) Mailbox.BIND_SHM_NAME);
        e.put("sizeof(struct arflex_msg_bind)", (long) Mailbox.BIND_SIZE);
        e.put("ARFLEX_OBJ_NAME_SIZE", (long) Mailbox.OBJ_NAME_SIZE);
        e.put("offsetof(struct arflex_msg_state, state)", (long) Mailbox.STATE_STATE);
        e.put("offsetof(struct arflex_msg_state, flags)", (long) Mailbox.STATE_FLAGS);
        e.put("offsetof(struct arflex_msg_state, pid)", (long) Mailbox.STATE_PID);
        e.put("offsetof(struct arflex_msg_state, bound_inputs)", (long) Mailbox.STATE_BOUND);
        e.put("offsetof(struct arflex_msg_state, cycles)", (long) Mailbox.STATE_CYCLES);
        for (Mailbox.Cmd c : Mailbox.Cmd.values()) {
            e.put("ARFLEX_CMD_" + c.name(), (long) c.code);
        }
        check("mailbox.h", e);
    }

    @Test
    void portConstantsMatchTheCLayout() throws Exception {
        Map<String, Long> e = new LinkedHashMap<>();
        e.put("ARFLEX_PORT_MAGIC", PortSegment.MAGIC);
        e.put("ARFLEX_PORT_HDR_SIZE", (long) PortSegment.HDR_SIZE);
        e.put("sizeof(struct arflex_port_hdr)", (long) PortSegment.HDR_SIZE);
        e.put("ARFLEX_SLOT_HDR_SIZE", (long) PortSegment.SLOT_HDR_SIZE);
        e.put("sizeof(struct arflex_slot_hdr)", (long) PortSegment.SLOT_HDR_SIZE);
        e.put("ARFLEX_SLOT_ALIGN", (long) PortSegment.SLOT_ALIGN);
        e.put("ARFLEX_PORT_ABI_MAJOR", (long) PortSegment.ABI_MAJOR);
        e.put("ARFLEX_PORT_ABI_MINOR", (long) PortSegment.ABI_MINOR);
        e.put("ARFLEX_TYPE_NAME_SIZE", (long) PortSegment.TYPE_NAME_SIZE);
        e.put("offsetof(struct arflex_port_hdr, abi_major)", (long) PortSegment.OFF_ABI_MAJOR);
        e.put("offsetof(struct arflex_port_hdr, abi_minor)", (long) PortSegment.OFF_ABI_MINOR);
        e.put("offsetof(struct arflex_port_hdr, header_size)", (long) PortSegment.OFF_HEADER_SIZE);
        e.put("offsetof(struct arflex_port_hdr, size)", (long) PortSegment.OFF_SIZE);
        e.put("offsetof(struct arflex_port_hdr, method)", (long) PortSegment.OFF_METHOD);
        e.put("offsetof(struct arflex_port_hdr, elem_size)", (long) PortSegment.OFF_ELEM_SIZE);
        e.put("offsetof(struct arflex_port_hdr, depth)", (long) PortSegment.OFF_DEPTH);
        e.put("offsetof(struct arflex_port_hdr, overflow)", (long) PortSegment.OFF_OVERFLOW);
        e.put("offsetof(struct arflex_port_hdr, slot_stride)", (long) PortSegment.OFF_SLOT_STRIDE);
        e.put("offsetof(struct arflex_port_hdr, type_major)", (long) PortSegment.OFF_TYPE_MAJOR);
        e.put("offsetof(struct arflex_port_hdr, type_minor)", (long) PortSegment.OFF_TYPE_MINOR);
        e.put("offsetof(struct arflex_port_hdr, type_hash)", (long) PortSegment.OFF_TYPE_HASH);
        e.put("offsetof(struct arflex_port_hdr, type_name)", (long) PortSegment.OFF_TYPE_NAME);
        e.put("offsetof(struct arflex_port_hdr, head)", (long) PortSegment.OFF_HEAD);
        e.put("offsetof(struct arflex_port_hdr, written)", (long) PortSegment.OFF_WRITTEN);
        e.put("offsetof(struct arflex_port_hdr, writer_pid)", (long) PortSegment.OFF_WRITER_PID);
        e.put("offsetof(struct arflex_port_hdr, tail)", (long) PortSegment.OFF_TAIL);
        e.put("ARFLEX_PORT_STATE", (long) PortSegment.METHOD_STATE);
        e.put("ARFLEX_PORT_STREAM", (long) PortSegment.METHOD_STREAM);
        e.put("ARFLEX_PORT_FRAME", (long) PortSegment.METHOD_FRAME);
        e.put("ARFLEX_OVERFLOW_DROP_OLDEST", (long) PortSegment.OVERFLOW_DROP_OLDEST);
        e.put("ARFLEX_OVERFLOW_DROP_NEWEST", (long) PortSegment.OVERFLOW_DROP_NEWEST);
        e.put("ARFLEX_PORT_MAX_DEPTH", (long) PortSegment.MAX_DEPTH);
        e.put("ARFLEX_PORT_MAX_ELEM", PortSegment.MAX_ELEM);
        check("port.h", e);
    }

    @Test
    void typeHashIsFnv1a64() {
        // Reference values of FNV-1a 64: "" and "a".
        assertEquals(0xcbf29ce484222325L, PortSegment.typeHash(""));
        assertEquals(0xaf63dc4c8601ec8cL, PortSegment.typeHash("a"));
    }

    private static void check(String header, Map<String, Long> expect) throws Exception {
        Map<String, Long> c = CLayout.probe(header, List.copyOf(expect.keySet()));
        for (var en : expect.entrySet()) {
            assertEquals(c.get(en.getKey()), en.getValue(), en.getKey());
        }
    }
}
