package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.net.InetAddress;
import java.net.ServerSocket;
import java.net.Socket;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * Issue 16 finding 4: Felix's own {@code install}/{@code update} from a server that never answers
 * blocked the Gogo shell for minutes. The assembly's conf/system.properties bounds every URL
 * connection of the JVM, and scripts/run-cell.sh (the main job) passes them on; this test starts
 * the runtime through run-cell.sh with a 2 s read timeout (the assembly's is 30 s) so that it
 * runs quickly, and checks that the shell is back and answers the next command.
 */
class ShellTimeoutIT {

    @Test
    void felixInstallFromASilentServerGivesTheShellBack() throws Exception {
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).resolve("shell-timeout").toAbsolutePath();
        try (ServerSocket silent = new ServerSocket(0, 10, InetAddress.getByName("127.0.0.1"));
                RuntimeUnderTest rt = new RuntimeUnderTest(work, false, Map.of("sun.net.client.defaultConnectTimeout",
                        "2000", "sun.net.client.defaultReadTimeout", "2000"))) {
            List<Socket> held = new ArrayList<>();
            Thread acceptor = new Thread(() -> {
                while (!silent.isClosed()) {
                    try {
                        held.add(silent.accept());
                    } catch (java.io.IOException e) {
                        return;
                    }
                }
            }, "silent-server");
            acceptor.setDaemon(true);
            acceptor.start();
            rt.awaitUp(Duration.ofSeconds(90));
            long t0 = System.nanoTime();
            rt.gogo("install ftp://127.0.0.1:" + silent.getLocalPort() + "/x.jar");
            rt.gogo("echo shell-is-back-" + t0);
            RuntimeUnderTest.awaitCondition("the shell back after the read timeout", Duration.ofSeconds(20),
                    () -> log(rt).contains("shell-is-back-" + t0));
            double s = (System.nanoTime() - t0) / 1e9;
            System.out.printf("ShellTimeoutIT: shell back after %.1f s%n", s);
            String log = log(rt);
            assertTrue(log.contains("Read timed out") || log.contains("timed out"), rt.tail());
            assertTrue(held.size() >= 1, "the server was reached");
            for (Socket k : held) {
                k.close();
            }
        }
    }

    private static String log(RuntimeUnderTest rt) {
        try {
            return Files.readString(rt.log);
        } catch (java.io.IOException e) {
            return "";
        }
    }
}
