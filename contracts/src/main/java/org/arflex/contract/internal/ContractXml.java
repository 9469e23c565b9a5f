package org.arflex.contract.internal;

import com.fasterxml.jackson.annotation.JsonSetter;
import com.fasterxml.jackson.dataformat.xml.annotation.JacksonXmlProperty;
import com.fasterxml.jackson.dataformat.xml.annotation.JacksonXmlText;
import java.util.ArrayList;
import java.util.List;

/**
 * The mutable binding model of a contract document: exactly what the XML says, every value still
 * text, so that {@link ContractValidator} can report every problem at once instead of stopping
 * at the first bad number. Repeated elements are collected in document order by setters.
 */
public final class ContractXml extends Located {
    @JacksonXmlProperty(isAttribute = true) public String name;
    @JacksonXmlProperty(isAttribute = true) public String version;
    public Text description;
    public Impl implementation;
    public Attributes attributes;
    public Ports ports;
    public Properties properties;
    public TimingXml timing;
    public ResourcesXml resources;
    public Text criticality;
    public Fault fault;
    public Update update;
    public StateXml state;
    public Rollout rollout;

    @JsonSetter("description") void description(Text t) { once(description, "description"); description = t; }
    @JsonSetter("implementation") void implementation(Impl v) { once(implementation, "implementation"); implementation = v; }
    @JsonSetter("attributes") void attributes(Attributes v) { once(attributes, "attributes"); attributes = v; }
    @JsonSetter("ports") void ports(Ports v) { once(ports, "ports"); ports = v; }
    @JsonSetter("properties") void properties(Properties v) { once(properties, "properties"); properties = v; }
    @JsonSetter("timing") void timing(TimingXml v) { once(timing, "timing"); timing = v; }
    @JsonSetter("resources") void resources(ResourcesXml v) { once(resources, "resources"); resources = v; }
    @JsonSetter("criticality") void criticality(Text v) { once(criticality, "criticality"); criticality = v; }
    @JsonSetter("fault") void fault(Fault v) { once(fault, "fault"); fault = v; }
    @JsonSetter("update") void update(Update v) { once(update, "update"); update = v; }
    @JsonSetter("state") void state(StateXml v) { once(state, "state"); state = v; }
    @JsonSetter("rollout") void rollout(Rollout v) { once(rollout, "rollout"); rollout = v; }

    /** {@code <implementation>}. */
    public static final class Impl extends Located {
        @JacksonXmlProperty(isAttribute = true) public String executable;
        @JacksonXmlProperty(isAttribute = true) public String task;
        @JacksonXmlProperty(isAttribute = true) public String movesHardware;
        @JacksonXmlProperty(isAttribute = true) public String motionThrough;
    }

    /** {@code <attributes>}. */
    public static final class Attributes extends Located {
        public final List<Attr> list = new ArrayList<>();

        @JsonSetter("attribute") void attribute(Attr a) { list.add(a); }
    }

    /** {@code <attribute name value/>}. */
    public static final class Attr extends Located {
        @JacksonXmlProperty(isAttribute = true) public String name;
        @JacksonXmlProperty(isAttribute = true) public String value;
    }

    /** {@code <ports>}: in and out elements in document order. */
    public static final class Ports extends Located {
        public final List<Port> list = new ArrayList<>();

        @JsonSetter("in") void in(Port p) { p.out = false; list.add(p); }
        @JsonSetter("out") void out(Port p) { p.out = true; list.add(p); }
    }

    /** {@code <in>} or {@code <out>}. */
    public static final class Port extends Located {
        public boolean out;
        @JacksonXmlProperty(isAttribute = true) public String name;
        @JacksonXmlProperty(isAttribute = true) public String type;
        @JacksonXmlProperty(isAttribute = true) public String typeVersion;
        @JacksonXmlProperty(isAttribute = true) public String method;
        @JacksonXmlProperty(isAttribute = true) public String optional;
        @JacksonXmlProperty(isAttribute = true) public String safety;
        @JacksonXmlProperty(isAttribute = true) public String depth;
        @JacksonXmlProperty(isAttribute = true) public String overflow;
        public final List<Bind> binds = new ArrayList<>();

        @JsonSetter("bind") void bind(Bind b) { binds.add(b); }
    }

    /** {@code <bind component port/>} or {@code <bind filter/>}. */
    public static final class Bind extends Located {
        @JacksonXmlProperty(isAttribute = true) public String component;
        @JacksonXmlProperty(isAttribute = true) public String port;
        @JacksonXmlProperty(isAttribute = true) public String filter;
    }

    /** {@code <properties>}. */
    public static final class Properties extends Located {
        public final List<Prop> list = new ArrayList<>();

        @JsonSetter("property") void property(Prop p) { list.add(p); }
    }

    /** {@code <property>}; its text is the description. */
    public static final class Prop extends Located {
        @JacksonXmlProperty(isAttribute = true) public String name;
        @JacksonXmlProperty(isAttribute = true) public String type;
        @JacksonXmlProperty(isAttribute = true, localName = "default") public String defaultValue;
        @JacksonXmlProperty(isAttribute = true) public String min;
        @JacksonXmlProperty(isAttribute = true) public String max;
        @JacksonXmlProperty(isAttribute = true) public String unit;
        @JacksonXmlProperty(isAttribute = true) public String mutable;
        @JacksonXmlText public String text;
    }

    /** {@code <timing>}. */
    public static final class TimingXml extends Located {
        @JacksonXmlProperty(isAttribute = true) public String period;
        @JacksonXmlProperty(isAttribute = true) public String deadline;
        @JacksonXmlProperty(isAttribute = true) public String wcet;
        @JacksonXmlProperty(isAttribute = true) public String priority;
        @JacksonXmlProperty(isAttribute = true) public String cpus;
        @JacksonXmlProperty(isAttribute = true) public String exclusive;
    }

    /** {@code <resources>}. */
    public static final class ResourcesXml extends Located {
        @JacksonXmlProperty(isAttribute = true) public String memory;
        @JacksonXmlProperty(isAttribute = true) public String network;
    }

    /** {@code <fault>}. */
    public static final class Fault extends Located {
        @JacksonXmlProperty(isAttribute = true) public String restart;
        @JacksonXmlProperty(isAttribute = true) public String intensity;
        @JacksonXmlProperty(isAttribute = true) public String window;
        @JacksonXmlProperty(isAttribute = true) public String backoff;
        @JacksonXmlProperty(isAttribute = true) public String safe;
        @JacksonXmlProperty(isAttribute = true) public String heartbeatTimeout;
        @JacksonXmlProperty(isAttribute = true) public String orphanHold;
    }

    /** {@code <update>}. */
    public static final class Update extends Located {
        @JacksonXmlProperty(isAttribute = true) public String url;
        @JacksonXmlProperty(isAttribute = true) public String sha256;
    }

    /** {@code <state type typeVersion>} with {@code <convertsFrom type typeVersion/>} children (SPEC §12.1). */
    public static final class StateXml extends Located {
        @JacksonXmlProperty(isAttribute = true) public String type;
        @JacksonXmlProperty(isAttribute = true) public String typeVersion;
        public final List<From> convertsFrom = new ArrayList<>();

        @JsonSetter("convertsFrom") void convertsFrom(From f) { convertsFrom.add(f); }
    }

    /** {@code <convertsFrom type typeVersion/>}. */
    public static final class From extends Located {
        @JacksonXmlProperty(isAttribute = true) public String type;
        @JacksonXmlProperty(isAttribute = true) public String typeVersion;
    }

    /** {@code <rollout shadow window>} with its tolerances and envelopes (SPEC §12.2). */
    public static final class Rollout extends Located {
        @JacksonXmlProperty(isAttribute = true) public String shadow;
        @JacksonXmlProperty(isAttribute = true) public String window;
        public final List<OutputRule> tolerances = new ArrayList<>();
        public final List<OutputRule> envelopes = new ArrayList<>();

        @JsonSetter("tolerance") void tolerance(OutputRule r) { tolerances.add(r); }
        @JsonSetter("envelope") void envelope(OutputRule r) { envelopes.add(r); }
    }

    /** {@code <tolerance port field abs/>} or {@code <envelope port field min max/>}. */
    public static final class OutputRule extends Located {
        @JacksonXmlProperty(isAttribute = true) public String port;
        @JacksonXmlProperty(isAttribute = true) public String field;
        @JacksonXmlProperty(isAttribute = true) public String abs;
        @JacksonXmlProperty(isAttribute = true) public String min;
        @JacksonXmlProperty(isAttribute = true) public String max;
    }
}
