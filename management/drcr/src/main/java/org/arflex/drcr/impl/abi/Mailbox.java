package org.arflex.drcr.impl.abi;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.util.Optional;

/**
 * The manager side of rt-core/include/arflex/mailbox.h: the queue pair
 * {@code /arflex.<rid>.<inst>.cmd} (requests, manager to RT) and {@code .rsp} (replies), each
 * message one 512-byte struct arflex_msg. A request is sent ({@link #send}) and its reply awaited
 * ({@link #await}) apart, so a caller may stop waiting and another thread wait for the rest
 * (D39: the actor does not wait on a half that does not answer at once). Several requests may
 * be outstanding; whoever reads the reply queue keeps the replies of the others until they are
 * taken, and a reply to a request nobody awaits any more (it timed out) is discarded.
 *
 * <p>Every request carries the instance's token (ABI.md 5, DECISIONS.md D13), which the RT half
 * got as the first 8 bytes on its supervisor pipe; it ignores requests with another token, and
 * a reply with another token is not from it and is discarded here.
 *
 * <p>The offsets and codes below come from {@link Layout}, generated from the header
 * (DECISIONS.md D22).
 */
public final class Mailbox implements AutoCloseable {

    public static final int MSG_MAGIC = Layout.MSG_MAGIC; // "AFMS"
    public static final int MSG_SIZE = Layout.MSG_SIZE;
    public static final int MQ_MAXMSG = Layout.MQ_MAXMSG;
    public static final int OFF_MAGIC = Layout.OFF_MSG_MAGIC;
    public static final int OFF_ABI_MAJOR = Layout.OFF_MSG_ABI_MAJOR;
    public static final int OFF_ABI_MINOR = Layout.OFF_MSG_ABI_MINOR;
    public static final int OFF_SEQ = Layout.OFF_MSG_SEQ;
    public static final int OFF_CMD = Layout.OFF_MSG_CMD;
    public static final int OFF_FLAGS = Layout.OFF_MSG_FLAGS;
    public static final int OFF_STATUS = Layout.OFF_MSG_STATUS;
    public static final int OFF_PAYLOAD_LEN = Layout.OFF_MSG_PAYLOAD_LEN;
    public static final int OFF_TOKEN = Layout.OFF_MSG_TOKEN;
    public static final int OFF_PAYLOAD = Layout.OFF_MSG_U;
    public static final int FLAG_REPLY = Layout.MSG_REPLY;
    // struct arflex_msg_param, relative to the payload
    public static final int PARAM_INDEX = Layout.OFF_MSG_PARAM_INDEX;
    public static final int PARAM_TYPE = Layout.OFF_MSG_PARAM_TYPE;
    public static final int PARAM_VALUE = Layout.OFF_MSG_PARAM_VALUE;
    public static final int PARAM_APPLIED_SEQ = Layout.OFF_MSG_PARAM_APPLIED_SEQ;
    public static final int PARAM_NAME = Layout.OFF_MSG_PARAM_NAME;
    public static final int PARAM_SIZE = Layout.SIZEOF_MSG_PARAM;
    // struct arflex_msg_bind
    public static final int BIND_PORT = Layout.OFF_MSG_BIND_PORT;
    public static final int BIND_SHM_NAME = Layout.OFF_MSG_BIND_SHM_NAME;
    public static final int BIND_SIZE = Layout.SIZEOF_MSG_BIND;
    public static final int OBJ_NAME_SIZE = Layout.OBJ_NAME_SIZE;
    // struct arflex_msg_state
    public static final int STATE_STATE = Layout.OFF_MSG_STATE_STATE;
    public static final int STATE_FLAGS = Layout.OFF_MSG_STATE_FLAGS;
    public static final int STATE_PID = Layout.OFF_MSG_STATE_PID;
    public static final int STATE_BOUND = Layout.OFF_MSG_STATE_BOUND_INPUTS;
    public static final int STATE_CYCLES = Layout.OFF_MSG_STATE_CYCLES;

    /** enum arflex_cmd. */
    public enum Cmd {
        START(Layout.CMD_START), STOP(Layout.CMD_STOP), SET_PARAM(Layout.CMD_SET_PARAM),
        GET_PARAM(Layout.CMD_GET_PARAM), BIND(Layout.CMD_BIND), UNBIND(Layout.CMD_UNBIND),
        GET_STATE(Layout.CMD_GET_STATE), GET_STATS(Layout.CMD_GET_STATS), RESET(Layout.CMD_RESET),
        SHUTDOWN(Layout.CMD_SHUTDOWN), PING(Layout.CMD_PING), ADOPT(Layout.CMD_ADOPT),
        READOPT(Layout.CMD_READOPT);

        public final int code;

        Cmd(int code) {
            this.code = code;
        }
    }

    /** A reply: status 0 or -errno from the RT side, and the whole message for payload reads. */
    public record Reply(int status, ByteBuffer msg) {
        public long payloadLong(int off) {
            return msg.getLong(OFF_PAYLOAD + off);
        }

        public int payloadInt(int off) {
            return msg.getInt(OFF_PAYLOAD + off);
        }
    }

    private final MessageQueue cmd;
    private final MessageQueue rsp;
    private final long token;
    private int seq;
    /** Requests whose reply is still awaited, and replies read for them by another waiter. */
    private final java.util.Set<Integer> awaited = new java.util.HashSet<>();
    private final java.util.Map<Integer, Reply> arrived = new java.util.HashMap<>();
    /** One reader of the reply queue at a time, for at most {@link #PEER_CHECK_MS} per turn. */
    private final java.util.concurrent.locks.ReentrantLock reader = new java.util.concurrent.locks.ReentrantLock();
    /** Whether the RT half at the other end still runs: a call to a dead one ends early. */
    private volatile java.util.function.BooleanSupplier peerAlive = () -> true;
    /** How often a waiting call looks whether its peer still runs. */
    static final long PEER_CHECK_MS = 10;

    Mailbox(MessageQueue cmd, MessageQueue rsp, long token) {
        this.cmd = cmd;
        this.rsp = rsp;
        this.token = token;
    }

    /**
     * Creates both queues exclusively (0600); nothing is left behind on failure. {@code token}
     * goes into every request and must come back in every reply.
     */
    public static Mailbox create(String cmdName, String rspName, long token) throws IOException {
        MessageQueue c = MessageQueue.create(cmdName, MQ_MAXMSG, MSG_SIZE);
        try {
            return new Mailbox(c, MessageQueue.create(rspName, MQ_MAXMSG, MSG_SIZE), token);
        } catch (IOException e) {
            c.close();
            throw e;
        }
    }

    /** A request message with header filled and zeroed payload. */
    public static ByteBuffer message(Cmd c, int seq) {
        ByteBuffer b = ByteBuffer.allocate(MSG_SIZE).order(ByteOrder.LITTLE_ENDIAN);
        b.putInt(OFF_MAGIC, MSG_MAGIC);
        b.putShort(OFF_ABI_MAJOR, (short) ControlBlock.ABI_MAJOR);
        b.putShort(OFF_ABI_MINOR, (short) ControlBlock.ABI_MINOR);
        b.putInt(OFF_SEQ, seq);
        b.putShort(OFF_CMD, (short) c.code);
        return b;
    }

    /** Writes a NUL-terminated name into the payload. */
    public static void putName(ByteBuffer b, int payloadOff, int size, String s) {
        byte[] bytes = s.getBytes(StandardCharsets.US_ASCII);
        if (bytes.length >= size) {
            throw new IllegalArgumentException("'" + s + "' longer than " + (size - 1) + " bytes");
        }
        for (int i = 0; i < size; i++) {
            b.put(OFF_PAYLOAD + payloadOff + i, i < bytes.length ? bytes[i] : 0);
        }
    }

    /** BIND of input {@code port} to the provider segment {@code shmName}. */
    public Reply bind(String port, String shmName, long timeoutMs) throws IOException {
        return call(Cmd.BIND, bindPayload(port, shmName), timeoutMs);
    }

    private static java.util.function.Consumer<ByteBuffer> bindPayload(String port, String shmName) {
        return b -> {
            putName(b, BIND_PORT, ControlBlock.NAME_SIZE, port);
            if (shmName != null) {
                putName(b, BIND_SHM_NAME, OBJ_NAME_SIZE, shmName);
            }
            b.putInt(OFF_PAYLOAD_LEN, BIND_SIZE);
        };
    }

    /**
     * ADOPT (ABI 1.3, D41): the half takes the newest value of the state segment {@code shmName}
     * (the half it replaces) over at its next START.
     */
    public Reply adopt(String shmName, long timeoutMs) throws IOException {
        return call(Cmd.ADOPT, bindPayload("", shmName), timeoutMs);
    }

    /**
     * READOPT (D61): the running half takes the newest value of the state segment {@code shmName}
     * at its next cycle boundary; the reply comes once it did, or says why it did not.
     */
    public Reply readopt(String shmName, long timeoutMs) throws IOException {
        return call(Cmd.READOPT, bindPayload("", shmName), timeoutMs);
    }

    /** UNBIND of input {@code port}. */
    public Reply unbind(String port, long timeoutMs) throws IOException {
        return call(Cmd.UNBIND, bindPayload(port, null), timeoutMs);
    }

    /** Sends BIND of {@code port} to {@code shmName}; returns its seq for {@link #await}. */
    public int sendBind(String port, String shmName, long timeoutMs) throws IOException {
        return send(Cmd.BIND, bindPayload(port, shmName), timeoutMs);
    }

    /** Sends UNBIND of {@code port}; returns its seq for {@link #await}. */
    public int sendUnbind(String port, long timeoutMs) throws IOException {
        return send(Cmd.UNBIND, bindPayload(port, null), timeoutMs);
    }

    /** SET_PARAM of slot {@code index}; the reply carries the applied value. */
    public Reply setParam(int index, long bits, long timeoutMs) throws IOException {
        return call(Cmd.SET_PARAM, b -> {
            b.putInt(OFF_PAYLOAD + PARAM_INDEX, index);
            b.putLong(OFF_PAYLOAD + PARAM_VALUE, bits);
            b.putInt(OFF_PAYLOAD_LEN, PARAM_SIZE);
        }, timeoutMs);
    }

    /**
     * A call now also ends when {@code alive} says the RT half has exited, within
     * {@link #PEER_CHECK_MS} of that, instead of waiting for its whole timeout (issue 17: the
     * lifecycle actor waited up to 2 s on a BIND to a half that had been killed, and the exit of
     * every other half waited behind it).
     */
    public void watch(java.util.function.BooleanSupplier alive) {
        peerAlive = alive;
    }

    /** A command without payload. */
    public Reply call(Cmd c, long timeoutMs) throws IOException {
        return call(c, b -> { }, timeoutMs);
    }

    /**
     * Sends a request and waits for its reply until the deadline.
     *
     * @throws IOException on transport failure or when no reply came in time
     */
    public Reply call(Cmd c, java.util.function.Consumer<ByteBuffer> fill, long timeoutMs)
            throws IOException {
        int s = send(c, fill, timeoutMs);
        Optional<Reply> r;
        try {
            r = await(c, s, timeoutMs);
        } finally {
            forget(s);
        }
        return r.orElseThrow(() -> new IOException(c + " (seq " + s + "): no reply within " + timeoutMs + " ms on " + rsp.name()));
    }

    /** Sends a request (waiting at most {@code timeoutMs} for room in the queue); returns its seq, now awaited. */
    public int send(Cmd c, java.util.function.Consumer<ByteBuffer> fill, long timeoutMs) throws IOException {
        int s;
        ByteBuffer req;
        synchronized (this) {
            s = ++seq;
            req = message(c, s);
            fill.accept(req);
            req.putLong(OFF_TOKEN, token);
            awaited.add(s);
        }
        try {
            cmd.send(req.array(), timeoutMs);
        } catch (IOException | RuntimeException e) {
            forget(s);
            throw e;
        }
        return s;
    }

    /**
     * Waits up to {@code timeoutMs} for the reply to request {@code s} of command {@code c}:
     * empty when none came in that time (the request stays awaited: wait again, or
     * {@link #forget} it).
     *
     * @throws IOException on transport failure, or when the RT half exited before it answered
     */
    public Optional<Reply> await(Cmd c, int s, long timeoutMs) throws IOException {
        long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
        while (true) {
            synchronized (this) {
                Reply got = arrived.remove(s);
                if (got != null) {
                    return Optional.of(got);
                }
            }
            long left = (deadline - System.nanoTime()) / 1_000_000L;
            if (left <= 0) {
                return Optional.empty();
            }
            if (!reader.tryLock()) {
                // another waiter reads the queue for this turn; it keeps our reply for us
                java.util.concurrent.locks.LockSupport.parkNanos(200_000);
                continue;
            }
            Optional<byte[]> got;
            try {
                got = rsp.receive(Math.min(left, PEER_CHECK_MS));
                if (got.isPresent()) {
                    keep(got.get());
                }
            } finally {
                reader.unlock();
            }
            if (got.isEmpty() && !peerAlive.getAsBoolean()) {
                synchronized (this) {
                    if (arrived.containsKey(s)) {
                        continue;
                    }
                }
                throw new IOException(c + " (seq " + s + "): the RT half exited before it answered (" + rsp.name() + ")");
            }
        }
    }

    /** Request {@code s} is not awaited any more: its reply, now or later, is discarded. */
    public synchronized void forget(int s) {
        awaited.remove(s);
        arrived.remove(s);
    }

    /** A message from the reply queue: kept when it is our RT half's reply to an awaited request. */
    private synchronized void keep(byte[] m) {
        ByteBuffer r = ByteBuffer.wrap(m).order(ByteOrder.LITTLE_ENDIAN);
        if (m.length < OFF_PAYLOAD || r.getInt(OFF_MAGIC) != MSG_MAGIC
                || r.getShort(OFF_ABI_MAJOR) != ControlBlock.ABI_MAJOR) {
            return; // not a message of ours: discarded
        }
        if (r.getLong(OFF_TOKEN) != token) {
            return; // not from our RT half
        }
        int s = r.getInt(OFF_SEQ);
        if ((r.getShort(OFF_FLAGS) & FLAG_REPLY) == 0 || !awaited.contains(s)) {
            return; // a late reply to a request nobody awaits any more
        }
        arrived.put(s, new Reply(r.getInt(OFF_STATUS), r));
    }

    public String cmdName() {
        return cmd.name();
    }

    public String rspName() {
        return rsp.name();
    }

    /** Closes and removes both queues. */
    @Override
    public void close() {
        cmd.close();
        rsp.close();
    }
}
