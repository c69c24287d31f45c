/* gen_trace.c — RK4 streamline tracing in arc length, fixed vertex spacing (see gen_trace.h).
 *
 * Double precision throughout; floats only when storing. Each RK4 stage
 * uses the unit direction of the field, so a step moves at most h (the
 * average of four vectors of length <= 1, also after splitting): generators
 * rely on this to bound segment lengths (hotroom radius > segment). Steps
 * that turn sharply are split (rk4_step). No allocation, no state. Any thread.
 */
#include "gen_trace.h"

#include <math.h>

/* Unit-speed direction of the field at p (the raw value in raw, if given). */
static void direction(sl_trace_field field, const void *ctx, const double p[3], double d[3], double raw[3])
{
    double v[3];
    field(p, ctx, v);
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    double inv = 1.0 / (len > SL_TRACE_SPEED_FLOOR ? len : SL_TRACE_SPEED_FLOOR);
    for (int c = 0; c < 3; c++) {
        d[c] = v[c] * inv;
        if (raw)
            raw[c] = v[c];
    }
}

/* One RK4 step of length h from p (k1 = unit direction at p, given). When
 * the direction turns by more than SL_TRACE_MAX_TURN_COS over the step, the
 * step is split in two halves, recursively up to SL_TRACE_MAX_SPLIT levels,
 * so tight spirals (the tornado's core) stay on their streamline even when
 * the caller's vertex spacing h is coarse. */
static void rk4_step(sl_trace_field field, const void *ctx, double p[3], const double k1[3], double h, int depth)
{
    double k2[3], k3[3], k4[3], q[3];
    for (int c = 0; c < 3; c++) q[c] = p[c] + 0.5 * h * k1[c];
    direction(field, ctx, q, k2, NULL);
    for (int c = 0; c < 3; c++) q[c] = p[c] + 0.5 * h * k2[c];
    direction(field, ctx, q, k3, NULL);
    for (int c = 0; c < 3; c++) q[c] = p[c] + h * k3[c];
    direction(field, ctx, q, k4, NULL);
    double turn = k1[0] * k4[0] + k1[1] * k4[1] + k1[2] * k4[2];
    if (depth < SL_TRACE_MAX_SPLIT && turn < SL_TRACE_MAX_TURN_COS) {
        double mid[3];
        rk4_step(field, ctx, p, k1, 0.5 * h, depth + 1);
        direction(field, ctx, p, mid, NULL);
        rk4_step(field, ctx, p, mid, 0.5 * h, depth + 1);
        return;
    }
    for (int c = 0; c < 3; c++)
        p[c] += h / 6.0 * (k1[c] + 2.0 * k2[c] + 2.0 * k3[c] + k4[c]);
}

int sl_trace_rk4(sl_trace_field field, const void *ctx, const double start[3], double h,
                 size_t count, const double lo[3], const double hi[3],
                 float *positions, float *tangents)
{
    double p[3] = {start[0], start[1], start[2]};
    for (size_t i = 0; i < count; i++) {
        double k1[3], raw[3];
        direction(field, ctx, p, k1, raw);
        for (int c = 0; c < 3; c++) {
            positions[3 * i + c] = (float)p[c];
            if (tangents)
                tangents[3 * i + c] = (float)raw[c];
            if ((lo && p[c] < lo[c]) || (hi && p[c] > hi[c]))
                return 0;
        }
        if (i + 1 == count)
            break;
        rk4_step(field, ctx, p, k1, h, 0);
    }
    return 1;
}

/* Reverses n 3-vectors in place. */
static void reverse3(float *a, size_t n)
{
    for (size_t i = 0, j = n - 1; i < j; i++, j--)
        for (int c = 0; c < 3; c++) {
            float t = a[3 * i + c];
            a[3 * i + c] = a[3 * j + c];
            a[3 * j + c] = t;
        }
}

int sl_trace_rk4_centred(sl_trace_field field, const void *ctx, const double start[3], double h,
                         size_t count, const double lo[3], const double hi[3],
                         float *positions, float *tangents)
{
    size_t back = (count + 1) / 2;
    if (!sl_trace_rk4(field, ctx, start, -h, back, lo, hi, positions, tangents))
        return 0;
    reverse3(positions, back);
    if (tangents)
        reverse3(tangents, back);
    /* The forward half starts at the seed again, overwriting the identical
     * last backward point. */
    size_t at = back - 1;
    return sl_trace_rk4(field, ctx, start, h, count - at, lo, hi, positions + 3 * at,
                        tangents ? tangents + 3 * at : NULL);
}
