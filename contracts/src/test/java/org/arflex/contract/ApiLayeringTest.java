package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.lang.reflect.Constructor;
import java.lang.reflect.Field;
import java.lang.reflect.Method;
import java.lang.reflect.Modifier;
import java.lang.reflect.Type;
import java.util.ArrayList;
import java.util.List;
import org.junit.jupiter.api.Test;

/** The exported packages never show a type of the private {@code internal} package in their public API. */
class ApiLayeringTest {
    private static final List<Class<?>> API = List.of(Contract.class, PortSpec.class, TypeVersion.class, Binding.class,
            PropertySpec.class, Timing.class, Resources.class, FaultPolicy.class, UpdateSpec.class, ContractParser.class,
            ContractParser.Result.class, ContractWriter.class, ContractException.class, Problem.class, Filter.class,
            PortType.class, PortTypes.class, org.arflex.contract.types.JointStateLayout.class,
            org.arflex.contract.types.ImageFrameLayout.class);

    @Test
    void publicSignaturesUseNoInternalType() {
        List<String> leaks = new ArrayList<>();
        for (Class<?> c : API) {
            for (Method m : c.getDeclaredMethods()) {
                if (Modifier.isPublic(m.getModifiers())) {
                    check(leaks, c + "." + m.getName(), m.getGenericReturnType());
                    for (Type t : m.getGenericParameterTypes()) {
                        check(leaks, c + "." + m.getName(), t);
                    }
                }
            }
            for (Constructor<?> k : c.getDeclaredConstructors()) {
                if (Modifier.isPublic(k.getModifiers())) {
                    for (Type t : k.getGenericParameterTypes()) {
                        check(leaks, c + ".<init>", t);
                    }
                }
            }
            for (Field f : c.getDeclaredFields()) {
                if (Modifier.isPublic(f.getModifiers())) {
                    check(leaks, c + "." + f.getName(), f.getGenericType());
                }
            }
        }
        assertEquals(List.of(), leaks);
    }

    private static void check(List<String> leaks, String where, Type t) {
        if (t.getTypeName().contains("org.arflex.contract.internal")) {
            leaks.add(where + " uses " + t.getTypeName());
        }
    }
}
