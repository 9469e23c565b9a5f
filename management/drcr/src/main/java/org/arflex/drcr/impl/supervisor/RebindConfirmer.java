package org.arflex.drcr.impl.supervisor;

import java.io.IOException;
import java.util.Optional;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import org.arflex.drcr.impl.abi.Mailbox;

/**
 * A running half's BIND or UNBIND, confirmed apart from its caller (docs/DECISIONS.md D39): the
 * request is sent on the half's mailbox and its answer awaited for the caller's {@code waitMs};
 * a half that has not answered by then is awaited by a daemon confirmer thread for the rest of
 * the call timeout, and the stage completes when it answers or the timeout passes.
 */
final class RebindConfirmer {

    /** Waits for the answers the actor did not wait for (D39); daemon threads, made as needed. */
    private final ExecutorService confirmer = Executors.newCachedThreadPool(r -> {
        Thread t = new Thread(r, "arflex-mailbox-confirm");
        t.setDaemon(true);
        return t;
    });

    /** Made with the launcher, so that a first rebind on the actor has nothing to load or set up. */
    RebindConfirmer() {
    }

    /**
     * Sends BIND {@code port} to {@code segment} (UNBIND when it is null) to the half {@code inst}
     * and waits up to {@code waitMs} for its answer on the calling thread, the rest of
     * {@code timeoutMs} (counted from the send) on a confirmer thread. The stage completes
     * normally on status 0 and exceptionally on a refusal, no answer within {@code timeoutMs}, or
     * a mailbox error; the request is forgotten either way.
     */
    CompletableFuture<Void> rebind(Mailbox mb, String inst, String port, String segment, long waitMs,
                                   long timeoutMs) {
        Mailbox.Cmd c = segment != null ? Mailbox.Cmd.BIND : Mailbox.Cmd.UNBIND;
        String what = c + " " + inst + "." + port + (segment != null ? " to " + segment : "");
        int s;
        try {
            s = segment != null ? mb.sendBind(port, segment, timeoutMs) : mb.sendUnbind(port, timeoutMs);
        } catch (IOException | RuntimeException e) {
            return CompletableFuture.failedFuture(e);
        }
        CompletableFuture<Void> done = new CompletableFuture<>();
        long t0 = System.nanoTime();
        Runnable rest = () -> {
            try {
                long left = timeoutMs - (System.nanoTime() - t0) / 1_000_000L;
                Optional<Mailbox.Reply> r = mb.await(c, s, Math.max(0, left));
                if (r.isEmpty()) {
                    done.completeExceptionally(new IOException(what + ": no reply within " + timeoutMs + " ms"));
                } else {
                    settle(done, what, r.get());
                }
            } catch (IOException | RuntimeException e) {
                done.completeExceptionally(e);
            } finally {
                mb.forget(s);
            }
        };
        try {
            Optional<Mailbox.Reply> r = mb.await(c, s, waitMs);
            if (r.isPresent()) {
                mb.forget(s);
                settle(done, what, r.get());
                return done;
            }
        } catch (IOException | RuntimeException e) {
            mb.forget(s);
            return CompletableFuture.failedFuture(e);
        }
        confirmer.execute(rest); // the rest of the wait, off the caller's thread
        return done;
    }

    /** Completes {@code done} with the half's answer: normally on status 0, else as a refusal. */
    private static void settle(CompletableFuture<Void> done, String what, Mailbox.Reply r) {
        if (r.status() != 0) {
            done.completeExceptionally(new IOException(what + " refused: status " + r.status()));
        } else {
            done.complete(null);
        }
    }
}
