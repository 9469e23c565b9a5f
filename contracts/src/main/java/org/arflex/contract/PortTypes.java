package org.arflex.contract;

import java.io.IOException;
import java.io.InputStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collection;
import java.util.EnumSet;
import java.util.HashSet;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Optional;
import java.util.Set;
import java.util.TreeMap;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import javax.xml.stream.XMLInputFactory;
import org.arflex.contract.internal.Binder;
import org.arflex.contract.internal.PortTypeXml;
import org.arflex.contract.internal.SecureXml;

/**
 * A registry of port types (spec §13). {@link #builtin()} holds the definitions shipped in this
 * bundle (contracts/types, packaged under {@code arflex/types/}); {@link #load(Path)} reads a
 * directory of definitions. Immutable and thread-safe.
 */
public final class PortTypes {
    /** Namespace of port type definitions. */
    public static final String NAMESPACE = "urn:arflex:porttype:1";
    /** Resource folder of the shipped definitions, with an {@code index.txt} naming each file. */
    public static final String RESOURCE_DIR = "/arflex/types/";

    /**
     * Reserved namespace of evaluation-only records (e.g. the simulator's eval.GroundTruth):
     * no contract port may use it and no port type definition may be named in it (SPEC 6.7).
     */
    public static final String EVAL_NAMESPACE = "eval.";

    static final Pattern TYPE_NAME = Pattern.compile("[a-z][a-z0-9]{0,15}(\\.[A-Z][A-Za-z0-9]{0,47})");
    private static final Pattern FIELD_NAME = Pattern.compile("[a-z][a-z0-9_]{0,31}");
    private static final Pattern CONST_NAME = Pattern.compile("[A-Z][A-Z0-9_]{0,47}");
    private static final Pattern VERSION = Pattern.compile("(0|[1-9][0-9]{0,4})\\.(0|[1-9][0-9]{0,4})");
    private static final Pattern UNIT = Pattern.compile("[\\p{L}\\p{N}/^*.%·_-]{0,16}");
    private static final Set<String> RESERVED = Set.of("size", "id", "name", "class", "default", "int", "long",
            "float", "double", "char", "short", "byte", "boolean", "void", "struct", "union", "static", "const",
            "register", "volatile", "auto", "signed", "unsigned", "new", "this", "super", "final", "native");

    private static volatile PortTypes builtin;

    private final Map<String, PortType> types;

    private PortTypes(Map<String, PortType> types) {
        this.types = Map.copyOf(types);
    }

    /** A registry of the given types (names must be unique). */
    public static PortTypes of(Collection<PortType> types) {
        Map<String, PortType> m = new TreeMap<>();
        for (PortType t : types) {
            if (m.put(t.name(), t) != null) {
                throw new IllegalArgumentException("port type " + t.name() + " defined twice");
            }
        }
        return new PortTypes(m);
    }

    /** The port types shipped with this bundle. Loaded once; a broken shipped definition is a build bug. */
    public static PortTypes builtin() {
        PortTypes b = builtin;
        if (b == null) {
            synchronized (PortTypes.class) {
                b = builtin;
                if (b == null) {
                    try {
                        b = loadResources();
                    } catch (ContractException | IOException e) {
                        throw new IllegalStateException("shipped port types are broken: " + e.getMessage(), e);
                    }
                    builtin = b;
                }
            }
        }
        return b;
    }

    private static PortTypes loadResources() throws IOException, ContractException {
        List<PortType> list = new ArrayList<>();
        List<Problem> problems = new ArrayList<>();
        try (InputStream idx = PortTypes.class.getResourceAsStream(RESOURCE_DIR + "index.txt")) {
            if (idx == null) {
                throw new IOException("resource " + RESOURCE_DIR + "index.txt missing from the bundle");
            }
            for (String line : new String(idx.readAllBytes(), StandardCharsets.UTF_8).split("\n")) {
                String file = line.trim();
                if (file.isEmpty() || file.startsWith("#")) {
                    continue;
                }
                try (InputStream in = PortTypes.class.getResourceAsStream(RESOURCE_DIR + file)) {
                    if (in == null) {
                        throw new IOException("resource " + RESOURCE_DIR + file + " listed in index.txt is missing");
                    }
                    PortType t = read(in, file, problems);
                    if (t != null) {
                        list.add(t);
                    }
                }
            }
        }
        if (!problems.isEmpty()) {
            throw new ContractException(problems);
        }
        return of(list);
    }

    /** Reads every {@code *.xml} in {@code dir}; throws with all problems of all files. */
    public static PortTypes load(Path dir) throws IOException, ContractException {
        List<Path> files;
        try (Stream<Path> s = Files.list(dir)) {
            files = s.filter(p -> p.getFileName().toString().endsWith(".xml")).sorted().toList();
        }
        List<Problem> problems = new ArrayList<>();
        List<PortType> list = new ArrayList<>();
        Set<String> names = new HashSet<>();
        for (Path f : files) {
            try (InputStream in = Files.newInputStream(f)) {
                String file = f.getFileName().toString();
                PortType t = read(in, file, problems);
                if (t != null && !file.equals(t.name() + ".xml")) {
                    problems.add(new Problem(file, 1, 1, "13.1", "portType/@name",
                            "file of port type " + t.name() + " must be named " + t.name() + ".xml"));
                } else if (t != null && !names.add(t.name())) {
                    problems.add(new Problem(t.source(), 1, 1, "13.1", "portType/@name",
                            "port type " + t.name() + " is defined by more than one file"));
                } else if (t != null) {
                    list.add(t);
                }
            }
        }
        if (!problems.isEmpty()) {
            throw new ContractException(problems);
        }
        return of(list);
    }

    /** Parses one definition; throws with every problem found. */
    public static PortType parse(InputStream in, String source) throws IOException, ContractException {
        List<Problem> problems = new ArrayList<>();
        PortType t = read(in, source, problems);
        if (t == null || !problems.isEmpty()) {
            throw new ContractException(problems);
        }
        return t;
    }

    /** The type of that name. */
    public Optional<PortType> find(String name) {
        return Optional.ofNullable(types.get(name));
    }

    /** Every type, sorted by name. */
    public Collection<PortType> all() {
        return new TreeMap<>(types).values();
    }

    private static PortType read(InputStream in, String source, List<Problem> problems) throws IOException {
        int before = problems.size();
        byte[] data = SecureXml.readBounded(in, source, problems);
        if (data == null) {
            return null;
        }
        XMLInputFactory f = SecureXml.newInputFactory();
        if (!SecureXml.prescan(f, data, source, NAMESPACE, "portType", "13.1", problems)) {
            return null;
        }
        PortTypeXml x = new Binder(f).bind(data, PortTypeXml.class, source, problems);
        if (x == null) {
            return null;
        }
        PortType t = freeze(x, source, problems);
        return problems.size() == before ? t : null;
    }

    private static PortType freeze(PortTypeXml x, String src, List<Problem> out) {
        Problems p = new Problems(src, out);
        for (String d : x.duplicates) {
            p.at(x, "13.1", d, "element <" + d + "> may appear only once");
        }
        String name = x.name;
        if (name == null) {
            p.at(x, "13.1", "portType/@name", "required attribute is missing");
        } else if (!TYPE_NAME.matcher(name).matches()) {
            p.at(x, "13.1", "portType/@name", "'" + name + "' is not a type name (namespace.TypeName, e.g. arflex.Pose)");
        } else if (name.startsWith(EVAL_NAMESPACE)) {
            p.at(x, "6.7", "portType/@name", "'" + name + "': the eval. namespace is reserved for evaluation-only types,"
                    + " which are not port types");
        }
        TypeVersion version = null;
        if (x.version == null) {
            p.at(x, "13.1", "portType/@version", "required attribute is missing");
        } else if (!VERSION.matcher(x.version).matches()) {
            p.at(x, "13.1", "portType/@version", "'" + x.version + "' is not MAJOR.MINOR (e.g. 1.0)");
        } else {
            version = TypeVersion.parse(x.version);
        }
        EnumSet<PortSpec.Method> methods = EnumSet.noneOf(PortSpec.Method.class);
        if (x.methods == null || x.methods.isBlank()) {
            p.at(x, "13.1", "portType/@methods", "required attribute is missing (a list of state, stream, frame)");
        } else {
            for (String m : x.methods.trim().split("\\s+")) {
                switch (m) {
                    case "state" -> methods.add(PortSpec.Method.STATE);
                    case "stream" -> methods.add(PortSpec.Method.STREAM);
                    case "frame" -> methods.add(PortSpec.Method.FRAME);
                    default -> p.at(x, "13.1", "portType/@methods", "unknown method '" + m + "' (state, stream, frame)");
                }
            }
        }
        long maxPayload = 0;
        if (methods.contains(PortSpec.Method.FRAME)) {
            if (x.maxPayload == null) {
                p.at(x, "13.1", "portType/@maxPayload", "required for a type that allows method frame");
            } else {
                Long v = Values.size(x.maxPayload);
                if (v == null || v < 1 || v > (256L << 20)) {
                    p.at(x, "13.1", "portType/@maxPayload",
                            "'" + x.maxPayload + "' is not a size between 1 B and 256MiB");
                } else {
                    maxPayload = v;
                }
            }
        } else if (x.maxPayload != null) {
            p.at(x, "13.1", "portType/@maxPayload", "only a type that allows method frame has a payload");
        }
        List<PortType.Field> fields = new ArrayList<>();
        Set<String> seen = new HashSet<>();
        int offset = 0;
        int pads = 0;
        for (PortTypeXml.Member m : x.members) {
            if (m.pad) {
                String field = "pad[" + pads + "]/@bytes";
                Integer n = m.bytes == null ? null : Values.integer(m.bytes);
                if (m.name != null || m.type != null || m.count != null || m.unit != null || m.finite != null
                        || m.min != null || m.max != null) {
                    p.at(m, "13.2", "pad[" + pads + "]", "a pad has only a bytes attribute");
                }
                if (n == null || n < 1 || n > 64) {
                    p.at(m, "13.2", field, m.bytes == null ? "required attribute is missing"
                            : "'" + m.bytes + "' is not a byte count 1..64");
                } else {
                    fields.add(new PortType.Field("_pad" + pads, PortType.Scalar.U8, n, true, offset, true, "", "",
                            PortType.Bounds.NONE));
                    offset += n;
                }
                pads++;
                continue;
            }
            String fname = m.name == null ? "?" : m.name;
            String base = "field[" + fname + "]";
            if (m.name == null) {
                p.at(m, "13.2", "field/@name", "required attribute is missing");
            } else if (!FIELD_NAME.matcher(m.name).matches() || RESERVED.contains(m.name)) {
                p.at(m, "13.2", base + "/@name", "'" + m.name
                        + "' is not a field name ([a-z][a-z0-9_]{0,31}, not a C or Java keyword or size/id/name)");
            } else if (!seen.add(m.name)) {
                p.at(m, "13.2", base + "/@name", "duplicate field name '" + m.name + "'");
            }
            if (m.bytes != null) {
                p.at(m, "13.2", base + "/@bytes", "only a pad has a bytes attribute");
            }
            PortType.Scalar scalar = scalar(m.type);
            if (scalar == null) {
                p.at(m, "13.2", base + "/@type", m.type == null ? "required attribute is missing"
                        : "'" + m.type + "' is not a scalar type (u8 u16 u32 u64 i32 i64 f32 f64)");
            }
            int count = 1;
            if (m.count != null) {
                Integer c = Values.integer(m.count);
                if (c == null || c < 1 || c > 4096) {
                    p.at(m, "13.2", base + "/@count", "'" + m.count + "' is not an array length 1..4096");
                } else {
                    count = c;
                }
            }
            String unit = m.unit == null ? "" : m.unit;
            if (!UNIT.matcher(unit).matches()) {
                p.at(m, "13.2", base + "/@unit", "'" + unit + "' is not a unit symbol (up to 16 characters, no spaces)");
            }
            if (scalar != null) {
                if (offset % scalar.size() != 0) {
                    int need = scalar.size() - offset % scalar.size();
                    p.at(m, "13.2", base, "offset " + offset + " is not a multiple of " + scalar.size()
                            + " (the alignment of " + scalar.xmlName() + "); insert <pad bytes=\"" + need
                            + "\"/> before it or reorder fields");
                }
                fields.add(new PortType.Field(fname, scalar, count, m.count != null, offset, false, unit,
                        Values.text(m.text), bounds(m, base, scalar, p)));
                offset += scalar.size() * count;
            }
        }
        if (x.members.stream().noneMatch(m -> !m.pad)) {
            p.at(x, "13.2", "portType/field", "a port type needs at least one field");
        }
        if (offset % 8 != 0) {
            p.at(x, "13.2", "portType/@size", "size " + offset + " is not a multiple of 8; add <pad bytes=\""
                    + (8 - offset % 8) + "\"/> at the end");
        }
        if (offset > 65536) {
            p.at(x, "13.2", "portType/@size", "size " + offset + " exceeds 65536 bytes");
        }
        List<PortType.Constant> constants = new ArrayList<>();
        Set<String> cnames = new HashSet<>();
        for (PortTypeXml.Const c : x.constants) {
            String base = "const[" + c.name + "]";
            if (c.name == null || !CONST_NAME.matcher(c.name).matches()) {
                p.at(c, "13.2", base + "/@name", "'" + c.name + "' is not a constant name ([A-Z][A-Z0-9_]{0,47})");
            } else if (Set.of("NAME", "ID", "SIZE", "METHODS", "MAX_PAYLOAD", "VERSION_MAJOR", "VERSION_MINOR")
                    .contains(c.name) || c.name.startsWith("OFFSET_") || c.name.endsWith("_LENGTH")) {
                p.at(c, "13.2", base + "/@name", "'" + c.name + "' clashes with a generated name");
            } else if (!cnames.add(c.name)) {
                p.at(c, "13.2", base + "/@name", "duplicate constant '" + c.name + "'");
            }
            PortType.Scalar s = scalar(c.type);
            if (s == null || s == PortType.Scalar.F32 || s == PortType.Scalar.F64) {
                p.at(c, "13.2", base + "/@type", "'" + c.type + "' is not an integer scalar type");
                continue;
            }
            Long v = c.value == null ? null : Values.longValue(c.value);
            if (v == null || !fits(s, v)) {
                p.at(c, "13.2", base + "/@value", "'" + c.value + "' is not a " + s.xmlName() + " value");
                continue;
            }
            constants.add(new PortType.Constant(c.name, s, v, Values.text(c.text)));
        }
        if (!p.clean()) {
            return null;
        }
        return new PortType(name, version, methods, fields, constants, offset, maxPayload,
                x.description == null ? "" : x.description.value.trim(), src);
    }

    /** The {@code finite}, {@code min}, {@code max} attributes of a field (§13.2), only on f32 and f64. */
    private static PortType.Bounds bounds(PortTypeXml.Member m, String base, PortType.Scalar scalar, Problems p) {
        if (m.finite == null && m.min == null && m.max == null) {
            return PortType.Bounds.NONE;
        }
        if (scalar != PortType.Scalar.F32 && scalar != PortType.Scalar.F64) {
            p.at(m, "13.2", base, "finite, min and max apply to f32 and f64 fields only");
            return PortType.Bounds.NONE;
        }
        Boolean finite = m.finite == null ? Boolean.FALSE : Values.bool(m.finite);
        if (finite == null) {
            p.at(m, "13.2", base + "/@finite", "'" + m.finite + "' is not true or false");
        }
        Double min = m.min == null ? Double.valueOf(Double.NEGATIVE_INFINITY) : Values.decimal(m.min);
        if (min == null) {
            p.at(m, "13.2", base + "/@min", "'" + m.min + "' is not a finite decimal number");
        }
        Double max = m.max == null ? Double.valueOf(Double.POSITIVE_INFINITY) : Values.decimal(m.max);
        if (max == null) {
            p.at(m, "13.2", base + "/@max", "'" + m.max + "' is not a finite decimal number");
        }
        if (finite == null || min == null || max == null) {
            return PortType.Bounds.NONE;
        }
        if (min > max) {
            p.at(m, "13.2", base + "/@min", "min " + m.min + " is greater than max " + m.max);
        }
        return new PortType.Bounds(finite, min, max);
    }

    private static boolean fits(PortType.Scalar s, long v) {
        return switch (s) {
            case U8 -> v >= 0 && v <= 0xff;
            case U16 -> v >= 0 && v <= 0xffff;
            case U32 -> v >= 0 && v <= 0xffffffffL;
            case U64, I64 -> v >= 0 || s == PortType.Scalar.I64;
            case I32 -> v >= Integer.MIN_VALUE && v <= Integer.MAX_VALUE;
            default -> false;
        };
    }

    private static PortType.Scalar scalar(String s) {
        if (s == null) {
            return null;
        }
        for (PortType.Scalar v : PortType.Scalar.values()) {
            if (v.xmlName().equals(s)) {
                return v;
            }
        }
        return null;
    }

    @Override
    public String toString() {
        return "PortTypes" + types.keySet();
    }

    static String lower(String s) {
        return s.toLowerCase(Locale.ROOT);
    }
}
