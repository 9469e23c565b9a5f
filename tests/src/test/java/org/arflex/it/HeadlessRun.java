package org.arflex.it;

import java.io.IOException;
import java.net.InetAddress;
import java.net.ServerSocket;
import java.nio.file.Files;
import java.nio.file.Path;

/**
 * The main job as {@code ./arflex run --headless SECONDS} starts it ({@code scripts/run-cell.sh}), on
 * a copy of the runtime assembly whose console listens on a free loopback port, without the
 * caller's console credentials, with its own home folder.
 *
 * @param assembly the copy of the assembly the run uses
 * @param port     the console's HTTP port in that copy
 */
record HeadlessRun(Path assembly, int port) {

    /** A fresh copy of the assembly under the ITs' work folder, named {@code name}. */
    static HeadlessRun copy(String name) throws IOException {
        Path copy = Path.of(System.getProperty("arflex.it.work")).resolve(name);
        Runtime.deleteTree(copy);
        Runtime.copyTree(Path.of(System.getProperty("arflex.it.runtime")), copy);
        int port;
        try (ServerSocket s = new ServerSocket(0, 1, InetAddress.getLoopbackAddress())) {
            port = s.getLocalPort();
        }
        Path conf = copy.resolve("conf/config.properties");
        Files.writeString(conf, Files.readString(conf).replace("org.osgi.service.http.port=8480",
                "org.osgi.service.http.port=" + port));
        return new HeadlessRun(copy, port);
    }

    /** The run for {@code seconds}, with {@code home} as ARFLEX_HOME, output and errors merged. */
    ProcessBuilder command(int seconds, Path home) {
        ProcessBuilder pb = new ProcessBuilder("bash", Components.root().resolve("scripts/run-cell.sh").toString(),
                assembly.toString(), Integer.toString(seconds)).redirectErrorStream(true);
        pb.environment().remove("ARFLEX_CONSOLE_PASSWORD");
        pb.environment().remove("ARFLEX_CONSOLE_USER");
        pb.environment().put("ARFLEX_HOME", home.toString());
        return pb;
    }
}
