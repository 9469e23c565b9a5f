package org.arflex.planner;

import java.lang.reflect.Constructor;
import java.lang.reflect.Field;
import java.lang.reflect.Member;
import java.lang.reflect.Method;
import java.lang.reflect.Modifier;
import java.lang.reflect.Type;
import java.util.ArrayList;
import java.util.List;

/** Finds public or protected signatures of API types that name a type of a hidden package. */
final class ApiSurface {

    private ApiSurface() {
    }

    static List<String> leaks(List<Class<?>> api, String hiddenPackage) {
        List<String> out = new ArrayList<>();
        for (Class<?> c : api) {
            if (!Modifier.isPublic(c.getModifiers())) {
                continue;
            }
            List<Type> heads = new ArrayList<>(List.of(c.getGenericInterfaces()));
            if (c.getGenericSuperclass() != null) {
                heads.add(c.getGenericSuperclass());
            }
            for (Type t : heads) {
                check(out, c, "type declaration extends or implements", t, hiddenPackage);
            }
            for (Field f : c.getDeclaredFields()) {
                if (visible(f)) {
                    check(out, c, "field " + f.getName() + " has type", f.getGenericType(), hiddenPackage);
                }
            }
            for (Constructor<?> k : c.getDeclaredConstructors()) {
                if (visible(k)) {
                    for (Type t : k.getGenericParameterTypes()) {
                        check(out, c, "constructor takes", t, hiddenPackage);
                    }
                }
            }
            for (Method m : c.getDeclaredMethods()) {
                if (visible(m) && !m.isSynthetic()) {
                    List<Type> ts = new ArrayList<>(List.of(m.getGenericParameterTypes()));
                    ts.add(m.getGenericReturnType());
                    ts.addAll(List.of(m.getGenericExceptionTypes()));
                    for (Type t : ts) {
                        check(out, c, "method " + m.getName() + "() returns or takes", t, hiddenPackage);
                    }
                }
            }
        }
        return out;
    }

    private static boolean visible(Member m) {
        return Modifier.isPublic(m.getModifiers()) || Modifier.isProtected(m.getModifiers());
    }

    private static void check(List<String> out, Class<?> c, String what, Type t, String hiddenPackage) {
        if (t.getTypeName().contains(hiddenPackage + ".")) {
            out.add(c.getName() + ": " + what + " " + t.getTypeName());
        }
    }
}
