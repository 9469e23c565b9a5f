package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.util.concurrent.CompletableFuture;
import org.junit.jupiter.api.Test;

/** Issue 16 finding 6 (ABI.md 5, DECISIONS.md D13): the token in requests and replies. */
class MailboxTokenTest {

    private static final long TOKEN = 0x0123_4567_89ab_cdefL;
    private final String rid = "jt" + ProcessHandle.current().pid();

    /** Plays the RT half: answers one request with each of {@code replyTokens}, in order. */
    private static CompletableFuture<Long> respond(MessageQueue cmd, MessageQueue rsp, long... replyTokens) {
        return CompletableFuture.supplyAsync(() -> {
            try {
                ByteBuffer req = ByteBuffer.wrap(cmd.receive(5_000).orElseThrow()).order(ByteOrder.LITTLE_ENDIAN);
                for (long t : replyTokens) {
                    ByteBuffer r = ByteBuffer.allocate(Mailbox.MSG_SIZE).order(ByteOrder.LITTLE_ENDIAN);
                    r.put(req.array());
                    r.putShort(Mailbox.OFF_FLAGS, (short) Mailbox.FLAG_REPLY);
                    r.putInt(Mailbox.OFF_STATUS, t == TOKEN ? -7 : -99);
                    r.putLong(Mailbox.OFF_TOKEN, t);
                    rsp.send(r.array(), 1_000);
                }
                return req.getLong(Mailbox.OFF_TOKEN);
            } catch (IOException e) {
                throw new IllegalStateException(e);
            }
        });
    }

    @Test
    void requestsCarryTheTokenAndRepliesWithAnotherOneAreDiscarded() throws Exception {
        MessageQueue cmd = MessageQueue.create("/arflex." + rid + ".tok.cmd", Mailbox.MQ_MAXMSG, Mailbox.MSG_SIZE);
        MessageQueue rsp = MessageQueue.create("/arflex." + rid + ".tok.rsp", Mailbox.MQ_MAXMSG, Mailbox.MSG_SIZE);
        try (Mailbox mb = new Mailbox(cmd, rsp, TOKEN)) {
            CompletableFuture<Long> seen = respond(cmd, rsp, 0L, TOKEN ^ 1, TOKEN);
            assertEquals(-7, mb.call(Mailbox.Cmd.PING, 5_000).status(), "only the reply with our token counts");
            assertEquals(TOKEN, seen.get());

            seen = respond(cmd, rsp, 0L, ~TOKEN);
            assertThrows(IOException.class, () -> mb.call(Mailbox.Cmd.STOP, 300), "forged replies only: no reply");
            assertEquals(TOKEN, seen.get());
        }
    }

    @Test
    void aCallToAnRtHalfThatExitedEndsAtOnceNotAtItsTimeout() throws Exception {
        MessageQueue cmd = MessageQueue.create("/arflex." + rid + ".gone.cmd", Mailbox.MQ_MAXMSG, Mailbox.MSG_SIZE);
        MessageQueue rsp = MessageQueue.create("/arflex." + rid + ".gone.rsp", Mailbox.MQ_MAXMSG, Mailbox.MSG_SIZE);
        try (Mailbox mb = new Mailbox(cmd, rsp, TOKEN)) {
            mb.watch(() -> false); // nobody will ever answer: the peer is gone
            long t0 = System.nanoTime();
            IOException e = assertThrows(IOException.class, () -> mb.call(Mailbox.Cmd.BIND, 60_000));
            long ms = (System.nanoTime() - t0) / 1_000_000L;
            org.junit.jupiter.api.Assertions.assertTrue(e.getMessage().contains("exited before it answered"), e.getMessage());
            org.junit.jupiter.api.Assertions.assertTrue(ms < 30_000, "waited " + ms + " ms of a 60 s timeout");
        }
    }
}
