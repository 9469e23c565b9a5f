package org.arflex.shell;

import java.io.FileDescriptor;
import java.io.FileInputStream;
import java.io.FileOutputStream;
import java.io.IOException;
import java.io.InputStream;
import java.io.InputStreamReader;
import java.io.PrintStream;
import java.net.URL;
import java.nio.charset.StandardCharsets;
import java.util.concurrent.CountDownLatch;
import java.util.concurrent.TimeUnit;
import org.apache.felix.service.command.CommandProcessor;
import org.apache.felix.service.command.CommandSession;
import org.osgi.annotation.bundle.Header;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleActivator;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;
import org.osgi.framework.Constants;
import org.osgi.framework.FrameworkEvent;
import org.osgi.framework.FrameworkListener;
import org.osgi.util.tracker.ServiceTracker;

/**
 * The runtime's console on standard input (docs/DECISIONS.md D28): a Gogo session created as
 * Gogo's shell creates its login session (the same profile, so the same {@code SCOPE}, prompt
 * and commands), read by {@link LineConsole}. The end of input stops the framework, as Gogo's
 * login shell did. The first line is read once the framework has started (every bundle of its
 * start level started), so a piped script's commands exist when it runs. Gogo's own console is
 * kept off by {@code gosh.args=--nointeractive} in conf/config.properties; {@code arflex.shell=none}
 * starts no console at all.
 */
@Header(name = Constants.BUNDLE_ACTIVATOR, value = "${@class}")
public final class Activator implements BundleActivator {

    private static final long WAIT_MS = 30_000;
    /** Longest wait for the framework's start before the console reads its first line. */
    private static final long START_MS = 300_000;

    private volatile Thread thread;
    private volatile boolean stopping;

    @Override
    public void start(BundleContext ctx) {
        if ("none".equals(ctx.getProperty("arflex.shell"))) {
            return;
        }
        Thread t = new Thread(() -> run(ctx), "arflex-shell");
        t.setDaemon(true);
        thread = t;
        t.start();
    }

    @Override
    public void stop(BundleContext ctx) {
        stopping = true;
        Thread t = thread;
        if (t != null) {
            t.interrupt();
        }
    }

    private void run(BundleContext ctx) {
        ServiceTracker<CommandProcessor, CommandProcessor> tracker = new ServiceTracker<>(ctx, CommandProcessor.class, null);
        tracker.open();
        try {
            CommandProcessor processor = tracker.waitForService(WAIT_MS);
            if (processor == null) {
                System.err.println("arflex shell: no Gogo command processor after " + WAIT_MS / 1000 + " s: no console");
                return;
            }
            awaitStarted(ctx);
            PrintStream out = new PrintStream(new FileOutputStream(FileDescriptor.out), true, StandardCharsets.UTF_8);
            InputStream keyboard = new FileInputStream(FileDescriptor.in);
            CommandSession session = processor.createSession(keyboard, out, new FileOutputStream(FileDescriptor.err));
            session.put(".gosh_login", true);
            session.put(".gosh_interactive", true);
            session.put(".gosh_quiet", true);
            profile(ctx, session);
            new LineConsole(session, new InputStreamReader(keyboard, StandardCharsets.UTF_8), out).run();
            session.close();
            if (!stopping) {
                out.println("gosh: stopping shell and framework");
                ctx.getBundle(Constants.SYSTEM_BUNDLE_LOCATION).stop();
            }
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
        } catch (IOException | BundleException | RuntimeException e) {
            if (!stopping) {
                System.err.println("arflex shell: " + e);
            }
        } finally {
            tracker.close();
        }
    }

    /**
     * Waits until the framework has started every bundle of its start level (the system bundle
     * is ACTIVE once they all are, then STARTED is fired), so that the commands of the runtime's
     * bundles (the DRCR's arflex:*) exist before the first line typed runs: a script piped into
     * the console needs no sign from the log. Not forever: a bundle whose start hangs would keep
     * the console closed, so after START_MS it reads anyway and says so.
     */
    private static void awaitStarted(BundleContext ctx) throws InterruptedException {
        CountDownLatch started = new CountDownLatch(1);
        FrameworkListener l = e -> {
            if (e.getType() == FrameworkEvent.STARTED) {
                started.countDown();
            }
        };
        ctx.addFrameworkListener(l);
        try {
            if (ctx.getBundle(Constants.SYSTEM_BUNDLE_LOCATION).getState() != Bundle.ACTIVE
                    && !started.await(START_MS, TimeUnit.MILLISECONDS)) {
                System.err.println("arflex shell: the framework has not finished starting after " + START_MS / 1000
                        + " s; reading commands anyway");
            }
        } finally {
            ctx.removeFrameworkListener(l);
        }
    }

    /**
     * Gogo's login profile, from Gogo's shell bundle only (a bundle the code gate admitted).
     * Gogo's own shell also ran {@code etc/gosh_profile} of the working directory: a file on disk
     * executed as commands at every start, unverified; this console does not.
     */
    private static void profile(BundleContext ctx, CommandSession session) {
        for (Bundle b : ctx.getBundles()) {
            if (!"org.apache.felix.gogo.shell".equals(b.getSymbolicName())) {
                continue;
            }
            URL u = b.getEntry("/ext/gosh_profile");
            u = u != null ? u : b.getEntry("/gosh_profile");
            if (u == null) {
                continue;
            }
            try (InputStream s = u.openStream()) {
                session.execute(new String(s.readAllBytes(), StandardCharsets.UTF_8));
            } catch (Exception e) {
                System.err.println("arflex shell: the login profile failed: " + e);
            }
        }
    }
}
