package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;
import java.util.Set;
import java.util.TreeSet;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * The set of component bundles has one source, {@code bundles/} (docs/DECISIONS.md D34): this
 * unit test (surefire, the tests module's test phase, after the runtime is assembled) fails
 * when a component folder is missing from {@code bundles/pom.xml}'s modules or dependencies,
 * when the assembled runtime does not carry every component, when it carries a stale one, or
 * when {@code conf/cell.gosh} starts a jar the assembly does not have.
 */
class ComponentSetTest {

    static final Path ROOT = Components.root();
    static final Path BUNDLES_POM = ROOT.resolve("bundles/pom.xml");
    static final Path RUNTIME_POM = ROOT.resolve("management/runtime/pom.xml");

    static List<String> artifactIds() {
        return Components.folders().stream().map(Components::artifactId).toList();
    }

    /** The dependencies' artifactIds of a pom's own {@code <dependencies>} (not dependencyManagement). */
    static List<String> dependencyIds(String pom) {
        String s = Components.afterParent(pom).replaceAll("(?s)<dependencyManagement>.*?</dependencyManagement>", "");
        List<String> out = new ArrayList<>();
        Matcher deps = Pattern.compile("(?s)<dependencies>(.*?)</dependencies>").matcher(s);
        while (deps.find()) {
            Matcher d = Pattern.compile("(?s)<dependency>(.*?)</dependency>").matcher(deps.group(1));
            while (d.find()) {
                String head = d.group(1).replaceAll("(?s)<exclusions>.*?</exclusions>", "");
                out.addAll(Components.all(head, "artifactId"));
            }
        }
        return out;
    }

    static List<String> property(String pom, String name) {
        List<String> v = Components.all(pom.replaceAll("(?s)<!--.*?-->", ""), name);
        assertEquals(1, v.size(), "property " + name + " in " + RUNTIME_POM);
        return Arrays.stream(v.get(0).split(",")).map(String::trim).filter(x -> !x.isEmpty()).toList();
    }

    @Test
    void everyFolderIsAModuleAndADependencyOfBundlesPom() {
        String pom = Components.read(BUNDLES_POM);
        List<String> folders = Components.folders();
        assertFalse(folders.isEmpty(), "no component folder in " + ROOT.resolve("bundles"));
        List<String> modules = Components.all(pom.replaceAll("(?s)<!--.*?-->", ""), "module");
        assertEquals(new TreeSet<>(folders), new TreeSet<>(modules),
                BUNDLES_POM + ": <module> lines and the folders of bundles/ with a pom.xml differ");
        assertEquals(modules.size(), new TreeSet<>(modules).size(), "a module listed twice: " + modules);
        // the same components, in the same order: module i is dependency i
        List<String> expected = modules.stream().map(Components::artifactId).toList();
        assertEquals(expected, dependencyIds(pom), BUNDLES_POM
                + ": its <dependencies> must be its modules' artifactIds, in the order of <modules>");
    }

    @Test
    void runtimeAndTestsNameNoComponentBundleThemselves() {
        Set<String> ids = new TreeSet<>(artifactIds());
        String runtime = Components.read(RUNTIME_POM);
        List<String> deps = dependencyIds(runtime);
        assertTrue(deps.contains("arflex-bundles"), RUNTIME_POM + " must depend on arflex-bundles: " + deps);
        assertTrue(Pattern.compile("(?s)<artifactId>arflex-bundles</artifactId>\\s*<version>[^<]*</version>\\s*"
                + "<type>pom</type>\\s*<scope>provided</scope>").matcher(runtime).find(),
                "arflex-bundles must be a provided pom dependency (provided keeps the components out of bundle/)");
        for (String d : deps) {
            assertFalse(ids.contains(d), RUNTIME_POM + " names component " + d + " itself");
        }
        for (String d : dependencyIds(Components.read(ROOT.resolve("tests/pom.xml")))) {
            assertFalse(ids.contains(d), "tests/pom.xml names component " + d + " itself");
        }
        // the runtime's exceptions name existing components only (a renamed one would be deployed)
        for (String p : List.of("arflex.tool.bundles", "arflex.undeployed.bundles")) {
            for (String id : property(runtime, p)) {
                assertTrue(ids.contains(id), p + " names " + id + ", which is no component of bundles/: " + ids);
            }
        }
    }

    @Test
    void theAssemblyCarriesEveryComponentAsBuilt() throws IOException {
        Path assembly = Path.of(System.getProperty("arflex.it.runtime",
                ROOT.resolve("management/runtime/target/arflex-runtime").toString()));
        assertTrue(Files.isDirectory(assembly.resolve("cell")), "no assembled runtime at " + assembly
                + " (mvn -pl management/runtime -am package)");
        String runtime = Components.read(RUNTIME_POM);
        Set<String> tools = new TreeSet<>(property(runtime, "arflex.tool.bundles"));
        Set<String> undeployed = new TreeSet<>(property(runtime, "arflex.undeployed.bundles"));
        Set<String> cellWanted = new TreeSet<>();
        for (String folder : Components.folders()) {
            String id = Components.artifactId(folder);
            Path built = Components.jar(folder);
            assertTrue(Files.isRegularFile(built), "component " + folder + " not built: " + built);
            if (undeployed.contains(id)) {
                continue;
            }
            Path shipped = assembly.resolve(tools.contains(id) ? "tools" : "cell").resolve(id + ".jar");
            assertTrue(Files.isRegularFile(shipped), "component " + folder + " (" + id + ") missing from the assembly: " + shipped);
            assertArrayEquals(Files.readAllBytes(built), Files.readAllBytes(shipped),
                    shipped + " is not the jar built in " + built);
            if (!tools.contains(id)) {
                cellWanted.add(id + ".jar");
            }
        }
        assertEquals(cellWanted, names(assembly.resolve("cell")), "cell/ holds exactly the cell's components");
        assertEquals(new TreeSet<>(tools.stream().map(t -> t + ".jar").toList()), names(assembly.resolve("tools")),
                "tools/ holds exactly the tool components");
        // no component in the run set started at launch (bundle/) or among the console's bundles
        Set<String> ids = new TreeSet<>(artifactIds());
        for (String dir : List.of("bundle", "console")) {
            for (String jar : names(assembly.resolve(dir))) {
                for (String id : ids) {
                    assertFalse(jar.startsWith(id + "-") || jar.equals(id + ".jar"), "component " + id + " in " + dir + "/: " + jar);
                }
            }
        }
    }

    @Test
    void theCellScriptStartsOnlyJarsOfTheAssembly() {
        String gosh = Components.read(ROOT.resolve("management/runtime/src/main/dist/conf/cell.gosh"));
        Matcher m = Pattern.compile("(?m)^start file:@CELL@/([^\\s]+)$").matcher(gosh);
        List<String> started = new ArrayList<>();
        while (m.find()) {
            started.add(m.group(1));
        }
        assertFalse(started.isEmpty(), "cell.gosh starts nothing");
        String runtime = Components.read(RUNTIME_POM);
        Set<String> notInCell = new TreeSet<>(property(runtime, "arflex.tool.bundles"));
        notInCell.addAll(property(runtime, "arflex.undeployed.bundles"));
        Set<String> cell = new TreeSet<>();
        for (String id : artifactIds()) {
            if (!notInCell.contains(id)) {
                cell.add(id + ".jar");
            }
        }
        for (String jar : started) {
            assertTrue(cell.contains(jar), "cell.gosh starts " + jar + ", which cell/ does not hold: " + cell);
        }
    }

    static Set<String> names(Path dir) throws IOException {
        try (Stream<Path> s = Files.list(dir)) {
            return new TreeSet<>(s.map(p -> p.getFileName().toString()).toList());
        }
    }
}
