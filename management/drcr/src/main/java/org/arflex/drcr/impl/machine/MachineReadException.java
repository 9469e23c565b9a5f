package org.arflex.drcr.impl.machine;

/** The machine's resources could not be read: the message names the file and what is wrong. */
public final class MachineReadException extends Exception {
    private static final long serialVersionUID = 1L;

    public MachineReadException(String message) {
        super(message);
    }
}
