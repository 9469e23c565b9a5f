package org.arflex.contract.internal;

import com.fasterxml.jackson.annotation.JsonAutoDetect;
import com.fasterxml.jackson.annotation.PropertyAccessor;
import com.fasterxml.jackson.core.JsonLocation;
import com.fasterxml.jackson.core.JsonParser;
import com.fasterxml.jackson.core.JsonStreamContext;
import com.fasterxml.jackson.core.JsonToken;
import com.fasterxml.jackson.databind.BeanDescription;
import com.fasterxml.jackson.databind.DeserializationConfig;
import com.fasterxml.jackson.databind.DeserializationContext;
import com.fasterxml.jackson.databind.DeserializationFeature;
import com.fasterxml.jackson.databind.JsonDeserializer;
import com.fasterxml.jackson.databind.JsonMappingException;
import com.fasterxml.jackson.databind.deser.BeanDeserializerModifier;
import com.fasterxml.jackson.databind.deser.DeserializationProblemHandler;
import com.fasterxml.jackson.databind.deser.std.DelegatingDeserializer;
import com.fasterxml.jackson.databind.deser.std.StdDeserializer;
import com.fasterxml.jackson.databind.module.SimpleModule;
import com.fasterxml.jackson.dataformat.xml.XmlFactory;
import com.fasterxml.jackson.dataformat.xml.XmlMapper;
import java.io.IOException;
import java.util.ArrayList;
import java.util.List;
import javax.xml.stream.XMLInputFactory;
import org.arflex.contract.Problem;

/**
 * Jackson XML data binding of a (prescanned) document into a mutable binding model such as
 * {@link ContractXml}, on the hardened factory of {@link SecureXml}.
 *
 * <p>Only members annotated for XML are bound (auto-detection is off), so a stray attribute
 * never lands in an internal field. Unknown elements and attributes do not stop binding: they
 * are recorded as §2.4 problems and skipped, so that one pass reports them all. Each model node
 * records the line and column of its start tag.
 */
public final class Binder {
    private static final String PROBLEMS = "arflex.problems";
    private static final String SOURCE = "arflex.source";

    private final XmlMapper mapper;

    /** A binder over {@code inputFactory} (which must be a hardened one from {@link SecureXml}). */
    public Binder(XMLInputFactory inputFactory) {
        XmlFactory factory = XmlFactory.builder().xmlInputFactory(inputFactory)
                .xmlOutputFactory(SecureXml.newOutputFactory()).build();
        XmlMapper m = new XmlMapper(factory);
        m.setVisibility(PropertyAccessor.ALL, JsonAutoDetect.Visibility.NONE);
        m.enable(DeserializationFeature.FAIL_ON_UNKNOWN_PROPERTIES);
        SimpleModule module = new SimpleModule("arflex-locations");
        module.addDeserializer(Text.class, new TextDeserializer());
        module.setDeserializerModifier(new BeanDeserializerModifier() {
            @Override
            public JsonDeserializer<?> modifyDeserializer(DeserializationConfig config, BeanDescription desc,
                    JsonDeserializer<?> deserializer) {
                return Located.class.isAssignableFrom(desc.getBeanClass()) ? new Locating(deserializer) : deserializer;
            }
        });
        m.registerModule(module);
        m.addHandler(new DeserializationProblemHandler() {
            @Override
            public boolean handleUnknownProperty(DeserializationContext ctxt, JsonParser p,
                    JsonDeserializer<?> deserializer, Object beanOrClass, String propertyName) throws IOException {
                JsonLocation loc = p.currentTokenLocation();
                JsonStreamContext ctx = p.getParsingContext();
                JsonStreamContext parent = ctx == null ? null : ctx.getParent();
                String owner = parent != null && parent.getCurrentName() != null ? parent.getCurrentName()
                        : beanOrClass instanceof Located l ? elementName(l) : "element";
                String msg = propertyName.isEmpty()
                        ? "text is not allowed inside <" + owner + ">"
                        : "unknown element or attribute '" + propertyName + "' in <" + owner + ">";
                problems(ctxt).add(new Problem((String) ctxt.getAttribute(SOURCE), loc.getLineNr(),
                        loc.getColumnNr(), "2.4", owner + "/" + (propertyName.isEmpty() ? "text()" : propertyName),
                        msg));
                p.skipChildren();
                return true;
            }
        });
        this.mapper = m;
    }

    /**
     * Binds {@code data} to {@code type}; on a binding failure adds a problem and returns null.
     * Non-fatal problems (unknown names) are added too, and the model is still returned.
     */
    public <T> T bind(byte[] data, Class<T> type, String source, List<Problem> problems) {
        try {
            return mapper.readerFor(type).withAttribute(PROBLEMS, problems).withAttribute(SOURCE, source)
                    .readValue(data);
        } catch (JsonMappingException e) {
            if (XmlFailure.fromParser(e)) {
                // data binding wrapped a parser failure: report it as the parser's (§2.1)
                problems.add(XmlFailure.problem(e, source, null));
                return null;
            }
            JsonLocation loc = e.getLocation();
            problems.add(new Problem(source, loc == null ? 0 : loc.getLineNr(), loc == null ? 0 : loc.getColumnNr(),
                    "2.4", path(e), "cannot bind: " + e.getOriginalMessage()));
            return null;
        } catch (IOException | RuntimeException e) {
            // RuntimeException: Woodstox's unchecked WstxLazyException (an error found while
            // text is read lazily) and limits' IllegalArgumentException (issue 16)
            problems.add(XmlFailure.problem(e, source, null));
            return null;
        }
    }

    @SuppressWarnings("unchecked")
    private static List<Problem> problems(DeserializationContext ctxt) {
        Object o = ctxt.getAttribute(PROBLEMS);
        return o == null ? new ArrayList<>() : (List<Problem>) o;
    }

    private static String path(JsonMappingException e) {
        StringBuilder b = new StringBuilder();
        for (JsonMappingException.Reference r : e.getPath()) {
            if (r.getFieldName() != null) {
                b.append(b.length() == 0 ? "" : "/").append(r.getFieldName());
            }
        }
        return b.length() == 0 ? "(document)" : b.toString();
    }

    static String elementName(Located l) {
        if (l instanceof ContractXml) {
            return "component";
        }
        if (l instanceof ContractXml.Port p) {
            return p.out ? "out" : "in";
        }
        if (l instanceof PortTypeXml) {
            return "portType";
        }
        String n = l.getClass().getSimpleName().replace("Xml", "");
        return switch (n) {
            case "Impl" -> "implementation";
            case "Attr" -> "attribute";
            case "Prop" -> "property";
            default -> Character.toLowerCase(n.charAt(0)) + n.substring(1);
        };
    }

    /** Wraps a bean deserializer to stamp the start tag's location on the node. */
    private static final class Locating extends DelegatingDeserializer {
        private static final long serialVersionUID = 1L;

        Locating(JsonDeserializer<?> d) {
            super(d);
        }

        @Override
        protected JsonDeserializer<?> newDelegatingInstance(JsonDeserializer<?> newDelegatee) {
            return new Locating(newDelegatee);
        }

        @Override
        public Object deserialize(JsonParser p, DeserializationContext ctxt) throws IOException {
            JsonLocation loc = p.currentTokenLocation();
            Object o = super.deserialize(p, ctxt);
            if (o instanceof Located l) {
                l.at(loc.getLineNr(), loc.getColumnNr());
            }
            return o;
        }
    }

    /** Simple text elements; an element with attributes or children is flagged, not bound. */
    private static final class TextDeserializer extends StdDeserializer<Text> {
        private static final long serialVersionUID = 1L;

        TextDeserializer() {
            super(Text.class);
        }

        @Override
        public Text deserialize(JsonParser p, DeserializationContext ctxt) throws IOException {
            Text t = new Text();
            JsonLocation loc = p.currentTokenLocation();
            t.at(loc.getLineNr(), loc.getColumnNr());
            if (p.currentToken() == JsonToken.START_OBJECT || p.currentToken() == JsonToken.START_ARRAY) {
                t.structured = true;
                p.skipChildren();
            } else {
                String s = p.getValueAsString();
                if (s != null && s.length() > SecureXml.MAX_TEXT_LENGTH) {
                    // Woodstox enforces its text limit only when it grows a buffer, so a text
                    // read into a large recycled buffer passes it: check here too (§2.1)
                    problems(ctxt).add(new Problem((String) ctxt.getAttribute(SOURCE), loc.getLineNr(),
                            loc.getColumnNr(), "2.1", "(document)", "document exceeds a parser limit: a text node"
                                    + " is longer than " + SecureXml.MAX_TEXT_LENGTH + " characters"));
                    s = "";
                }
                t.value = s == null ? "" : s;
            }
            return t;
        }

        @Override
        public Text getNullValue(DeserializationContext ctxt) {
            return new Text();
        }
    }
}
