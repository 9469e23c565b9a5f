package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;

import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.dto.PortValueDTO;
import org.junit.jupiter.api.Test;

/** arflex:summary over port values as the DRCR's port reader decodes them. */
class CellSummaryTest {

    private final List<InstanceDTO> instances = new ArrayList<>();
    private final Map<String, PortValueDTO> values = new HashMap<>();
    private final List<String> reads = new ArrayList<>();

    private CellSummary summary() {
        CellDTO c = new CellDTO();
        c.instances = instances.toArray(new InstanceDTO[0]);
        return CellSummary.of(c, (component, port) -> {
            reads.add(component + "." + port);
            return values.get(component + "." + port);
        });
    }

    private void instance(String name, long pid, boolean awaitingReset) {
        InstanceDTO i = new InstanceDTO();
        i.name = name;
        i.state = "ACTIVE";
        i.pid = pid;
        i.awaitingReset = awaitingReset;
        instances.add(i);
    }

    private static PortFieldDTO field(String name, String scalar, double... v) {
        PortFieldDTO f = new PortFieldDTO();
        f.name = name;
        f.scalar = scalar;
        f.unit = "";
        f.count = v.length;
        f.values = v;
        return f;
    }

    private void value(String port, PortFieldDTO... fields) {
        PortValueDTO v = new PortValueDTO();
        v.index = 41;
        v.published = 42;
        v.fields = fields;
        values.put(port, v);
    }

    private static final double[] Q = {0.1, -0.4, 0.3, 0.7, -0.5, 1.2};

    private void demonstrationCell(double[] qd) {
        instance("sim-robot", 101, false);
        instance("tcp-correction", 102, false);
        instance("trajectory", 103, false);
        instance("vision", 0, false);
        value("sim-robot.joint_state", field("t_ns", "i64", 5e9), field("seq", "u64", 123456), field("q", "f64", Q),
                field("qd", "f64", qd), field("tau", "f64", 0, 0, 0, 0, 0, 0));
        value("tcp-correction.error", field("seq", "u64", 17), field("t_ns", "i64", 5e9), field("value", "f64", 0.01234));
        value("tcp-correction.correction", field("seq", "u64", 17), field("t_ns", "i64", 5e9), field("value", "f64", 0.4567));
        value("trajectory.joint_ref", field("t_ns", "i64", 5e9), field("seq", "u64", 9), field("q", "f64", Q));
        double[] p = NominalArm.tcp(Q);
        value("sim-robot.truth", field("seq", "u64", 123456), field("p", "f64", p[0] + 0.00003, p[1], p[2] - 0.00004));
    }

    @Test
    void theDemonstrationCellInOneLine() {
        demonstrationCell(new double[6]);
        assertEquals("arflex cell: 3 RT halves running; robot seq 123456; vision-measured TCP error 0.0123 mm"
                + " (measurement 17); correction 0.457 mrad; TRUE TCP error 0.0500 mm (at rest)", summary().text());
    }

    @Test
    void aMovingRobotIsSaidSo() {
        demonstrationCell(new double[] {0, 0, 0.002, 0, 0, 0});
        assertEquals(Boolean.TRUE, summary().moving());
        demonstrationCell(new double[] {0, 0, -0.0009, 0, 0, 0});
        assertEquals(Boolean.FALSE, summary().moving());
    }

    @Test
    void theJsonForm() {
        demonstrationCell(new double[6]);
        instances.get(0).awaitingReset = true;
        String json = summary().json();
        assertEquals("{\"rtHalves\":3,\"awaitingReset\":[\"sim-robot\"],\"robotSeq\":123456,\"visionErrorMm\":0.01234,"
                + "\"measurement\":17,\"correctionMrad\":0.4567,\"trueErrorMm\":" + summary().trueErrorMm() + ",\"moving\":false}",
                json);
    }

    @Test
    void partsWhoseValuesAreMissingAreLeftOut() {
        instance("sim-robot", 101, true);
        instance("force-guard", 0, true);
        instance("sample-counter", 104, false);
        // published nothing yet
        PortValueDTO none = new PortValueDTO();
        none.fields = new PortFieldDTO[0];
        values.put("sim-robot.joint_state", none);
        assertEquals("arflex cell: 2 RT halves running; WAITING FOR AN OPERATOR RESET (safe mode): force-guard sim-robot"
                + " (arflex:reset <name>)", summary().text());
        assertEquals("{\"rtHalves\":2,\"awaitingReset\":[\"force-guard\",\"sim-robot\"],\"robotSeq\":null,"
                + "\"visionErrorMm\":null,\"measurement\":null,\"correctionMrad\":null,\"trueErrorMm\":null,\"moving\":null}",
                summary().json());
        // components that are not there are not asked for
        assertEquals(List.of("sim-robot.joint_state", "sim-robot.joint_state"), reads);
    }

    @Test
    void withoutTheGroundTruthNoTrueError() {
        demonstrationCell(new double[6]);
        values.remove("sim-robot.truth");
        assertEquals("arflex cell: 3 RT halves running; robot seq 123456; vision-measured TCP error 0.0123 mm"
                + " (measurement 17); correction 0.457 mrad", summary().text());
    }

    @Test
    void anEmptyCell() {
        assertEquals("arflex cell: 0 RT halves running", summary().text());
    }

    @Test
    void theNominalArm() {
        assertArrayEquals(new double[] {2.065, 0, 1.866}, NominalArm.tcp(new double[6]), 1e-12);
        assertArrayEquals(new double[] {0, 2.065, 1.866}, NominalArm.tcp(new double[] {Math.PI / 2, 0, 0, 0, 0, 0}), 1e-12);
        // the same chain evaluated by the summary script this replaced (run-cell.sh's Python)
        assertArrayEquals(new double[] {1.5311962718624592, -0.0062265735719109205, 2.1278349125901017},
                NominalArm.tcp(Q), 1e-12);
        // the cell model's `arflex-cellmodel fk` at the poses of cellmodel.copies (check_copies.py)
        double[][][] poses = {
            {{0.3, 0.2, 0.5, -0.4, 0.7, 0.1}, {1.5926070071881704, 0.35741271384316908, 0.57289829226925004}},
            {{0.1, 0.45, 0.35, 0.2, 0.7, 0.3}, {1.7414865878892865, 0.2409753721017759, 0.36914948336843223}},
            {{-1.2, -0.5, 1.1, 2.0, -1.0, 3.0}, {-0.026639994565526459, -1.0189416147140968, 0.73453142313038877}},
            {{0.2, 0.5, 0.3, 0.1, 0.8, -0.2}, {1.7108128872123145, 0.38443138081903694, 0.3384630855235203}}};
        for (double[][] p : poses) {
            assertArrayEquals(p[1], NominalArm.tcp(p[0]), 1e-12);
        }
    }
}
