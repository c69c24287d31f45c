/* gen_trace.h — RK4 streamline tracing over an analytic vector field, fixed vertex spacing.
 *
 * Integrates dp/ds = v(p) / |v(p)| (arc-length parametrisation), so a line of
 * n points with step h is (n - 1) * h long wherever the flow is fast or slow;
 * near a stagnation point (|v| < SL_TRACE_SPEED_FLOOR) the step shrinks with
 * |v| instead of dividing by zero. Writes the field value itself (not
 * normalised) as the tangent of each vertex. Vertices are always h apart in
 * arc length; a step whose direction turns sharply is integrated in halves
 * (recursively) so coarse vertex spacing does not throw the line off its
 * streamline. No seeding strategy (callers pick start points), no
 * allocation. Any thread.
 */
#ifndef SL_GEN_TRACE_H
#define SL_GEN_TRACE_H

#include <stddef.h>

#define SL_TRACE_SPEED_FLOOR 1e-9
#define SL_TRACE_MAX_TURN_COS 0.9848 /* split a step whose direction turns > ~10 degrees */
#define SL_TRACE_MAX_SPLIT 6         /* at most 2^6 sub-steps per vertex step */

/* v = field(p); ctx is the caller's parameter block (borrowed). */
typedef void (*sl_trace_field)(const double p[3], const void *ctx, double v[3]);

/* Traces `count` points from `start` with step h, writing 3 * count floats to
 * positions and, when tangents is non-NULL, 3 * count floats of field values.
 * Returns 1 when every point lies in the box [lo, hi] (both may be NULL: no
 * box); returns 0 as soon as a point leaves it, leaving the rest unwritten. h < 0 traces
 * against the flow (tangents are still the field values). */
int sl_trace_rk4(sl_trace_field field, const void *ctx, const double start[3], double h,
                 size_t count, const double lo[3], const double hi[3],
                 float *positions, float *tangents);

/* Like sl_trace_rk4 but centred on `start`: the first (count + 1) / 2 points
 * are traced backward (step -h) and stored reversed, the rest forward, so
 * the line runs in flow direction and passes through start. count >= 1. */
int sl_trace_rk4_centred(sl_trace_field field, const void *ctx, const double start[3], double h,
                         size_t count, const double lo[3], const double hi[3],
                         float *positions, float *tangents);

#endif
