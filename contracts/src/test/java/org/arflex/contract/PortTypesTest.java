package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import java.io.ByteArrayInputStream;
import java.io.File;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.concurrent.TimeUnit;
import org.arflex.contract.internal.PortTypeGenerator;
import org.arflex.contract.types.ImageFrameLayout;
import org.arflex.contract.types.JointStateLayout;
import org.arflex.contract.types.PoseLayout;
import org.arflex.contract.types.SampleLayout;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

class PortTypesTest {
    /** Surefire runs in the module directory. */
    private static final Path MODULE = Path.of("").toAbsolutePath();

    @Test
    void generatedHeadersAndAccessorsAreUpToDate() throws Exception {
        PortTypes types = PortTypes.load(MODULE.resolve("types"));
        Map<String, String> expected = PortTypeGenerator.generate(types);
        List<String> differ = new ArrayList<>();
        for (Map.Entry<String, String> e : expected.entrySet()) {
            Path p = MODULE.resolve(e.getKey());
            if (!Files.exists(p) || !Files.readString(p, StandardCharsets.UTF_8).equals(e.getValue())) {
                differ.add(e.getKey());
            }
        }
        differ.addAll(PortTypeGenerator.stale(MODULE, expected));
        if (!differ.isEmpty()) {
            fail("generated port type files are out of date: " + differ + "\nregenerate with:\n  "
                    + PortTypeGenerator.COMMAND);
        }
    }

    @Test
    void shippedTypesAreTheDefinitionsInTheTree() throws Exception {
        PortTypes fromDir = PortTypes.load(MODULE.resolve("types"));
        assertEquals(fromDir.all().stream().map(PortType::name).toList(),
                PortTypes.builtin().all().stream().map(PortType::name).toList());
        for (PortType t : fromDir.all()) {
            PortType b = PortTypes.builtin().find(t.name()).orElseThrow();
            assertEquals(t.fields(), b.fields());
            assertEquals(t.version(), b.version());
        }
    }

    @Test
    void requiredTypesHaveTheSpecifiedLayouts() {
        PortTypes t = PortTypes.builtin();
        assertEquals(24, t.find("arflex.Sample").orElseThrow().size());
        assertEquals(160, t.find("arflex.JointState").orElseThrow().size());
        assertEquals(64, t.find("arflex.JointRef").orElseThrow().size());
        assertEquals(64, t.find("arflex.Wrench").orElseThrow().size());
        assertEquals(128, t.find("arflex.Pose").orElseThrow().size());
        assertEquals(40, t.find("arflex.ImageFrame").orElseThrow().size());
        assertEquals(Set.of(PortSpec.Method.FRAME), t.find("arflex.ImageFrame").orElseThrow().methods());
        assertTrue(t.find("arflex.SafetyState").isPresent());
        assertTrue(t.find("arflex.ToolState").isPresent());
        assertEquals(120, t.find("arflex.Pose").orElseThrow().field("valid").orElseThrow().offset());
        assertEquals(PoseLayout.OFFSET_N_VIEWS, t.find("arflex.Pose").orElseThrow().field("n_views").orElseThrow().offset());
    }

    @Test
    void typeIdIsFnv1a64OfTheNameAsRtCoreHashesIt() {
        assertEquals(0xcbf29ce484222325L, PortType.fnv1a64(""));
        assertEquals(0xaf63dc4c8601ec8cL, PortType.fnv1a64("a"));
        assertEquals(PortType.fnv1a64("arflex.Sample"), PortTypes.builtin().find("arflex.Sample").orElseThrow().id());
        assertEquals(SampleLayout.ID, PortType.fnv1a64("arflex.Sample"));
    }

    @Test
    void accessorsWriteLittleEndianAtTheDeclaredOffsetsWhateverTheBufferOrder() {
        for (ByteOrder order : List.of(ByteOrder.BIG_ENDIAN, ByteOrder.LITTLE_ENDIAN)) {
            ByteBuffer b = ByteBuffer.allocateDirect(8 + JointStateLayout.SIZE).order(order);
            int at = 8;
            JointStateLayout.seq(b, at, 42);
            JointStateLayout.t_ns(b, at, -7);
            for (int i = 0; i < JointStateLayout.TAU_LENGTH; i++) {
                JointStateLayout.tau(b, at, i, i + 0.5);
            }
            ByteBuffer le = b.duplicate().order(ByteOrder.LITTLE_ENDIAN);
            assertEquals(42, le.getLong(at + 8));
            assertEquals(-7, le.getLong(at));
            assertEquals(5.5, le.getDouble(at + 112 + 5 * 8));
            assertEquals(42, JointStateLayout.seq(b, at));
            assertEquals(2.5, JointStateLayout.tau(b, at, 2));
            assertThrows(IndexOutOfBoundsException.class, () -> JointStateLayout.tau(b, at, 6));
        }
        ByteBuffer f = ByteBuffer.allocate(ImageFrameLayout.SIZE);
        ImageFrameLayout.width(f, 0, 0xfffffff0L);
        assertEquals(0xfffffff0L, ImageFrameLayout.width(f, 0));
        assertEquals(0xf0, f.get(ImageFrameLayout.OFFSET_WIDTH) & 0xff);
    }

    @Test
    void generatedHeadersCompileAsC11AndCxx17WithStaticAsserts(@TempDir Path tmp) throws Exception {
        for (String[] cc : List.of(new String[] {"gcc", "-std=c11", "t.c"}, new String[] {"g++", "-std=c++17", "t.cpp"})) {
            // the native build needs both compilers: a machine without one is not one to test on (D82)
            assertTrue(onPath(cc[0]), cc[0] + " not on PATH (scripts/setup.sh installs build-essential)");
            Path src = tmp.resolve(cc[2]);
            Files.writeString(src, "#include <arflex_types/all.h>\nint main(void) { return (int) sizeof(struct "
                    + "arflex_pose) - ARFLEX_TYPE_POSE_SIZE; }\n");
            Process p = new ProcessBuilder(cc[0], cc[1], "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-fsyntax-only",
                    "-I", MODULE.resolve("include").toString(), src.toString()).redirectErrorStream(true).start();
            if (!p.waitFor(60, TimeUnit.SECONDS)) {
                p.destroyForcibly();
                fail(cc[0] + " did not finish within 60 s");
            }
            String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
            assertEquals(0, p.exitValue(), cc[0] + " rejected the generated headers:\n" + out);
        }
    }

    private static boolean onPath(String exe) {
        for (String d : System.getenv().getOrDefault("PATH", "").split(File.pathSeparator)) {
            if (Files.isExecutable(Path.of(d, exe))) {
                return true;
            }
        }
        return false;
    }

    private static List<Problem> problems(String xml) throws Exception {
        ContractException e = assertThrows(ContractException.class,
                () -> PortTypes.parse(new ByteArrayInputStream(xml.getBytes(StandardCharsets.UTF_8)), "t.xml"));
        return e.problems();
    }

    private static String type(String body) {
        return "<portType xmlns=\"urn:arflex:porttype:1\" name=\"arflex.T\" version=\"1.0\" methods=\"state\">" + body
                + "</portType>";
    }

    @Test
    void misalignedFieldIsRefusedWithTheFix() throws Exception {
        List<Problem> p = problems(type("<field name=\"a\" type=\"u32\"/><field name=\"b\" type=\"f64\"/>"));
        assertEquals("13.2", p.get(0).section());
        assertEquals("field[b]", p.get(0).field());
        assertTrue(p.get(0).message().contains("<pad bytes=\"4\"/>"), p.get(0).message());
    }

    @Test
    void sizeMustBeAMultipleOfEight() throws Exception {
        List<Problem> p = problems(type("<field name=\"a\" type=\"u32\"/>"));
        assertEquals("portType/@size", p.get(0).field());
        PortType ok = PortTypes.parse(new ByteArrayInputStream(type("<field name=\"a\" type=\"u32\"/><pad bytes=\"4\"/>")
                .getBytes(StandardCharsets.UTF_8)), "t.xml");
        assertEquals(8, ok.size());
        assertTrue(ok.fields().get(1).padding());
    }

    @Test
    void badTypeDefinitionsReportEveryProblem() throws Exception {
        List<Problem> p = problems("<portType xmlns=\"urn:arflex:porttype:1\" name=\"Bad\" version=\"1\" methods=\"push\">"
                + "<field name=\"x\" type=\"u128\"/><field name=\"x\" type=\"u8\" count=\"0\"/></portType>");
        List<String> fields = p.stream().map(Problem::field).toList();
        assertTrue(fields.containsAll(List.of("portType/@name", "portType/@version", "portType/@methods",
                "field[x]/@type", "field[x]/@name", "field[x]/@count")), fields.toString());
    }

    @Test
    void evalNamespaceIsReservedForEvaluationOnlyRecords() throws Exception {
        List<Problem> p = problems("<portType xmlns=\"urn:arflex:porttype:1\" name=\"eval.GroundTruth\" version=\"1.0\" "
                + "methods=\"state\"><field name=\"a\" type=\"u64\"/></portType>");
        assertEquals(1, p.size(), p.toString());
        assertEquals("6.7", p.get(0).section());
        assertEquals("portType/@name", p.get(0).field());
        assertTrue(p.get(0).message().contains("reserved for evaluation-only types"), p.get(0).message());
    }

    @Test
    void frameTypesNeedAPayloadBound() throws Exception {
        List<Problem> p = problems("<portType xmlns=\"urn:arflex:porttype:1\" name=\"arflex.F\" version=\"1.0\" "
                + "methods=\"frame\"><field name=\"a\" type=\"u64\"/></portType>");
        assertEquals("portType/@maxPayload", p.get(0).field());
    }

    @Test
    void fileNameMustMatchTypeName(@TempDir Path dir) throws Exception {
        Files.writeString(dir.resolve("wrong.xml"), type("<field name=\"a\" type=\"u64\"/>"));
        ContractException e = assertThrows(ContractException.class, () -> PortTypes.load(dir));
        assertTrue(e.getMessage().contains("must be named arflex.T.xml"), e.getMessage());
    }

    @Test
    void floatFieldsDeclareFinitenessAndRangesThatTheJavaSideChecks() throws Exception {
        PortType s = PortTypes.builtin().find("arflex.SafetyState").orElseThrow();
        PortType.Bounds b = s.field("power_scale").orElseThrow().bounds();
        assertEquals(new PortType.Bounds(true, 0, 1), b);
        assertEquals("finite, 0..1", b.toString());
        assertTrue(b.accepts(0.5) && !b.accepts(Double.NaN) && !b.accepts(1.5) && !b.accepts(-0.1));
        assertEquals(PortType.Bounds.NONE, PortTypes.builtin().find("arflex.Pose").orElseThrow().field("p").orElseThrow().bounds());
        for (String[] f : List.of(new String[] {"arflex.JointRef", "q"}, new String[] {"arflex.Sample", "value"},
                new String[] {"arflex.Wrench", "force"}, new String[] {"arflex.Wrench", "torque"},
                new String[] {"arflex.JointState", "q"}, new String[] {"arflex.JointState", "qd"},
                new String[] {"arflex.JointState", "tau"})) {
            PortType.Bounds fb = PortTypes.builtin().find(f[0]).orElseThrow().field(f[1]).orElseThrow().bounds();
            assertEquals(new PortType.Bounds(true, Double.NEGATIVE_INFINITY, Double.POSITIVE_INFINITY), fb,
                    f[0] + "." + f[1]);
        }
        PortType js = PortTypes.builtin().find("arflex.JointState").orElseThrow();
        ByteBuffer v = ByteBuffer.allocate(js.size() + 8);
        assertEquals(List.of(), js.violations(v, 8));
        JointStateLayout.qd(v, 8, 2, Double.POSITIVE_INFINITY);
        JointStateLayout.tau(v, 8, 5, Double.NaN);
        assertEquals(List.of("qd[2] = Infinity, not finite", "tau[5] = NaN, not finite"), js.violations(v, 8));
    }

    @Test
    void generatedHeaderValidatesTheDeclaredBounds() {
        String h = PortTypeGenerator.generate(PortTypes.builtin()).get("include/arflex_types/safety_state.h");
        assertTrue(h.contains("static inline bool arflex_safety_state_valid(const struct arflex_safety_state *v)\n{\n"
                + "\tif (!(isfinite(v->power_scale) && v->power_scale >= 0.0 && v->power_scale <= 1.0))\n"
                + "\t\treturn false;\n\tif (!(isfinite(v->force_norm) && v->force_norm >= 0.0))\n"), h);
        String pose = PortTypeGenerator.generate(PortTypes.builtin()).get("include/arflex_types/pose.h");
        assertTrue(pose.contains("arflex_pose_valid(const struct arflex_pose *v)\n{\n\t(void)v;\n\treturn true;"), pose);
    }

    @Test
    void boundsApplyToFloatFieldsOnlyAndMustBeNumbers() throws Exception {
        List<Problem> p = problems(type("<field name=\"a\" type=\"u64\" finite=\"true\"/>"
                + "<field name=\"b\" type=\"f64\" finite=\"yes\" min=\"NaN\" max=\"x\"/>"
                + "<field name=\"c\" type=\"f64\" min=\"2\" max=\"1\"/><pad bytes=\"8\" finite=\"true\"/>"));
        List<String> fields = p.stream().map(Problem::field).toList();
        assertEquals(List.of("field[a]", "field[b]/@finite", "field[b]/@min", "field[b]/@max", "field[c]/@min",
                "pad[0]"), fields, p.toString());
        PortType ok = PortTypes.parse(new ByteArrayInputStream(type("<field name=\"a\" type=\"f32\" count=\"2\" "
                + "min=\"-1.5\"/>").getBytes(StandardCharsets.UTF_8)), "t.xml");
        assertEquals(new PortType.Bounds(false, -1.5, Double.POSITIVE_INFINITY), ok.fields().get(0).bounds());
        assertTrue(PortTypeGenerator.generate(PortTypes.of(List.of(ok))).get("include/arflex_types/t.h")
                .contains("\tfor (size_t i = 0; i < 2u; i++)\n\t\tif (!(v->a[i] >= -1.5f))\n"));
    }
}
