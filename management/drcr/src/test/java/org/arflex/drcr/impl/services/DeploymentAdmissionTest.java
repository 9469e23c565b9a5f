package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.Test;

/**
 * A deployment set's admission before anything is installed (D45): the planner's dry run of the
 * whole set under the change-set rules (D35) on PortFormatsTest's cell, traj -> corr -> robot.
 */
class DeploymentAdmissionTest {

    private final Planner planner = new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L));

    DeploymentAdmissionTest() throws Exception {
        planner.apply(Change.install(
                PortFormatsTest.contract("traj", "1.0.0", "motion",
                        "<out name=\"joint_ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"state\"/>"),
                PortFormatsTest.contract("corr", "1.0.0", "correction", PortFormatsTest.REF_IN + PortFormatsTest.CORRECTED),
                PortFormatsTest.contract("robot", "1.0.0", "robot", PortFormatsTest.ROBOT_IN)));
        assertEquals(3, planner.current().activeAfter().size(), planner.current()::toText);
    }

    private String admission(List<Contract> installs, List<Contract> updates) {
        Change.Builder b = Change.builder();
        installs.forEach(b::install);
        updates.forEach(b::replace);
        Plan p = planner.plan(b.build());
        return DeploymentSets.admission(p, installs, updates);
    }

    @Test
    void aNewComponentAndAnUpdateInTheSameFormatsAreAdmitted() throws Exception {
        Contract mon = PortFormatsTest.contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" "
                + "typeVersion=\"1.0\" method=\"state\"><bind component=\"corr\" port=\"corrected\"/></in>");
        Contract corr = PortFormatsTest.contract("corr", "1.0.1", "correction", PortFormatsTest.REF_IN
                + PortFormatsTest.CORRECTED);
        assertNull(admission(List.of(mon), List.of(corr)));
    }

    @Test
    void aNewComponentWithoutAProviderIsNotAdmitted() throws Exception {
        Contract mon = PortFormatsTest.contract("mon", "1.0.0", null, "<in name=\"w\" type=\"arflex.Wrench\" "
                + "typeVersion=\"1.0\" method=\"state\"/>");
        String why = admission(List.of(mon), List.of());
        assertTrue(why != null && why.startsWith("install mon: not admitted: ") && why.contains("arflex.Wrench"), why);
    }

    @Test
    void anUpdateThatWouldStopARunningConsumerIsNotAdmittedEvenPastTheFormatCheck() throws Exception {
        // what the resolver does with a format change the format check did not catch: the
        // consumer loses its provider and would stop; the set names it
        Contract corr = PortFormatsTest.contract("corr", "2.0.0", "correction", PortFormatsTest.REF_IN
                + "<out name=\"corrected\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"stream\" depth=\"8\"/>");
        String why = admission(List.of(), List.of(corr));
        assertTrue(why != null && why.startsWith("the set would stop 'robot' ("), why);
    }

    @Test
    void aComponentTheSetUninstallsMayStopAndItsConsumersMayNot() throws Exception {
        Contract mon = PortFormatsTest.contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" "
                + "typeVersion=\"1.0\" method=\"state\"><bind component=\"corr\" port=\"corrected\"/></in>");
        planner.apply(Change.install(mon));
        Plan p = planner.plan(Change.builder().uninstall("mon").build());
        assertNull(DeploymentSets.admission(p, List.of(), List.of(), java.util.Set.of("mon")));
        assertTrue(DeploymentSets.admission(p, List.of(), List.of()).startsWith("the set would stop 'mon'"),
                "without the uninstall named, the stop is refused");
        // uninstalling corr would stop robot (and mon), which the set does not name
        Plan q = planner.plan(Change.builder().uninstall("corr").build());
        String why = DeploymentSets.admission(q, List.of(), List.of(), java.util.Set.of("corr"));
        assertTrue(why != null && why.contains("the set would stop 'robot'") && !why.contains("stop 'corr'"), why);
    }
}
