package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import java.util.concurrent.CompletableFuture;
import org.junit.jupiter.api.Test;

/**
 * D39: a request is sent and its reply awaited apart, so the actor can stop waiting for a half
 * that does not answer at once and a confirmer thread waits for the rest. Real POSIX queues;
 * the test plays the RT half and answers when and in which order it wants.
 */
class MailboxAwaitTest {

    private static final long TOKEN = 0x7777_0000_1234_5678L;
    private final String rid = "ja" + ProcessHandle.current().pid();

    /** The requests waiting in the command queue, as the RT half would read them. */
    private static List<ByteBuffer> requests(MessageQueue cmd, int n) throws Exception {
        List<ByteBuffer> out = new ArrayList<>();
        for (int i = 0; i < n; i++) {
            out.add(ByteBuffer.wrap(cmd.receive(5_000).orElseThrow()).order(ByteOrder.LITTLE_ENDIAN));
        }
        return out;
    }

    private static void answer(MessageQueue rsp, ByteBuffer req, int status) throws Exception {
        ByteBuffer r = ByteBuffer.allocate(Mailbox.MSG_SIZE).order(ByteOrder.LITTLE_ENDIAN);
        r.put(req.array());
        r.putShort(Mailbox.OFF_FLAGS, (short) Mailbox.FLAG_REPLY);
        r.putInt(Mailbox.OFF_STATUS, status);
        rsp.send(r.array(), 1_000);
    }

    @Test
    void repliesInAnyOrderReachTheirWaitersAndAForgottenRequestsReplyIsDropped() throws Exception {
        MessageQueue cmd = MessageQueue.create("/arflex." + rid + ".aw.cmd", Mailbox.MQ_MAXMSG, Mailbox.MSG_SIZE);
        MessageQueue rsp = MessageQueue.create("/arflex." + rid + ".aw.rsp", Mailbox.MQ_MAXMSG, Mailbox.MSG_SIZE);
        try (Mailbox mb = new Mailbox(cmd, rsp, TOKEN)) {
            int a = mb.sendBind("x", "/arflex.t.p.out.y", 1_000);
            // the half has not answered yet: the caller stops waiting, the request stays awaited
            assertEquals(Optional.empty(), mb.await(Mailbox.Cmd.BIND, a, 20));
            int b = mb.sendUnbind("z", 1_000);
            int c = mb.send(Mailbox.Cmd.PING, buf -> { }, 1_000);
            mb.forget(c); // nobody waits for c any more
            List<ByteBuffer> req = requests(cmd, 3);
            assertEquals(List.of(a, b, c), req.stream().map(r -> r.getInt(Mailbox.OFF_SEQ)).toList());
            // answered in another order than asked: c (forgotten), b, then a
            answer(rsp, req.get(2), -5);
            answer(rsp, req.get(1), -2);
            answer(rsp, req.get(0), 0);
            // a waits on another thread meanwhile; b's waiter reads the queue: each gets its own
            CompletableFuture<Integer> first = CompletableFuture.supplyAsync(() -> {
                try {
                    return mb.await(Mailbox.Cmd.BIND, a, 5_000).orElseThrow().status();
                } catch (Exception e) {
                    throw new IllegalStateException(e);
                }
            });
            assertEquals(-2, mb.await(Mailbox.Cmd.UNBIND, b, 5_000).orElseThrow().status());
            assertEquals(0, first.get());
            mb.forget(a);
            mb.forget(b);
            // c's reply was dropped, not kept for a waiter that will never come
            assertEquals(Optional.empty(), mb.await(Mailbox.Cmd.PING, c, 30));
            // and a plain call still works after all this
            CompletableFuture<Void> half = CompletableFuture.runAsync(() -> {
                try {
                    answer(rsp, requests(cmd, 1).get(0), 0);
                } catch (Exception e) {
                    throw new IllegalStateException(e);
                }
            });
            assertEquals(0, mb.call(Mailbox.Cmd.PING, 5_000).status());
            half.get();
            assertTrue(cmd.receive(0).isEmpty(), "nothing left in the command queue");
        }
    }
}
