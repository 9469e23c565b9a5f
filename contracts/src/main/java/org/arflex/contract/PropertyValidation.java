package org.arflex.contract;

import static org.arflex.contract.ContractValidator.PROPERTY_NAME;
import static org.arflex.contract.ContractValidator.UNIT;
import static org.arflex.contract.ContractValidator.bool;

import java.util.Optional;
import java.util.Set;
import org.arflex.contract.internal.ContractXml;

/**
 * SPEC §7: checks one {@code <property>} of a contract (name, type, range, default, unit);
 * called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class PropertyValidation {
    private PropertyValidation() {
    }

    static PropertySpec check(Problems p, ContractXml.Prop x, Set<String> seen) {
        String f = "properties/property[" + (x.name == null ? "?" : x.name) + "]";
        boolean ok = true;
        if (x.name == null) {
            p.at(x, "7.1", f + "/@name", "required attribute is missing");
            ok = false;
        } else if (!PROPERTY_NAME.matcher(x.name).matches()) {
            p.at(x, "7.1", f + "/@name", "'" + x.name + "' is not a property name ([a-z][a-z0-9_.]{0,30})");
            ok = false;
        } else if (!seen.add(x.name)) {
            p.at(x, "7.1", f + "/@name", "duplicate property name '" + x.name + "'");
            ok = false;
        }
        PropertySpec.Type type = null;
        if (x.type == null) {
            p.at(x, "7.2", f + "/@type", "required attribute is missing (bool, int or double)");
            return null;
        }
        switch (x.type) {
            case "bool" -> type = PropertySpec.Type.BOOL;
            case "int" -> type = PropertySpec.Type.INT;
            case "double" -> type = PropertySpec.Type.DOUBLE;
            default -> {
                p.at(x, "7.2", f + "/@type", "'" + x.type + "' is not a property type (bool, int or double)");
                return null;
            }
        }
        Optional<Double> min = Optional.empty();
        Optional<Double> max = Optional.empty();
        PropertySpec.Value def = null;
        if (type == PropertySpec.Type.BOOL) {
            if (x.min != null || x.max != null) {
                p.at(x, "7.3", f + (x.min != null ? "/@min" : "/@max"), "a bool property has no range");
                ok = false;
            }
            if (x.defaultValue == null) {
                p.at(x, "7.2", f + "/@default", "required attribute is missing");
                ok = false;
            } else {
                Boolean b = Values.bool(x.defaultValue);
                if (b == null) {
                    p.at(x, "7.2", f + "/@default", "'" + x.defaultValue + "' is not a bool (true or false)");
                    ok = false;
                } else {
                    def = PropertySpec.Value.ofBool(b);
                }
            }
        } else {
            boolean isInt = type == PropertySpec.Type.INT;
            min = bound(p, x, x.min, isInt, f + "/@min");
            max = bound(p, x, x.max, isInt, f + "/@max");
            if ((x.min != null && min.isEmpty()) || (x.max != null && max.isEmpty())) {
                ok = false;
            }
            if (min.isPresent() && max.isPresent() && min.get() > max.get()) {
                p.at(x, "7.3", f + "/@min", "min " + x.min + " is greater than max " + x.max);
                ok = false;
            }
            if (x.defaultValue == null) {
                p.at(x, "7.2", f + "/@default", "required attribute is missing");
                ok = false;
            } else if (isInt) {
                Long v = Values.longValue(x.defaultValue);
                if (v == null || x.defaultValue.trim().startsWith("0x")) {
                    p.at(x, "7.2", f + "/@default", "'" + x.defaultValue + "' is not an int (64-bit decimal integer)");
                    ok = false;
                } else {
                    def = PropertySpec.Value.ofInt(v);
                }
            } else {
                Double v = Values.decimal(x.defaultValue);
                if (v == null) {
                    p.at(x, "7.2", f + "/@default", "'" + x.defaultValue + "' is not a finite decimal number");
                    ok = false;
                } else {
                    def = PropertySpec.Value.ofDouble(v);
                }
            }
            if (def != null) {
                double d = def.asDouble();
                if ((min.isPresent() && d < min.get()) || (max.isPresent() && d > max.get())) {
                    p.at(x, "7.3", f + "/@default", "default " + x.defaultValue + " is outside [" + (x.min == null
                            ? "-inf" : x.min) + ", " + (x.max == null ? "+inf" : x.max) + "]");
                    ok = false;
                }
            }
        }
        String unit = x.unit == null ? "" : x.unit;
        if (!UNIT.matcher(unit).matches()) {
            p.at(x, "7.4", f + "/@unit", "'" + unit + "' is not a unit symbol (up to 16 characters, no spaces)");
            ok = false;
        }
        if (type == PropertySpec.Type.BOOL && !unit.isEmpty()) {
            p.at(x, "7.4", f + "/@unit", "a bool property has no unit");
            ok = false;
        }
        boolean mutable = bool(p, x, x.mutable, false, "7.5", f + "/@mutable");
        if (!ok || def == null) {
            return null;
        }
        return new PropertySpec(x.name, type, def, min, max, unit, mutable, Values.text(x.text));
    }

    private static Optional<Double> bound(Problems p, ContractXml.Prop x, String text, boolean isInt, String f) {
        if (text == null) {
            return Optional.empty();
        }
        if (isInt) {
            Long v = Values.longValue(text);
            if (v == null || text.trim().startsWith("0x")) {
                p.at(x, "7.3", f, "'" + text + "' is not an int");
                return Optional.empty();
            }
            return Optional.of((double) v);
        }
        Double v = Values.decimal(text);
        if (v == null) {
            p.at(x, "7.3", f, "'" + text + "' is not a finite decimal number");
            return Optional.empty();
        }
        return Optional.of(v);
    }
}
