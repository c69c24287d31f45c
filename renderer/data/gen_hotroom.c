/* gen_hotroom.c — short, thick streamline pieces of a convective room flow.
 *
 * A 4 x 4 x 3 m room (z up) with two counter-rotating convection rolls in x-z
 * (a divergence-free stream-function flow: warm air rises over the middle,
 * sinks at the walls) plus a weak sideways drift along y. Each line is a
 * piece of 2-5 points traced with RK4 in arc length with a seeded step of
 * 2-6 cm from a seeded point; every vertex carries a radius of 1.2-2.5 times
 * that step, up to 25% more where the air is warm, so radius > segment length
 * (the tracer moves at most h per step): blobs, a stress case for tube joins
 * and culling. Attributes "temperature" (deg C, warmer where air rises) and
 * "speed"; tangents = velocity. Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"
#include "gen_trace.h"

#include <math.h>

#define SL_HOTROOM_LX 4.0
#define SL_HOTROOM_LY 4.0
#define SL_HOTROOM_LZ 3.0
#define SL_HOTROOM_PI 3.141592653589793

enum { K_LINES, K_SEED };

static void hotroom_field(const double p[3], const void *ctx, double v[3])
{
    (void)ctx;
    /* psi = sin(2 pi x / Lx) sin(pi z / Lz); u = dpsi/dz, w = -dpsi/dx. */
    double ax = 2.0 * SL_HOTROOM_PI / SL_HOTROOM_LX, az = SL_HOTROOM_PI / SL_HOTROOM_LZ;
    v[0] = az * sin(ax * p[0]) * cos(az * p[2]);
    v[2] = -ax * cos(ax * p[0]) * sin(az * p[2]);
    v[1] = 0.25 * sin(2.0 * SL_HOTROOM_PI * p[1] / SL_HOTROOM_LY) * cos(az * p[2]);
}

/* Warm (up to 26 C) in rising air and near the ceiling, cool (18 C) where it sinks. */
static double hotroom_temperature(const double p[3], const double v[3])
{
    double ax = 2.0 * SL_HOTROOM_PI / SL_HOTROOM_LX;
    return 21.0 + 2.0 * p[2] / SL_HOTROOM_LZ + 3.0 * v[2] / ax;
}

static sl_status hotroom_generate(const double *values, sl_dataset **out, sl_err *err)
{
    size_t lines = (size_t)values[K_LINES];
    uint64_t seed = (uint64_t)values[K_SEED];
    /* Lengths first (from their own stream) so the vertex count is known. */
    sl_rng len_rng;
    sl_rng_seed(&len_rng, seed, UINT64_MAX);
    size_t vertices = 0;
    for (size_t k = 0; k < lines; k++)
        vertices += (size_t)sl_rng_int(&len_rng, 2, 5);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "hotroom");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "hotroom: out of memory");
    sl_lines *l = &ds->lines;
    float *temp = NULL, *speed = NULL;
    if (sl_lines_alloc(l, lines, vertices, 1, 1, err) != SL_OK ||
        !(temp = sl_lines_add_attribute(l, "temperature", 0, err)) ||
        !(speed = sl_lines_add_attribute(l, "speed", 0, err)))
        goto fail;
    sl_rng_seed(&len_rng, seed, UINT64_MAX);
    size_t base = 0;
    const double room[3] = {SL_HOTROOM_LX, SL_HOTROOM_LY, SL_HOTROOM_LZ};
    for (size_t k = 0; k < lines; k++) {
        size_t n = (size_t)sl_rng_int(&len_rng, 2, 5);
        sl_rng rng;
        sl_rng_seed(&rng, seed, k);
        double start[3];
        for (int c = 0; c < 3; c++)
            start[c] = sl_rng_range(&rng, 0.05, room[c] - 0.05);
        double h = sl_rng_range(&rng, 0.02, 0.06);
        double thick = sl_rng_range(&rng, 1.2, 2.5) * h;
        l->line_offsets[k] = (uint32_t)base;
        sl_trace_rk4(hotroom_field, NULL, start, h, n, NULL, NULL, l->positions + 3 * base, l->tangents + 3 * base);
        for (size_t i = base; i < base + n; i++) {
            double p[3], v[3];
            for (int c = 0; c < 3; c++) {
                p[c] = l->positions[3 * i + c];
                v[c] = l->tangents[3 * i + c];
            }
            temp[i] = (float)hotroom_temperature(p, v);
            speed[i] = (float)sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            /* Thicker where warmer, but never below 1.2 steps. */
            l->radii[i] = (float)(thick * (1.0 + 0.05 * fmax(0.0, temp[i] - 21.0)));
        }
        base += n;
    }
    l->line_offsets[lines] = (uint32_t)base;
    if (sl_dataset_finish_lines(ds, err) != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "hotroom");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_hotroom = {
    .name = "hotroom",
    .kind = SL_DATASET_LINES,
    .description = "short thick streamline pieces (2-5 points, radius > segment length) of a convective room flow; radii, temperature, speed",
    .keys_help = "lines (1..1000000, default 20000), seed",
    .key_count = 2,
    .keys = {
        {.name = "lines", .type = SL_GEN_INT, .min = 1, .max = 1000000, .def = 20000},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
    },
    .generate = hotroom_generate,
};
