/* gen_abc.c — streamlines of the Arnold–Beltrami–Childress (ABC) flow.
 *
 * v = (A sin z + C cos y, B sin x + A cos z, C sin y + B cos x), a steady
 * Beltrami field (curl v = v, div v = 0) that is chaotic for the classic
 * A = sqrt(3), B = sqrt(2), C = 1. Lines start at seeded random points of
 * [0, 2pi]^3 and are traced forward with RK4 in arc length for a fixed length
 * (SL_ABC_LENGTH), so `points` refines rather than lengthens them; they are
 * not wrapped into the periodic cell (no jumps), so they may leave it by up
 * to that length. Tangents = velocity, attribute "speed" = |v|, then
 * "helicity" (curl v).v = |v|^2 and "vorticity_magnitude" |curl v| = |v|,
 * closed form (curl v = v for any A, B, C: (curl v)_x = dv_z/dy - dv_y/dz =
 * C cos y + A sin z = v_x, and cyclically), in double at the stored vertex.
 * Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"
#include "gen_trace.h"

#include <math.h>

#define SL_ABC_LENGTH 6.283185307179586 /* one period of the cell */

enum { K_LINES, K_POINTS, K_SEED, K_A, K_B, K_C };

typedef struct abc_params { double a, b, c; } abc_params;

static void abc_field(const double p[3], const void *ctx, double v[3])
{
    const abc_params *k = ctx;
    v[0] = k->a * sin(p[2]) + k->c * cos(p[1]);
    v[1] = k->b * sin(p[0]) + k->a * cos(p[2]);
    v[2] = k->c * sin(p[1]) + k->b * cos(p[0]);
}

static sl_status abc_generate(const double *values, sl_dataset **out, sl_err *err)
{
    size_t lines = (size_t)values[K_LINES], points = (size_t)values[K_POINTS];
    uint64_t seed = (uint64_t)values[K_SEED];
    abc_params prm = {values[K_A], values[K_B], values[K_C]};
    if ((double)lines * (double)points > SL_MAX_VERTICES)
        return sl_err_set(err, SL_ERR_LIMIT, "abc: lines * points = %zu exceeds the limit of %u vertices",
                          lines * points, SL_MAX_VERTICES);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "abc");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "abc: out of memory");
    sl_lines *l = &ds->lines;
    sl_status st = sl_lines_alloc(l, lines, lines * points, 0, 1, err);
    float *speed = st == SL_OK ? sl_lines_add_attribute(l, "speed", 0, err) : NULL;
    float *helicity = speed ? sl_lines_add_attribute(l, SL_ATTR_HELICITY, 0, err) : NULL;
    float *vorticity = helicity ? sl_lines_add_attribute(l, SL_ATTR_VORTICITY, 0, err) : NULL;
    if (!vorticity)
        goto fail;
    const double two_pi = 6.283185307179586;
    double h = SL_ABC_LENGTH / (double)(points - 1);
    for (size_t k = 0; k < lines; k++) {
        sl_rng rng;
        sl_rng_seed(&rng, seed, k);
        size_t base = k * points;
        l->line_offsets[k] = (uint32_t)base;
        double start[3];
        for (int c = 0; c < 3; c++)
            start[c] = sl_rng_range(&rng, 0.0, two_pi);
        sl_trace_rk4(abc_field, &prm, start, h, points, NULL, NULL,
                     l->positions + 3 * base, l->tangents + 3 * base);
        for (size_t i = base; i < base + points; i++) {
            const float *t = l->tangents + 3 * i;
            speed[i] = (float)sqrt((double)t[0] * t[0] + (double)t[1] * t[1] + (double)t[2] * t[2]);
            const double q[3] = {l->positions[3 * i], l->positions[3 * i + 1], l->positions[3 * i + 2]};
            double v[3];
            abc_field(q, &prm, v); /* = curl v */
            double vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            helicity[i] = (float)vv;
            vorticity[i] = (float)sqrt(vv);
        }
    }
    l->line_offsets[lines] = (uint32_t)(lines * points);
    if (sl_dataset_finish_lines(ds, err) != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "abc");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_abc = {
    .name = "abc",
    .kind = SL_DATASET_LINES,
    .description = "RK4 streamlines of the Arnold-Beltrami-Childress flow in [0,2pi]^3; tangents = velocity, attributes speed, helicity, vorticity_magnitude",
    .keys_help = "lines (1..1000000, default 500), points per line (2..10000, default 300), seed, "
                 "a (0..10, default sqrt 3), b (0..10, default sqrt 2), c (0..10, default 1)",
    .key_count = 6,
    .keys = {
        {.name = "lines", .type = SL_GEN_INT, .min = 1, .max = 1000000, .def = 500},
        {.name = "points", .type = SL_GEN_INT, .min = 2, .max = 10000, .def = 300},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
        {.name = "a", .type = SL_GEN_NUMBER, .min = 0, .max = 10, .def = 1.7320508075688772},
        {.name = "b", .type = SL_GEN_NUMBER, .min = 0, .max = 10, .def = 1.4142135623730951},
        {.name = "c", .type = SL_GEN_NUMBER, .min = 0, .max = 10, .def = 1.0},
    },
    .generate = abc_generate,
};
