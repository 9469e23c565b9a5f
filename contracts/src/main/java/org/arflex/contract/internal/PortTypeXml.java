package org.arflex.contract.internal;

import com.fasterxml.jackson.annotation.JsonSetter;
import com.fasterxml.jackson.dataformat.xml.annotation.JacksonXmlProperty;
import com.fasterxml.jackson.dataformat.xml.annotation.JacksonXmlText;
import java.util.ArrayList;
import java.util.List;

/** Binding model of a port type definition (contracts/types/*.xml, spec §13.1). */
public final class PortTypeXml extends Located {
    @JacksonXmlProperty(isAttribute = true) public String name;
    @JacksonXmlProperty(isAttribute = true) public String version;
    @JacksonXmlProperty(isAttribute = true) public String methods;
    @JacksonXmlProperty(isAttribute = true) public String maxPayload;
    public Text description;
    /** Fields and pads, in declaration order. */
    public final List<Member> members = new ArrayList<>();
    public final List<Const> constants = new ArrayList<>();

    @JsonSetter("description") void description(Text t) { once(description, "description"); description = t; }
    @JsonSetter("field") void field(Member m) { m.pad = false; members.add(m); }
    @JsonSetter("pad") void pad(Member m) { m.pad = true; members.add(m); }
    @JsonSetter("const") void constant(Const c) { constants.add(c); }

    /** {@code <field name type count unit finite min max>doc</field>} or {@code <pad bytes/>}. */
    public static final class Member extends Located {
        public boolean pad;
        @JacksonXmlProperty(isAttribute = true) public String name;
        @JacksonXmlProperty(isAttribute = true) public String type;
        @JacksonXmlProperty(isAttribute = true) public String count;
        @JacksonXmlProperty(isAttribute = true) public String unit;
        @JacksonXmlProperty(isAttribute = true) public String bytes;
        @JacksonXmlProperty(isAttribute = true) public String finite;
        @JacksonXmlProperty(isAttribute = true) public String min;
        @JacksonXmlProperty(isAttribute = true) public String max;
        @JacksonXmlText public String text;
    }

    /** {@code <const name type value>doc</const>}. */
    public static final class Const extends Located {
        @JacksonXmlProperty(isAttribute = true) public String name;
        @JacksonXmlProperty(isAttribute = true) public String type;
        @JacksonXmlProperty(isAttribute = true) public String value;
        @JacksonXmlText public String text;
    }
}
