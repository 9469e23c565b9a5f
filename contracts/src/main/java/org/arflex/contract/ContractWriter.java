package org.arflex.contract;

import java.io.StringWriter;
import java.util.Locale;
import java.util.Map;
import java.util.TreeMap;
import java.util.stream.Collectors;
import javax.xml.stream.XMLOutputFactory;
import javax.xml.stream.XMLStreamException;
import javax.xml.stream.XMLStreamWriter;
import org.arflex.contract.internal.SecureXml;

/**
 * Writes a {@link Contract} as a contract document (spec §2-§12) that {@link ContractParser}
 * reads back to an equal contract (except {@link Contract#source()}). Output is deterministic:
 * attributes sorted by name, durations and sizes in the largest exact unit, two-space indent.
 * Thread-safe.
 */
public final class ContractWriter {
    private final XMLOutputFactory factory = SecureXml.newOutputFactory();

    private ContractWriter() {
    }

    /** A writer. */
    public static ContractWriter create() {
        return new ContractWriter();
    }

    /** The contract as XML text (UTF-8 declared). */
    public String write(Contract c) {
        StringWriter sw = new StringWriter();
        try {
            XMLStreamWriter w = factory.createXMLStreamWriter(sw);
            w.writeStartDocument("UTF-8", "1.0");
            nl(w, 0);
            w.writeStartElement("component");
            w.writeDefaultNamespace(ContractParser.NAMESPACE);
            w.writeAttribute("name", c.name());
            w.writeAttribute("version", c.version());
            if (!c.description().isEmpty()) {
                nl(w, 1);
                w.writeStartElement("description");
                w.writeCharacters(c.description());
                w.writeEndElement();
            }
            nl(w, 1);
            w.writeEmptyElement("implementation");
            w.writeAttribute("executable", c.executable());
            w.writeAttribute("task", c.taskType().name().toLowerCase(Locale.ROOT));
            w.writeAttribute("movesHardware", Boolean.toString(c.movesHardware()));
            if (c.motionThroughOutputs()) {
                w.writeAttribute("motionThrough", "outputs");
            }
            if (!c.attributes().isEmpty()) {
                nl(w, 1);
                w.writeStartElement("attributes");
                for (Map.Entry<String, String> e : new TreeMap<>(c.attributes()).entrySet()) {
                    nl(w, 2);
                    w.writeEmptyElement("attribute");
                    w.writeAttribute("name", e.getKey());
                    w.writeAttribute("value", e.getValue());
                }
                nl(w, 1);
                w.writeEndElement();
            }
            if (!c.ports().isEmpty()) {
                nl(w, 1);
                w.writeStartElement("ports");
                for (PortSpec p : c.ports()) {
                    port(w, p);
                }
                nl(w, 1);
                w.writeEndElement();
            }
            if (!c.properties().isEmpty()) {
                nl(w, 1);
                w.writeStartElement("properties");
                for (PropertySpec p : c.properties()) {
                    property(w, p);
                }
                nl(w, 1);
                w.writeEndElement();
            }
            Timing t = c.timing();
            boolean service = c.taskType() == Contract.TaskType.SERVICE;
            if (!service || t.periodNs() > 0 || !t.cpus().isEmpty()) {
                nl(w, 1);
                w.writeEmptyElement("timing");
                if (t.periodNs() > 0) {
                    w.writeAttribute("period", Values.formatDuration(t.periodNs()));
                    w.writeAttribute("deadline", Values.formatDuration(t.deadlineNs()));
                    w.writeAttribute("wcet", Values.formatDuration(t.wcetNs()));
                }
                if (!service) {
                    w.writeAttribute("priority", Integer.toString(t.priority()));
                }
                if (!t.cpus().isEmpty()) {
                    w.writeAttribute("cpus", t.cpus().stream().map(String::valueOf).collect(Collectors.joining(",")));
                }
                if (t.exclusive()) {
                    w.writeAttribute("exclusive", "true");
                }
            }
            nl(w, 1);
            w.writeEmptyElement("resources");
            w.writeAttribute("memory", Values.formatSize(c.resources().memoryBytes()));
            w.writeAttribute("network", Values.formatSize(c.resources().networkBps()) + "/s");
            nl(w, 1);
            w.writeStartElement("criticality");
            w.writeCharacters(Integer.toString(c.criticality()));
            w.writeEndElement();
            FaultPolicy f = c.fault();
            nl(w, 1);
            w.writeEmptyElement("fault");
            w.writeAttribute("restart", f.restart().name().toLowerCase(Locale.ROOT));
            w.writeAttribute("intensity", Integer.toString(f.intensity()));
            w.writeAttribute("window", Values.formatDuration(f.windowMs() * 1_000_000L));
            w.writeAttribute("backoff", f.backoffMs() == 0 ? "0ms" : Values.formatDuration(f.backoffMs() * 1_000_000L));
            w.writeAttribute("safe", f.safeOutput().name().toLowerCase(Locale.ROOT));
            w.writeAttribute("heartbeatTimeout", Values.formatDuration(f.heartbeatTimeoutMs() * 1_000_000L));
            w.writeAttribute("orphanHold", f.orphanHoldMs() == 0 ? "0ms" : Values.formatDuration(f.orphanHoldMs() * 1_000_000L));
            if (c.update().isPresent()) {
                nl(w, 1);
                w.writeEmptyElement("update");
                w.writeAttribute("url", c.update().get().url().toString());
                w.writeAttribute("sha256", c.update().get().sha256());
            }
            if (c.state().isPresent()) {
                StateSpec st = c.state().get();
                nl(w, 1);
                if (st.convertsFrom().isEmpty()) {
                    w.writeEmptyElement("state");
                } else {
                    w.writeStartElement("state");
                }
                w.writeAttribute("type", st.type());
                w.writeAttribute("typeVersion", st.typeVersion().toString());
                for (StateSpec.From from : st.convertsFrom()) {
                    nl(w, 2);
                    w.writeEmptyElement("convertsFrom");
                    w.writeAttribute("type", from.type());
                    w.writeAttribute("typeVersion", from.typeVersion().toString());
                }
                if (!st.convertsFrom().isEmpty()) {
                    nl(w, 1);
                    w.writeEndElement();
                }
            }
            if (c.rollout().isPresent()) {
                RolloutSpec r = c.rollout().get();
                nl(w, 1);
                boolean empty = r.tolerances().isEmpty() && r.envelopes().isEmpty();
                if (empty) {
                    w.writeEmptyElement("rollout");
                } else {
                    w.writeStartElement("rollout");
                }
                if (r.shadow().isPresent()) {
                    w.writeAttribute("shadow", Long.toString(r.shadow().getAsLong()));
                }
                if (r.window().isPresent()) {
                    w.writeAttribute("window", Long.toString(r.window().getAsLong()));
                }
                for (RolloutSpec.Tolerance tol : r.tolerances()) {
                    nl(w, 2);
                    w.writeEmptyElement("tolerance");
                    w.writeAttribute("port", tol.port());
                    w.writeAttribute("field", tol.field());
                    w.writeAttribute("abs", Double.toString(tol.abs()));
                }
                for (RolloutSpec.Envelope e : r.envelopes()) {
                    nl(w, 2);
                    w.writeEmptyElement("envelope");
                    w.writeAttribute("port", e.port());
                    w.writeAttribute("field", e.field());
                    w.writeAttribute("min", Double.toString(e.min()));
                    w.writeAttribute("max", Double.toString(e.max()));
                }
                if (!empty) {
                    nl(w, 1);
                    w.writeEndElement();
                }
            }
            nl(w, 0);
            w.writeEndElement();
            w.writeEndDocument();
            w.close();
        } catch (XMLStreamException e) {
            throw new IllegalStateException("cannot write contract " + c.name() + ": " + e.getMessage(), e);
        }
        return sw.toString() + "\n";
    }

    private static void port(XMLStreamWriter w, PortSpec p) throws XMLStreamException {
        nl(w, 2);
        boolean in = p.direction() == PortSpec.Direction.IN;
        boolean hasBind = in && p.binding().isPresent();
        if (hasBind) {
            w.writeStartElement(in ? "in" : "out");
        } else {
            w.writeEmptyElement(in ? "in" : "out");
        }
        w.writeAttribute("name", p.name());
        w.writeAttribute("type", p.type());
        w.writeAttribute("typeVersion", p.typeVersion().toString());
        w.writeAttribute("method", p.method().name().toLowerCase(Locale.ROOT));
        if (in) {
            if (p.safety()) {
                w.writeAttribute("safety", "true");
            } else {
                w.writeAttribute("optional", Boolean.toString(p.optional()));
            }
        } else {
            if (p.method() != PortSpec.Method.STATE) {
                w.writeAttribute("depth", Integer.toString(p.depth()));
            }
            if (p.method() == PortSpec.Method.STREAM) {
                w.writeAttribute("overflow", p.overflow() == PortSpec.Overflow.DROP_OLDEST ? "drop-oldest" : "drop-newest");
            }
        }
        if (hasBind) {
            Binding b = p.binding().get();
            nl(w, 3);
            w.writeEmptyElement("bind");
            if (b.filter().isPresent()) {
                w.writeAttribute("filter", b.filter().get());
            } else {
                w.writeAttribute("component", b.component().orElseThrow());
                w.writeAttribute("port", b.port().orElseThrow());
            }
            nl(w, 2);
            w.writeEndElement();
        }
    }

    private static void property(XMLStreamWriter w, PropertySpec p) throws XMLStreamException {
        nl(w, 2);
        boolean hasText = !p.description().isEmpty();
        if (hasText) {
            w.writeStartElement("property");
        } else {
            w.writeEmptyElement("property");
        }
        w.writeAttribute("name", p.name());
        w.writeAttribute("type", p.type().name().toLowerCase(Locale.ROOT));
        w.writeAttribute("default", p.defaultValue().toString());
        boolean isInt = p.type() == PropertySpec.Type.INT;
        if (p.min().isPresent()) {
            w.writeAttribute("min", number(p.min().get(), isInt));
        }
        if (p.max().isPresent()) {
            w.writeAttribute("max", number(p.max().get(), isInt));
        }
        if (!p.unit().isEmpty()) {
            w.writeAttribute("unit", p.unit());
        }
        w.writeAttribute("mutable", Boolean.toString(p.mutable()));
        if (hasText) {
            w.writeCharacters(p.description());
            w.writeEndElement();
        }
    }

    private static String number(double d, boolean isInt) {
        return isInt ? Long.toString((long) d) : Double.toString(d);
    }

    private static void nl(XMLStreamWriter w, int depth) throws XMLStreamException {
        w.writeCharacters("\n" + "  ".repeat(depth));
    }
}
