package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.io.InputStream;
import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermission;
import java.security.GeneralSecurityException;
import java.security.KeyStore;
import java.security.cert.Certificate;
import java.security.cert.CertificateException;
import java.security.cert.CertificateFactory;
import java.util.ArrayList;
import java.util.Collection;
import java.util.List;
import java.util.Locale;
import java.util.Set;

/**
 * The runtime's trust store for signed code (docs/DECISIONS.md D14): a folder of X.509
 * certificates, one or more per file named {@code *.crt}, {@code *.pem} or {@code *.cer} (PEM
 * or DER, as {@code keytool -exportcert [-rfc]} writes them). A key is trusted while its
 * certificate is in the folder; other files and subfolders are ignored.
 *
 * <p>The folder is read again for every decision, so adding or removing a certificate takes
 * effect at the next start of a bundle. It is refused as a whole, and no signature is trusted,
 * when it does not exist, when it or a certificate file is writable by group or others or owned
 * by anyone but the runtime's user or root, when a folder above it is writable by group or
 * others without the sticky bit, or when a certificate file cannot be read: a trust store that
 * others can write to is a door, and a broken one is a mistake to fix, not to work around.
 */
final class TrustStore {

    private static final Set<PosixFilePermission> OTHERS_WRITE = Set.of(PosixFilePermission.GROUP_WRITE,
            PosixFilePermission.OTHERS_WRITE);

    private final Path folder;

    /** @param folder the trust store folder; null: none configured, no signature is trusted */
    TrustStore(Path folder) {
        this.folder = folder == null ? null : folder.toAbsolutePath().normalize();
    }

    /** The folder, or null when none is configured. */
    Path folder() {
        return folder;
    }

    /**
     * The certificates now in the folder (as trusted-certificate entries, alias = file name and
     * index), or an exception whose message says why no signature is trusted.
     */
    KeyStore load() throws IOException {
        if (folder == null) {
            throw new IOException("no trust store is configured (framework property arflex.code.truststore)");
        }
        if (!Files.isDirectory(folder)) {
            throw new IOException("the trust store " + folder + " does not exist or is not a folder"
                    + " (framework property arflex.code.truststore)");
        }
        Path real = folder.toRealPath();
        checkNotADoor(real, "the trust store folder");
        Path up = FileDoors.writableAbove(real);
        if (up != null) {
            throw new IOException("the trust store " + real + " is refused: the folder " + up
                    + " above it is writable by group or others (" + FileDoors.octal(FileDoors.mode(up))
                    + "), so its trust store could be replaced");
        }
        KeyStore ks;
        try {
            ks = KeyStore.getInstance("PKCS12");
            ks.load(null, null);
        } catch (GeneralSecurityException e) {
            throw new IOException("cannot make a key store: " + e.getMessage(), e);
        }
        CertificateFactory cf;
        try {
            cf = CertificateFactory.getInstance("X.509");
        } catch (CertificateException e) {
            throw new IOException("no X.509 support: " + e.getMessage(), e);
        }
        List<Path> files = new ArrayList<>();
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(real)) {
            for (Path f : ds) {
                String n = f.getFileName().toString().toLowerCase(Locale.ROOT);
                if ((n.endsWith(".crt") || n.endsWith(".pem") || n.endsWith(".cer")) && Files.isRegularFile(f)) {
                    files.add(f);
                }
            }
        }
        files.sort(null);
        for (Path f : files) {
            checkNotADoor(f.toRealPath(), "the certificate file");
            Collection<? extends Certificate> certs;
            try (InputStream in = Files.newInputStream(f)) {
                certs = cf.generateCertificates(in);
            } catch (CertificateException e) {
                throw new IOException("the trust store " + real + " is refused: " + f.getFileName()
                        + " is not an X.509 certificate (" + e.getMessage() + ")", e);
            }
            if (certs.isEmpty()) {
                throw new IOException("the trust store " + real + " is refused: " + f.getFileName()
                        + " holds no certificate");
            }
            int i = 0;
            for (Certificate c : certs) {
                try {
                    ks.setCertificateEntry(f.getFileName() + "#" + i++, c);
                } catch (GeneralSecurityException e) {
                    throw new IOException("cannot hold " + f.getFileName() + ": " + e.getMessage(), e);
                }
            }
        }
        return ks;
    }

    /** Refuses a folder or file that group or others may write, or that another user owns. */
    private static void checkNotADoor(Path p, String what) throws IOException {
        Set<PosixFilePermission> perms = Files.getPosixFilePermissions(p);
        if (perms.stream().anyMatch(OTHERS_WRITE::contains)) {
            throw new IOException(what + " " + p + " is writable by group or others ("
                    + java.nio.file.attribute.PosixFilePermissions.toString(perms)
                    + "): the trust store is refused, no signature is trusted; chmod go-w it");
        }
        String owner = Files.getOwner(p, LinkOption.NOFOLLOW_LINKS).getName();
        String me = System.getProperty("user.name");
        if (!owner.equals(me) && !owner.equals("root")) {
            throw new IOException(what + " " + p + " is owned by " + owner + ", not by " + me
                    + " or root: the trust store is refused, no signature is trusted");
        }
    }
}
