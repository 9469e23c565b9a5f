package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import org.arflex.drcr.ComponentManagement;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.UpdateService;
import org.arflex.drcr.dto.BindingDTO;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.ParamDTO;
import org.arflex.drcr.dto.PortDTO;
import org.arflex.drcr.dto.ResourcesDTO;
import org.arflex.drcr.dto.StatsDTO;
import org.junit.jupiter.api.Test;

/** Shell output over stub services: the commands' text and the one-line JSON of {@code dto}. */
class CommandsTest {

    private final List<String> calls = new ArrayList<>();
    private final ResourcesDTO res = new ResourcesDTO();
    private StatsDTO stats;
    private final CellDTO cell = new CellDTO();

    CommandsTest() {
        res.cpus = new int[] {0, 1};
        res.cpuUtilisation = new double[] {0.05, 0.0};
        res.memoryBytes = 1 << 30;
        res.networkBps = 1000;
        InstanceDTO i = new InstanceDTO();
        i.name = "cons";
        i.state = "UNSATISFIED";
        i.targetState = "ACTIVE";
        i.failureReason = "input x: no provider \"prov\"\n";
        i.cpu = -1;
        ParamDTO p = new ParamDTO();
        p.name = "gain";
        p.type = "DOUBLE";
        p.value = "2.0";
        p.unit = "";
        p.mutable = true;
        i.params = new ParamDTO[] {p};
        i.bindings = new BindingDTO[0];
        cell.runtimeId = "t";
        cell.instances = new InstanceDTO[] {i};
        cell.contracts = new ContractDTO[0];
        BindingDTO b = new BindingDTO();
        b.consumer = "cons";
        b.input = "x";
        b.provider = "prov";
        b.output = "y";
        cell.bindings = new BindingDTO[] {b};
        cell.resources = res;
        cell.problems = new String[] {"bad.xml:3:4: [§5] name: missing"};
    }

    private final DrcrService drcr = new DrcrService() {
        @Override
        public CellDTO cell() {
            return cell;
        }

        @Override
        public Optional<InstanceDTO> instance(String name) {
            return name.equals("cons") ? Optional.of(cell.instances[0]) : Optional.empty();
        }

        @Override
        public Optional<ContractDTO> contract(String name) {
            ContractDTO c = new ContractDTO();
            c.name = name;
            c.version = "1.0.0";
            c.ports = new PortDTO[0];
            c.taskType = "PERIODIC";
            c.restart = "PERMANENT";
            c.safeOutput = "HOLD";
            return Optional.of(c);
        }

        @Override
        public String planInstall(String location) {
            return "plan install " + location;
        }

        @Override
        public String planUpdate(String name) {
            return "plan update " + name;
        }

        @Override
        public String planUninstall(String name) {
            return "plan uninstall " + name;
        }

        @Override
        public String planCapacity(List<Integer> cpus, long memoryBytes, long networkBps) {
            return "plan cpus " + cpus + " memory " + memoryBytes + " network " + networkBps;
        }
    };

    private final ResourceManager rm = new ResourceManager() {
        @Override
        public ResourcesDTO resources() {
            return res;
        }

        @Override
        public void setCpus(List<Integer> cpus) {
            calls.add("cpus " + cpus);
        }

        @Override
        public void setMemory(long bytes) {
            calls.add("memory " + bytes);
        }

        @Override
        public void setNetwork(long bps) {
            calls.add("network " + bps);
        }
    };

    private final UpdateService upd = new UpdateService() {
        @Override
        public String update(String name) {
            throw new IllegalStateException(name + ": SHA-256 mismatch");
        }

        @Override
        public void verified(byte[] jar, String sha256, String origin) {
            throw new UnsupportedOperationException();
        }
    };

    private final ComponentManagement cm = new ComponentManagement() {
        @Override
        public String name() {
            return "cons";
        }

        @Override
        public InstanceDTO instance() {
            return cell.instances[0];
        }

        @Override
        public String state() {
            return "UNSATISFIED";
        }

        @Override
        public String get(String param) {
            return "2.0";
        }

        @Override
        public String set(String param, String value) {
            if (value.equals("99")) {
                throw new IllegalArgumentException("gain: 99 is out of range [-10.0, 10.0]");
            }
            return value;
        }

        @Override
        public StatsDTO stats() {
            return stats;
        }

        @Override
        public org.arflex.drcr.dto.PortValueDTO portValue(String port) {
            if (!port.equals("y")) {
                throw new IllegalArgumentException("component 'cons' has no output port '" + port + "'");
            }
            org.arflex.drcr.dto.PortValueDTO v = new org.arflex.drcr.dto.PortValueDTO();
            v.type = "arflex.Sample";
            v.typeVersion = "1.0";
            v.method = "STATE";
            v.index = 41;
            v.published = 42;
            org.arflex.drcr.dto.PortFieldDTO seq = new org.arflex.drcr.dto.PortFieldDTO();
            seq.name = "seq";
            seq.unit = "";
            seq.scalar = "u64";
            seq.count = 1;
            seq.values = new double[] {42};
            org.arflex.drcr.dto.PortFieldDTO val = new org.arflex.drcr.dto.PortFieldDTO();
            val.name = "value";
            val.unit = "mm";
            val.scalar = "f64";
            val.count = 1;
            val.values = new double[] {-0.25};
            v.fields = new org.arflex.drcr.dto.PortFieldDTO[] {seq, val};
            return v;
        }

        @Override
        public void reset() {
            calls.add("reset");
        }
    };

    private final Commands cmd = new Commands(drcr, rm, upd, n -> n.equals("cons") ? Optional.of(cm) : Optional.empty(),
            new Commands.BundleUpdater() {
                @Override
                public String update(long id, String location, String sha256) {
                    calls.add("felix update " + id + " " + location + " " + sha256);
                    return "";
                }

                @Override
                public String deploy(String location, String sha256) {
                    calls.add("deploy " + location + " " + sha256);
                    return "Bundle ID: 9 (sha256 verified)";
                }
            });

    @Test
    void updateOfABundleIdIsFelixsUpdateThroughTheVerifiedFetch() {
        assertEquals("", cmd.update("27"));
        assertEquals("", cmd.update("27", "file:/x.jar"));
        assertEquals("", cmd.update("27", "https://h/x.jar", "ab12"));
        assertEquals(List.of("felix update 27 null null", "felix update 27 file:/x.jar null",
                "felix update 27 https://h/x.jar ab12"), calls);
        assertTrue(cmd.update().startsWith("usage:"));
    }

    @Test
    void deployTakesAUrlAndItsPinnedSha256OrNoneForASignedJar() {
        assertEquals("Bundle ID: 9 (sha256 verified)", cmd.deploy("https://h/x.jar", "ab12"));
        cmd.deploy("https://h/signed.jar");
        assertEquals(List.of("deploy https://h/x.jar ab12", "deploy https://h/signed.jar null"), calls);
        assertTrue(cmd.deploy().startsWith("usage: deploy <https-or-file-url> [<sha256>]"));
        assertTrue(cmd.deploy("a", "b", "c").startsWith("usage:"));
    }

    @Test
    void listShowsStateReasonAndProblems() {
        String out = cmd.list();
        assertTrue(out.startsWith("NAME"), out);
        assertTrue(out.contains("cons  UNSATISFIED"), out);
        assertTrue(out.contains("no provider"), out);
        assertTrue(out.contains("problem: bad.xml:3:4: [§5] name: missing"), out);
    }

    @Test
    void getSetAndErrorsAreOneLine() {
        assertEquals("2.0", cmd.get("cons", "gain"));
        assertEquals("cons.gain = 3", cmd.set("cons", "gain", "3"));
        assertEquals("error: gain: 99 is out of range [-10.0, 10.0]", cmd.set("cons", "gain", "99"));
        assertEquals("error: no component 'nope'", cmd.get("nope", "gain"));
        assertEquals("error: cons: SHA-256 mismatch", cmd.update("cons"));
        assertEquals("cons: no RT half running", cmd.stats("cons"));
    }

    @Test
    void portPrintsTheDecodedFieldsOrNamesTheMissingPort() {
        assertEquals("cons.y (arflex.Sample 1.0, state): element 41, 42 published\n  seq = 42\n  value = -0.25 mm",
                cmd.port("cons", "y"));
        assertEquals("error: component 'cons' has no output port 'z'", cmd.port("cons", "z"));
        assertEquals("error: no component 'nope'", cmd.port("nope", "y"));
    }

    @Test
    void statsShowPercentiles() {
        StatsDTO s = new StatsDTO();
        s.rtState = "RUNNING";
        s.cycles = 1000;
        s.maxLatencyNs = 250_000;
        s.latencyCount = 1000;
        s.latencyP50Ns = 400;
        s.latencyP99Ns = 1300;
        s.latencyP999Ns = 15_100;
        s.execP50Ns = 2000;
        s.execP99Ns = 2100;
        s.execP999Ns = 2200;
        s.histBinNs = 100;
        s.latencyHistOverflow = 1;
        s.latencyHistBins = new int[] {3, 12, 150};
        s.latencyHistCounts = new long[] {900, 95, 4};
        stats = s;
        String[] lines = cmd.stats("cons").split("\n");
        assertEquals(2, lines.length, String.join("|", lines));
        assertTrue(lines[0].startsWith("cons: rt RUNNING, cycles 1000,"), lines[0]);
        assertTrue(lines[0].contains("latency max 250000 ns"), lines[0]);
        assertEquals("cons: latency p50 400 ns, p99 1300 ns, p99.9 15100 ns (1000 samples, 1 >= 200 us); exec p50 2000 ns,"
                + " p99 2100 ns, p99.9 2200 ns", lines[1]);
        s.latencyHistBins = null;
        assertEquals(1, cmd.stats("cons").split("\n").length, "no percentile line when the RT half gave no histogram");
    }

    @Test
    void bindingsAndPlan() {
        assertEquals("cons.x <- prov.y", cmd.bindings());
        assertEquals("plan install file:/x.jar", cmd.plan("install", "file:/x.jar"));
        assertEquals("plan update cons", cmd.plan("update", "cons"));
        assertEquals("plan cpus [0] memory 1073741824 network 1000", cmd.plan("cpus", "0"));
        assertTrue(cmd.plan("bogus").startsWith("usage:"));
    }

    @Test
    void resourcesSetOnlyChangesWhatDiffers() {
        String out = cmd.resources("set", "cpus", "1-1", "memory", "512m");
        assertEquals(List.of("cpus [1]", "memory " + (512L << 20)), calls, out);
        assertTrue(cmd.resources().contains("cpus: 0(U=0.050) 1(U=0.000)"), cmd.resources());
        assertTrue(cmd.resources("set", "disk", "1").startsWith("error: unknown resource 'disk'"));
    }

    @Test
    void summaryAndAwaitAreCommands() throws Exception {
        assertEquals("arflex cell: 0 RT halves running", cmd.summary());
        assertEquals("{\"rtHalves\":0,\"awaitingReset\":[],\"robotSeq\":null,\"visionErrorMm\":null,\"measurement\":null,"
                + "\"correctionMrad\":null,\"trueErrorMm\":null,\"moving\":null}", cmd.summary("--json"));
        assertEquals("usage: summary [--json]", cmd.summary("--yaml"));
        assertEquals("cons UNSATISFIED (after 0.0 s)", cmd.await("cons", "UNSATISFIED", "--timeout", "0"));
        assertEquals("error: cons is UNSATISFIED, not ACTIVE, after 0 s: input x: no provider \"prov\"",
                cmd.await("cons", "--timeout", "0"));
        for (String f : Commands.FUNCTIONS) {
            assertTrue(java.util.Arrays.stream(Commands.class.getMethods()).anyMatch(m -> m.getName().equals(f)), f);
        }
    }

    @Test
    void changeWithoutActionsPrintsItsUsage() {
        String usage = "usage: change plan|apply <action>... | change progress | change history [<count>] (actions: install <component>, uninstall <component>,"
                + " set <component> <parameter> <value>, update <component> <jar URL> [<sha256>] [window <cycles>]"
                + " [shadow <cycles>] [envelope <port>.<field> <min> <max>]... [tolerance <port>.<field> <max difference>]...;"
                + " shadow: a component with a state block only when its new RT half registers a re-adopt hook"
                + " (arflex_component_readopt), else the update is refused once that half is READY: apply it with shadow 0)";
        assertEquals(usage, cmd.change());
        assertEquals(usage, cmd.change("apply"));
        assertEquals(usage, cmd.change("do", "install", "x"));
    }

    @Test
    void dtoIsOneLineOfValidJson() {
        String json = cmd.dto();
        assertFalse(json.contains("\n"), json);
        assertTrue(json.startsWith("{\"runtimeId\":\"t\","), json);
        assertTrue(json.contains("\"failureReason\":\"input x: no provider \\\"prov\\\"\\n\""), json);
        assertTrue(json.contains("\"cpus\":[0,1]"), json);
        assertTrue(json.contains("\"stats\":null"), json);
        assertTrue(json.contains("\"problems\":[\"bad.xml:3:4: [§5] name: missing\"]"), json);
    }

    @Test
    void sizesAndCpuListsParseOrNameTheMistake() {
        assertEquals(List.of(0, 2, 3, 4), Commands.parseCpus("0,2-4"));
        assertEquals(List.of(), Commands.parseCpus("none"));
        assertEquals(3L << 30, Commands.parseSize("3g"));
        assertThrows(IllegalArgumentException.class, () -> Commands.parseSize("-1"));
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> Commands.parseCpus("a,b"));
        assertTrue(e.getMessage().contains("a,b"));
    }
}
