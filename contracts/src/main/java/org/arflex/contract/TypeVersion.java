package org.arflex.contract;

/**
 * A port type version {@code major.minor}. A provider of version P can feed a consumer built
 * against C when {@code P.major == C.major && P.minor >= C.minor}.
 */
public record TypeVersion(int major, int minor) implements Comparable<TypeVersion> {

    /** Parses {@code "1.2"}; throws IllegalArgumentException naming the bad text. */
    public static TypeVersion parse(String text) {
        String[] parts = text.trim().split("\\.");
        if (parts.length != 2) {
            throw new IllegalArgumentException("type version '" + text + "' is not MAJOR.MINOR");
        }
        try {
            return new TypeVersion(Integer.parseInt(parts[0]), Integer.parseInt(parts[1]));
        } catch (NumberFormatException e) {
            throw new IllegalArgumentException("type version '" + text + "' is not MAJOR.MINOR");
        }
    }

    /** True when a provider of this version can feed a consumer built against {@code consumer}. */
    public boolean canFeed(TypeVersion consumer) {
        return major == consumer.major && minor >= consumer.minor;
    }

    @Override
    public int compareTo(TypeVersion o) {
        return major != o.major ? Integer.compare(major, o.major) : Integer.compare(minor, o.minor);
    }

    @Override
    public String toString() {
        return major + "." + minor;
    }
}
