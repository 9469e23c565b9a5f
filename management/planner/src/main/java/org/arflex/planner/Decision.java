package org.arflex.planner;

import java.util.OptionalInt;

/**
 * The admission verdict for one component.
 *
 * @param component      component name
 * @param admitted       true when it fits
 * @param cpu            the CPU it runs on (admitted periodic and sporadic tasks only)
 * @param wcetNs         the WCET used for the analysis: the larger of the declared and the
 *                       measured one (0 for service tasks)
 * @param responseTimeNs exact worst-case response time when response-time analysis ran for it,
 *                       -1 when a utilisation bound was enough or it is a service task
 * @param reason         one human sentence: how it fits ({@code cpu 1: R=0.30 ms <= D=1 ms}) or
 *                       why it was refused ({@code cpu 1: response time 1.20 ms of 'x' exceeds
 *                       deadline 1 ms (U=0.97)}, {@code memory: 900 MiB requested, 512 MiB free},
 *                       {@code input 'x' of 'a': provider 'b' was refused admission})
 */
public record Decision(String component, boolean admitted, OptionalInt cpu, long wcetNs, long responseTimeNs,
        String reason) {
}
