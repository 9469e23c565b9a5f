package org.arflex.planner;

import java.nio.file.Path;
import org.arflex.apicheck.ApiBaseline;
import org.junit.jupiter.api.Test;

/** The packages this bundle exports match api-baseline.txt, or carry the version bump their change needs. */
class ApiBaselineTest {

    @Test
    void exportedPackagesAreVersionedAgainstTheBaseline() throws Exception {
        ApiBaseline.verify(Path.of("target/classes"), Path.of("api-baseline.txt"));
    }
}
