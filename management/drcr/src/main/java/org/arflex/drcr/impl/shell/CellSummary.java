package org.arflex.drcr.impl.shell;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.dto.PortValueDTO;

/**
 * The one-line summary of the demonstration cell ({@code arflex:summary}): RT halves running,
 * the components waiting for an operator reset, the robot's cycles, the vision-measured TCP
 * error and the correction, and in an evaluation run the TRUE TCP error (the true TCP from the
 * simulator's ground truth against the nominal model at the program's reference). Each part is
 * left out while its component or value is missing. Values come from the DRCR's port reader
 * ({@link PortValueDTO}), fields by name.
 *
 * @param rtHalves       instances whose RT half runs
 * @param awaitingReset  instances waiting for an operator reset (safe mode)
 * @param robotSeq       the robot's joint state sequence number, or null
 * @param visionErrorMm  the vision-measured TCP error (mm), or null
 * @param measurement    the sequence number of that measurement, or null
 * @param correctionMrad the norm of the applied correction (mrad), or null
 * @param trueErrorMm    the TRUE TCP error (mm), or null
 * @param moving         whether the robot moves (largest joint speed above 1 mrad/s), or null
 */
public record CellSummary(int rtHalves, List<String> awaitingReset, Long robotSeq, Double visionErrorMm, Long measurement,
        Double correctionMrad, Double trueErrorMm, Boolean moving) {

    /** The robot, the reference stage and the motion source of the demonstration cell (conf/cell.gosh). */
    static final String ROBOT = "sim-robot";
    static final String CORRECTION = "tcp-correction";
    static final String MOTION = "trajectory";
    /** Faster than this (rad/s) on any joint, the robot moves. */
    static final double MOVING = 1e-3;

    public CellSummary {
        awaitingReset = List.copyOf(awaitingReset);
    }

    /** Reads ports; null when the component, the port or a value is not there. */
    @FunctionalInterface
    public interface Ports {
        PortValueDTO read(String component, String port);
    }

    /** The summary of {@code cell}, its port values read through {@code ports}. */
    public static CellSummary of(CellDTO cell, Ports ports) {
        int halves = 0;
        List<String> waiting = new ArrayList<>();
        List<String> names = new ArrayList<>();
        for (InstanceDTO i : cell.instances) {
            names.add(i.name);
            halves += i.pid != 0 ? 1 : 0;
            if (i.awaitingReset) {
                waiting.add(i.name);
            }
        }
        waiting.sort(null);
        PortValueDTO joints = names.contains(ROBOT) ? ports.read(ROBOT, "joint_state") : null;
        PortValueDTO error = names.contains(CORRECTION) ? ports.read(CORRECTION, "error") : null;
        PortValueDTO corr = names.contains(CORRECTION) ? ports.read(CORRECTION, "correction") : null;
        PortValueDTO ref = names.contains(MOTION) ? ports.read(MOTION, "joint_ref") : null;
        PortValueDTO truth = names.contains(ROBOT) && ref != null && joints != null ? ports.read(ROBOT, "truth") : null;
        Double trueError = null;
        Boolean moving = null;
        double[] q = values(ref, "q");
        double[] p = values(truth, "p");
        double[] qd = values(joints, "qd");
        if (q != null && q.length == 6 && p != null && p.length == 3 && qd != null) {
            trueError = 1e3 * distance(p, NominalArm.tcp(q));
            double fastest = 0;
            for (double v : qd) {
                fastest = Math.max(fastest, Math.abs(v));
            }
            moving = fastest > MOVING;
        }
        return new CellSummary(halves, waiting, whole(joints, "seq"), scalar(error, "value"), whole(error, "seq"),
                scalar(corr, "value"), trueError, moving);
    }

    /** The line {@code arflex:summary} prints. */
    public String text() {
        List<String> parts = new ArrayList<>();
        parts.add(rtHalves + " RT halves running");
        if (!awaitingReset.isEmpty()) {
            parts.add("WAITING FOR AN OPERATOR RESET (safe mode): " + String.join(" ", awaitingReset) + " (arflex:reset <name>)");
        }
        if (robotSeq != null) {
            parts.add("robot seq " + robotSeq);
        }
        if (visionErrorMm != null) {
            parts.add(String.format(Locale.ROOT, "vision-measured TCP error %.4f mm (measurement %d)", visionErrorMm,
                    measurement));
        }
        if (correctionMrad != null) {
            parts.add(String.format(Locale.ROOT, "correction %.3f mrad", correctionMrad));
        }
        if (trueErrorMm != null) {
            parts.add(String.format(Locale.ROOT, "TRUE TCP error %.4f mm (%s)", trueErrorMm, moving ? "moving" : "at rest"));
        }
        return "arflex cell: " + String.join("; ", parts);
    }

    /** The same as one line of JSON ({@code arflex:summary --json}); missing values are null. */
    public String json() {
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("rtHalves", rtHalves);
        m.put("awaitingReset", awaitingReset);
        m.put("robotSeq", robotSeq);
        m.put("visionErrorMm", visionErrorMm);
        m.put("measurement", measurement);
        m.put("correctionMrad", correctionMrad);
        m.put("trueErrorMm", trueErrorMm);
        m.put("moving", moving);
        return Json.write(m);
    }

    private static double[] values(PortValueDTO v, String field) {
        if (v == null || v.index < 0 || v.fields == null) {
            return null;
        }
        for (PortFieldDTO f : v.fields) {
            if (f.name.equals(field)) {
                return f.values;
            }
        }
        return null;
    }

    private static Double scalar(PortValueDTO v, String field) {
        double[] d = values(v, field);
        return d == null || d.length == 0 ? null : d[0];
    }

    private static Long whole(PortValueDTO v, String field) {
        Double d = scalar(v, field);
        return d == null ? null : (long) (double) d;
    }

    private static double distance(double[] a, double[] b) {
        double dx = a[0] - b[0];
        double dy = a[1] - b[1];
        double dz = a[2] - b[2];
        return Math.sqrt(dx * dx + dy * dy + dz * dz);
    }
}
