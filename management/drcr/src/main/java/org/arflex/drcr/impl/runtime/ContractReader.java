package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.io.InputStream;
import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractException;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;

/**
 * Reads the contracts a bundle names in its {@code ARFLEX-Contract} manifest header. Each
 * contract is parsed on its own: a bad one becomes a problem (file, line, section) and the
 * others are still read.
 */
public final class ContractReader {

    /** The manifest header naming the contracts (comma-separated entry paths). */
    public static final String HEADER = "ARFLEX-Contract";
    /** Where the executables live inside a bundle. */
    public static final String NATIVE_DIR = "native/linux-x86_64/";

    /** Opens an entry of the bundle, or returns null when it does not exist. */
    public interface Entries {
        InputStream open(String path) throws IOException;
    }

    /** Contracts read and problems found. */
    public record Result(List<Contract> contracts, List<String> problems) {
    }

    private final ContractParser parser;

    public ContractReader(PortTypes types) {
        this.parser = ContractParser.create(types);
    }

    /** The entry paths named by a header value. */
    public static List<String> paths(String header) {
        List<String> out = new ArrayList<>();
        if (header != null) {
            for (String p : header.split(",")) {
                String t = p.trim();
                if (!t.isEmpty()) {
                    out.add(t.startsWith("/") ? t.substring(1) : t);
                }
            }
        }
        return out;
    }

    /**
     * Reads every contract named in {@code header}.
     *
     * @param label how to name the bundle in messages, for example {@code bundle 7 (org.x)}
     */
    public Result read(String label, String header, Entries entries) {
        List<Contract> ok = new ArrayList<>();
        List<String> problems = new ArrayList<>();
        for (String path : paths(header)) {
            String source = label + " " + path;
            try (InputStream in = entries.open(path)) {
                if (in == null) {
                    problems.add(source + ": contract named in " + HEADER + " is missing from the bundle");
                    continue;
                }
                Contract c = parser.parse(in, source);
                if (entries.open(NATIVE_DIR + c.executable()) == null) {
                    problems.add(source + ": executable " + NATIVE_DIR + c.executable() + " is missing from the bundle");
                    continue;
                }
                ok.add(c);
            } catch (ContractException e) {
                problems.add("contract rejected:\n" + e.getMessage());
            } catch (IOException | RuntimeException e) {
                problems.add(source + ": cannot read contract: " + e);
            }
        }
        return new Result(ok, problems);
    }

    /**
     * The same contract read from two places: every part equal but {@code source} (which says
     * where it was read: a bundle, a jar URL). A committed update's jar read again from its
     * updated bundle gives such a pair (D43).
     */
    public static boolean sameButSource(Contract a, Contract b) {
        if (a == b) {
            return true;
        }
        if (a == null || b == null) {
            return false;
        }
        try {
            for (java.lang.reflect.RecordComponent rc : Contract.class.getRecordComponents()) {
                if (!rc.getName().equals("source")
                        && !java.util.Objects.equals(rc.getAccessor().invoke(a), rc.getAccessor().invoke(b))) {
                    return false;
                }
            }
            return true;
        } catch (ReflectiveOperationException e) {
            throw new IllegalStateException(e);
        }
    }
}
