package org.arflex.contract.internal;

import java.io.PrintStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.ContractParser;
import org.arflex.contract.Problem;

/**
 * {@code arflex validate FILE...}: checks contracts from the command line with the parser and
 * validator the DRCR reads bundles with (the schema, then every rule of contracts/SPEC.md; the
 * built-in port types), without a runtime (D84). Prints {@code FILE: ok (component NAME)} for a
 * good contract and one line per problem for a bad one,
 * {@code FILE:LINE:COLUMN: [§SECTION] FIELD: what is wrong}. Exit 0 when every file is a valid
 * contract, 1 when one is not (or cannot be read), 2 on a wrong command line.
 */
public final class ValidateCommand {

    private ValidateCommand() {
    }

    public static void main(String[] args) {
        System.exit(run(List.of(args), System.out, System.err));
    }

    /** Validates each file; returns the exit status. */
    static int run(List<String> args, PrintStream out, PrintStream err) {
        if (args.isEmpty() || args.stream().anyMatch(a -> a.startsWith("-"))) {
            err.println("usage: arflex validate CONTRACT.xml...   (checks each contract with the DRCR's rules)");
            return 2;
        }
        List<Path> files = new ArrayList<>();
        int status = 0;
        for (String a : args) {
            Path f = Path.of(a);
            if (!Files.isRegularFile(f)) {
                err.println(a + ":0:0: (document): no such file");
                status = 1;
            } else {
                files.add(f);
            }
        }
        for (ContractParser.Result r : ContractParser.create().parseFiles(files)) {
            if (r.ok()) {
                out.println(r.source() + ": ok (component " + r.contract().orElseThrow().name() + ")");
            } else {
                status = 1;
                for (Problem p : r.problems()) {
                    err.println(p);
                }
            }
        }
        return status;
    }
}
