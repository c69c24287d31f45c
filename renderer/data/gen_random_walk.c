/* gen_random_walk.c — random polylines in a box: the benchmark set the peers are compared on.
 *
 * Each line starts at a seeded point of the box [-half, half]^3 and walks with
 * steps that follow an AR(1) process, s' = PHI s + SIGMA sqrt(1 - PHI^2) n
 * (n standard normal per axis), so consecutive segments are correlated and
 * their lengths are mostly 0.01-0.05 (mean about 0.03); a step that would
 * leave the box is mirrored at the wall. Radii vary smoothly along each line
 * between radius_min and radius_max (a sine of seeded phase), so a file of it
 * carries a per-vertex radius. No tangents, no attributes. Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"

#include <math.h>

#include "../core/sl_math.h"

#define SL_WALK_PHI 0.9        /* step kept per step: memory of about 10 segments */
#define SL_WALK_SIGMA 0.018    /* per-axis step deviation: |step| about 1.6 SIGMA */
#define SL_WALK_RADIUS_RATE 0.05 /* radians of radius phase per vertex */

enum { K_LINES, K_POINTS, K_HALF, K_RMIN, K_RMAX, K_SEED };

static double reflect(double x, double half)
{
    /* One mirror suffices: a step is far shorter than the box. */
    if (x > half)
        return 2.0 * half - x;
    if (x < -half)
        return -2.0 * half - x;
    return x;
}

static void walk_line(sl_rng *rng, size_t points, double half, double rmin, double rmax, float *pos, float *rad)
{
    double p[3], s[3];
    for (int c = 0; c < 3; c++) {
        p[c] = (2.0 * sl_rng_uniform(rng) - 1.0) * half;
        s[c] = SL_WALK_SIGMA * sl_rng_normal(rng);
    }
    double phase = 2.0 * SL_PI * sl_rng_uniform(rng);
    double keep = sqrt(1.0 - SL_WALK_PHI * SL_WALK_PHI);
    for (size_t i = 0; i < points; i++) {
        for (int c = 0; c < 3; c++)
            pos[3 * i + c] = (float)p[c];
        rad[i] = (float)(rmin + (rmax - rmin) * (0.5 + 0.5 * sin(phase + SL_WALK_RADIUS_RATE * (double)i)));
        for (int c = 0; c < 3; c++) {
            s[c] = SL_WALK_PHI * s[c] + SL_WALK_SIGMA * keep * sl_rng_normal(rng);
            double next = reflect(p[c] + s[c], half);
            if (next != p[c] + s[c])
                s[c] = -s[c];
            p[c] = next;
        }
    }
}

static sl_status random_walk_generate(const double *values, sl_dataset **out, sl_err *err)
{
    size_t lines = (size_t)values[K_LINES], points = (size_t)values[K_POINTS];
    double half = values[K_HALF], rmin = values[K_RMIN], rmax = values[K_RMAX];
    uint64_t seed = (uint64_t)values[K_SEED];
    if (rmin > rmax)
        return sl_err_set(err, SL_ERR_INVALID, "random_walk: radius_min %g exceeds radius_max %g", rmin, rmax);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "random_walk");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "random_walk: out of memory");
    sl_lines *l = &ds->lines;
    if (lines * points > SL_MAX_VERTICES) {
        sl_err_set(err, SL_ERR_LIMIT, "lines x points = %zu exceeds %u vertices", lines * points, SL_MAX_VERTICES);
        goto fail;
    }
    if (sl_lines_alloc(l, lines, lines * points, 1, 0, err) != SL_OK)
        goto fail;
    for (size_t k = 0; k < lines; k++) {
        sl_rng rng;
        sl_rng_seed(&rng, seed, k);
        l->line_offsets[k] = (uint32_t)(k * points);
        walk_line(&rng, points, half, rmin, rmax, l->positions + 3 * k * points, l->radii + k * points);
    }
    l->line_offsets[lines] = (uint32_t)(lines * points);
    if (sl_dataset_finish_lines(ds, err) != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "random_walk");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_random_walk = {
    .name = "random_walk",
    .kind = SL_DATASET_LINES,
    .description = "random polylines with AR(1) steps (about 0.01-0.05 long) in a box, smooth per-vertex radii",
    .keys_help = "lines (1..1000000, default 1000), points per line (2..10000, default 200), half = box half-size "
                 "(0.1..1000, default 3), radius_min / radius_max (0..100, default 0.004 / 0.006), seed",
    .key_count = 6,
    .keys = {
        {.name = "lines", .type = SL_GEN_INT, .min = 1, .max = 1000000, .def = 1000},
        {.name = "points", .type = SL_GEN_INT, .min = 2, .max = 10000, .def = 200},
        {.name = "half", .type = SL_GEN_NUMBER, .min = 0.1, .max = 1000, .def = 3},
        {.name = "radius_min", .type = SL_GEN_NUMBER, .min = 0, .max = 100, .def = 0.004},
        {.name = "radius_max", .type = SL_GEN_NUMBER, .min = 0, .max = 100, .def = 0.006},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
    },
    .generate = random_walk_generate,
};
