package org.arflex.drcr.impl.machine;

import java.util.concurrent.Executors;
import java.util.concurrent.ScheduledExecutorService;
import java.util.concurrent.TimeUnit;
import java.util.function.Consumer;

/**
 * Watches what the machine gives the runtime (D85): reads it with a {@link MachineReader} at
 * every poll (on its own thread, every second by default) and hands each change with its cause
 * to a listener, the Resource Manager, which re-plans as for a change through its API. Polled,
 * not inotify: cgroup v1 files do not notify a change of cpuset.cpus, and a poll reads five
 * small files. A file that cannot be read or parsed is logged once, naming it, and the last good
 * view is kept until it reads again.
 */
public final class MachineWatch implements AutoCloseable {

    /** Receives each change. */
    public interface Listener {
        /** The machine changed from {@code before} to {@code now}, because of {@code cause}. */
        void changed(MachineView before, MachineView now, String cause);
    }

    private final MachineReader reader;
    private final Listener listener;
    private final Consumer<String> log;
    private volatile MachineView last;
    private volatile String problem;
    private volatile String lastCause;
    private ScheduledExecutorService thread;

    /**
     * @param initial the view the capacities were set from (null when it could not be read: the
     *                first good read is then taken as it is, without a change)
     */
    public MachineWatch(MachineReader reader, MachineView initial, Listener listener, Consumer<String> log) {
        this.reader = reader;
        this.last = initial;
        this.listener = listener;
        this.log = log;
    }

    /**
     * Reads the machine once and reports a change; any thread, one at a time.
     *
     * @return the cause of the change, or null when nothing changed or the read failed
     */
    public synchronized String poll() {
        MachineView now;
        try {
            now = reader.read();
        } catch (MachineReadException e) {
            String p = e.getMessage() + "; keeping " + (last == null ? "the configured capacities" : last.describe());
            if (!p.equals(problem)) {
                log.accept("arflex: machine: " + p);
            }
            problem = p;
            return null;
        }
        if (problem != null) {
            log.accept("arflex: machine: readable again: " + now.describe());
            problem = null;
        }
        MachineView before = last;
        String cause = before == null ? null : MachineDiff.cause(before, now);
        if (cause != null) {
            log.accept("arflex: machine: " + cause + ": now " + now.describe());
            // the view is taken once the listener applied it: a change that failed is tried again
            listener.changed(before, now, cause);
            lastCause = cause;
        }
        last = now;
        return cause;
    }

    /** Polls every {@code periodMs} on a daemon thread of its own until {@link #close()}. */
    public synchronized void start(long periodMs) {
        if (thread != null) {
            throw new IllegalStateException("the machine watch is already started");
        }
        thread = Executors.newSingleThreadScheduledExecutor(r -> {
            Thread t = new Thread(r, "arflex-drcr-machine");
            t.setDaemon(true);
            return t;
        });
        thread.scheduleWithFixedDelay(() -> {
            try {
                poll();
            } catch (RuntimeException e) {
                log.accept("arflex: machine: the change could not be applied: " + e);
            }
        }, periodMs, periodMs, TimeUnit.MILLISECONDS);
    }

    /** The last view read well (null before the first). */
    public MachineView last() {
        return last;
    }

    /** Why the last read failed, null when it did not. */
    public String problem() {
        return problem;
    }

    /** The cause of the last change seen, null before the first. */
    public String lastCause() {
        return lastCause;
    }

    @Override
    public void close() {
        ScheduledExecutorService t;
        synchronized (this) {
            t = thread;
        }
        if (t != null) {
            t.shutdownNow();
        }
    }
}
