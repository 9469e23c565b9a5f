package org.arflex.contract;

/**
 * Memory and network budget of a component.
 *
 * @param memoryBytes resident memory the RT half may lock (mlockall), including its ports
 * @param networkBps  network bandwidth in bytes per second, 0 if none
 */
public record Resources(long memoryBytes, long networkBps) {
}
