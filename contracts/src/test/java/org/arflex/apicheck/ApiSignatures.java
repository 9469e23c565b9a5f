package org.arflex.apicheck;

import java.io.IOException;
import java.lang.reflect.Constructor;
import java.lang.reflect.Field;
import java.lang.reflect.Member;
import java.lang.reflect.Method;
import java.lang.reflect.Modifier;
import java.lang.reflect.Type;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.SortedSet;
import java.util.TreeSet;
import java.util.stream.Stream;

/**
 * The public signatures of one package, as sorted lines: one {@code T} line per visible type
 * (kind, modifiers, supertypes) and one {@code M} line, led by its type's name, per public or
 * protected constructor, method or field ({@code toGenericString()}, so generics and
 * {@code abstract}/{@code default} show). A visible type is public and nested only in visible types. A type whose class file
 * carries {@code @org.osgi.annotation.versioning.ProviderType} is marked {@code provider}:
 * clients use it but do not implement it, so an abstract method added to it is a minor change.
 */
public final class ApiSignatures {

    /** The line prefix of a type that clients may implement or extend (see {@link #of}). */
    public static final String CONSUMER = "consumer";
    private static final String PROVIDER_TYPE = "Lorg/osgi/annotation/versioning/ProviderType;";

    private ApiSignatures() {
    }

    /** The signatures of {@code pkg}, whose class files are under {@code classes}. */
    public static SortedSet<String> of(Path classes, String pkg, ClassLoader loader)
            throws IOException, ClassNotFoundException {
        Path dir = classes.resolve(pkg.replace('.', '/'));
        List<Path> files;
        try (Stream<Path> s = Files.list(dir)) {
            files = s.filter(p -> p.toString().endsWith(".class")).sorted().toList();
        }
        SortedSet<String> out = new TreeSet<>();
        for (Path f : files) {
            String simple = f.getFileName().toString().replace(".class", "");
            if (simple.equals("package-info")) {
                continue;
            }
            Class<?> c = Class.forName(pkg + "." + simple, false, loader);
            if (visible(c)) {
                boolean provider = new String(Files.readAllBytes(f), StandardCharsets.ISO_8859_1).contains(PROVIDER_TYPE);
                out.addAll(of(c, provider));
            }
        }
        return out;
    }

    /** The lines of one type. */
    public static List<String> of(Class<?> c, boolean provider) {
        List<String> out = new ArrayList<>();
        StringBuilder t = new StringBuilder("T " + c.getName() + " " + kind(c));
        String mods = Modifier.toString(c.getModifiers() & ~Modifier.INTERFACE);
        if (!mods.isEmpty()) {
            t.append(' ').append(mods);
        }
        boolean extensible = !Modifier.isFinal(c.getModifiers()) && !c.isEnum() && !c.isRecord()
                && !c.isAnnotation();
        t.append(' ').append(extensible && !provider ? CONSUMER : "provider");
        if (c.getGenericSuperclass() != null && c.getSuperclass() != Object.class && !c.isEnum() && !c.isRecord()) {
            t.append(" extends ").append(c.getGenericSuperclass().getTypeName());
        }
        List<String> ifs = new ArrayList<>();
        for (Type i : c.getGenericInterfaces()) {
            ifs.add(i.getTypeName());
        }
        if (!ifs.isEmpty()) {
            t.append(" implements ").append(String.join(", ", ifs));
        }
        out.add(t.toString());
        for (Constructor<?> k : c.getDeclaredConstructors()) {
            if (visible(k) && !k.isSynthetic()) {
                out.add("M " + c.getName() + " " + k.toGenericString());
            }
        }
        for (Method m : c.getDeclaredMethods()) {
            if (visible(m) && !m.isSynthetic() && !m.isBridge()) {
                out.add("M " + c.getName() + " " + m.toGenericString());
            }
        }
        for (Field f : c.getDeclaredFields()) {
            if (visible(f) && !f.isSynthetic()) {
                out.add("M " + c.getName() + " " + f.toGenericString());
            }
        }
        return out;
    }

    private static String kind(Class<?> c) {
        if (c.isAnnotation()) {
            return "@interface";
        }
        if (c.isInterface()) {
            return "interface";
        }
        if (c.isEnum()) {
            return "enum";
        }
        return c.isRecord() ? "record" : "class";
    }

    private static boolean visible(Class<?> c) {
        for (Class<?> k = c; k != null; k = k.getEnclosingClass()) {
            if (!Modifier.isPublic(k.getModifiers()) || k.isAnonymousClass() || k.isLocalClass()) {
                return false;
            }
        }
        return true;
    }

    private static boolean visible(Member m) {
        return Modifier.isPublic(m.getModifiers()) || Modifier.isProtected(m.getModifiers());
    }
}
