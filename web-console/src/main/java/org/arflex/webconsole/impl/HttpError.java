package org.arflex.webconsole.impl;

/** A request the console refuses, with the HTTP status and a message naming what is wrong. */
final class HttpError extends Exception {
    private static final long serialVersionUID = 1L;
    final int status;

    HttpError(int status, String message) {
        super(message);
        this.status = status;
    }

    /** An exception's message, or its class when it has none. */
    static String reason(RuntimeException e) {
        String m = e.getMessage();
        return m == null || m.isBlank() ? e.getClass().getSimpleName() : m;
    }
}
