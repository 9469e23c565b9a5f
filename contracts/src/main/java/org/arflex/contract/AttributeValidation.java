package org.arflex.contract;

import static org.arflex.contract.ContractValidator.ATTRIBUTE_NAME;
import static org.arflex.contract.ContractValidator.MAX_ATTRIBUTE_VALUE;

import java.util.HashSet;
import java.util.LinkedHashMap;
import java.util.Locale;
import java.util.Map;
import java.util.Set;
import org.arflex.contract.internal.ContractXml;

/**
 * SPEC §5: checks a contract's {@code <attributes>} (names, case-insensitive duplicates, values)
 * and keeps the good ones in order; called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class AttributeValidation {
    private AttributeValidation() {
    }

    static Map<String, String> check(Problems p, ContractXml x) {
        Map<String, String> attributes = new LinkedHashMap<>();
        if (x.attributes != null) {
            Set<String> seen = new HashSet<>();
            for (ContractXml.Attr a : x.attributes.list) {
                String f = "attributes/attribute[" + a.name + "]";
                boolean ok = true;
                if (a.name == null) {
                    p.at(a, "5", "attributes/attribute/@name", "required attribute is missing");
                    ok = false;
                } else if (!ATTRIBUTE_NAME.matcher(a.name).matches()) {
                    p.at(a, "5", f + "/@name", "'" + a.name + "' is not an attribute name ([A-Za-z][A-Za-z0-9_.-]{0,63})");
                    ok = false;
                } else if (!seen.add(a.name.toLowerCase(Locale.ROOT))) {
                    p.at(a, "5", f + "/@name", "duplicate attribute '" + a.name
                            + "' (names are compared ignoring case, as filters do)");
                    ok = false;
                }
                if (a.value == null) {
                    p.at(a, "5", f + "/@value", "required attribute is missing");
                    ok = false;
                } else if (a.value.length() > MAX_ATTRIBUTE_VALUE || a.value.chars().anyMatch(Character::isISOControl)) {
                    p.at(a, "5", f + "/@value", "value must be at most " + MAX_ATTRIBUTE_VALUE
                            + " characters without control characters");
                    ok = false;
                }
                if (ok) {
                    attributes.put(a.name, a.value);
                }
            }
        }
        return attributes;
    }
}
