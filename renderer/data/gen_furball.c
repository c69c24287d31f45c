/* gen_furball.c — many random curly curves filling a ball: a segment-count benchmark.
 *
 * Each curve starts at a seeded point of the unit ball and walks with a fixed
 * step; its direction turns by an angular velocity that itself performs a
 * damped random walk, so curves curl smoothly and change their curl. Past
 * radius 0.85 the direction is steered back inward, keeping curves in the
 * ball (up to about one step beyond radius 1). Curve lengths are seeded in
 * [SL_FURBALL_MIN, SL_FURBALL_MAX] segments and the last curve takes the
 * remainder, so the total segment count equals `segments` exactly. Attribute
 * "arclength" (world units from the curve's start). No tangents. Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"

#include <math.h>
#include <stdlib.h>

#define SL_FURBALL_MIN 40
#define SL_FURBALL_MAX 160
#define SL_FURBALL_STEP 0.012
#define SL_FURBALL_KICK 12.0   /* angular-velocity kick per step: KICK * sqrt(step) * N(0,1), rad per unit length */
#define SL_FURBALL_DAMP 0.97   /* angular velocity kept per step (memory of about 30 steps) */
#define SL_FURBALL_SHELL 0.85  /* radius beyond which curves are steered inward */
#define SL_FURBALL_PULL 200.0  /* inward steering per unit length and unit distance past the shell */

enum { K_SEGMENTS, K_SEED };

static void normalize3(double v[3])
{
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len > 0.0)
        for (int c = 0; c < 3; c++)
            v[c] /= len;
}

/* Segments per curve, summing to `segments`: *count curves, caller frees. */
static uint32_t *curve_lengths(size_t segments, uint64_t seed, size_t *count)
{
    size_t cap = segments / SL_FURBALL_MIN + 1;
    uint32_t *len = malloc(cap * sizeof *len);
    if (!len)
        return NULL;
    sl_rng rng;
    sl_rng_seed(&rng, seed, UINT64_MAX);
    size_t n = 0, left = segments;
    while (left > 0) {
        size_t s = (size_t)sl_rng_int(&rng, SL_FURBALL_MIN, SL_FURBALL_MAX);
        if (s > left)
            s = left;
        len[n++] = (uint32_t)s;
        left -= s;
    }
    *count = n;
    return len;
}

static void trace_curve(sl_rng *rng, size_t segs, float *pos, float *arclen)
{
    double p[3], d[3], w[3] = {0.0, 0.0, 0.0};
    sl_rng_in_ball(rng, p);
    for (int c = 0; c < 3; c++)
        p[c] *= 0.9;
    sl_rng_on_sphere(rng, d);
    double h = SL_FURBALL_STEP, kick = SL_FURBALL_KICK * sqrt(h);
    for (size_t i = 0; i <= segs; i++) {
        for (int c = 0; c < 3; c++)
            pos[3 * i + c] = (float)p[c];
        arclen[i] = (float)(h * (double)i);
        for (int c = 0; c < 3; c++)
            w[c] = SL_FURBALL_DAMP * w[c] + kick * sl_rng_normal(rng);
        double turn[3] = {w[1] * d[2] - w[2] * d[1], w[2] * d[0] - w[0] * d[2], w[0] * d[1] - w[1] * d[0]};
        double r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        double pull = r > SL_FURBALL_SHELL ? SL_FURBALL_PULL * (r - SL_FURBALL_SHELL) / r : 0.0;
        for (int c = 0; c < 3; c++)
            d[c] += h * (turn[c] - pull * p[c]);
        normalize3(d);
        for (int c = 0; c < 3; c++)
            p[c] += h * d[c];
    }
}

static sl_status furball_generate(const double *values, sl_dataset **out, sl_err *err)
{
    size_t segments = (size_t)values[K_SEGMENTS];
    uint64_t seed = (uint64_t)values[K_SEED];
    size_t curves = 0;
    uint32_t *len = curve_lengths(segments, seed, &curves);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "furball");
    if (!len || !ds) {
        free(len);
        sl_dataset_destroy(ds);
        return sl_err_set(err, SL_ERR_NOMEM, "furball: out of memory for %zu segments", segments);
    }
    sl_lines *l = &ds->lines;
    float *arclen = NULL;
    if (sl_lines_alloc(l, curves, segments + curves, 0, 0, err) != SL_OK ||
        !(arclen = sl_lines_add_attribute(l, "arclength", 0, err)))
        goto fail;
    size_t base = 0;
    for (size_t k = 0; k < curves; k++) {
        sl_rng rng;
        sl_rng_seed(&rng, seed, k);
        l->line_offsets[k] = (uint32_t)base;
        trace_curve(&rng, len[k], l->positions + 3 * base, arclen + base);
        base += (size_t)len[k] + 1;
    }
    l->line_offsets[curves] = (uint32_t)base;
    if (sl_dataset_finish_lines(ds, err) != SL_OK)
        goto fail;
    free(len);
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "furball");
    free(len);
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_furball = {
    .name = "furball",
    .kind = SL_DATASET_LINES,
    .description = "random smoothly curling curves in the unit ball, exact total segment count; attribute arclength",
    .keys_help = "segments = total segment count (1..10000000, default 100000), seed",
    .key_count = 2,
    .keys = {
        {.name = "segments", .type = SL_GEN_INT, .min = 1, .max = 10000000, .def = 100000},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
    },
    .generate = furball_generate,
};
