/* gen_bundle.c — a helical fibre bundle: many fibres twisting around one curved axis.
 *
 * The axis is a smooth space curve (an arc with an out-of-plane wobble)
 * sampled at `points` parameters, with a rotation-minimising frame (N, B)
 * transported along it. Fibre j sits at a seeded polar offset (rho_j, phi_j)
 * in that frame; the offset twists `twist` turns along the axis, fans out
 * towards both ends, and carries a small smooth per-fibre wobble, like a
 * tractography bundle. Attributes: per-vertex "curvature" (discrete, 1/world
 * unit) and "radial" (rho_j / spread, 0 at the axis, 1 at the rim); per-line
 * "fiber_index". No tangents. Any thread.
 */
#include "gen_family.h"
#include "gen_random.h"

#include <math.h>
#include <stdlib.h>

enum { K_LINES, K_POINTS, K_SEED, K_TWIST, K_SPREAD };

#define SL_BUNDLE_PI 3.141592653589793

static void axis_point(double t, double p[3])
{
    double theta = 1.6 * (t - 0.5), r = 2.0;
    p[0] = r * sin(theta);
    p[1] = r * (1.0 - cos(theta));
    p[2] = 0.4 * sin(2.0 * SL_BUNDLE_PI * t);
}

static void normalize3(double v[3])
{
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len > 0.0)
        for (int c = 0; c < 3; c++)
            v[c] /= len;
}

/* Axis samples and a rotation-minimising frame (projection transport), 9 doubles per sample. */
static void axis_frames(size_t points, double *f)
{
    for (size_t i = 0; i < points; i++) {
        double t = (double)i / (double)(points - 1), a[3], b[3], tan[3];
        double *c = f + 9 * i, *n = c + 3, *bn = c + 6;
        axis_point(t, c);
        axis_point(t - 1e-4, a);
        axis_point(t + 1e-4, b);
        for (int k = 0; k < 3; k++)
            tan[k] = b[k] - a[k];
        normalize3(tan);
        if (i == 0) {
            n[0] = 0.0; n[1] = 0.0; n[2] = 1.0;
        } else {
            for (int k = 0; k < 3; k++)
                n[k] = f[9 * (i - 1) + 3 + k];
        }
        double d = n[0] * tan[0] + n[1] * tan[1] + n[2] * tan[2];
        for (int k = 0; k < 3; k++)
            n[k] -= d * tan[k];
        normalize3(n);
        bn[0] = tan[1] * n[2] - tan[2] * n[1];
        bn[1] = tan[2] * n[0] - tan[0] * n[2];
        bn[2] = tan[0] * n[1] - tan[1] * n[0];
    }
}

/* Turning angle per unit length at each vertex of one line (ends copy their neighbour). */
static void line_curvature(const float *p, size_t n, float *kappa)
{
    for (size_t i = 1; i + 1 < n; i++) {
        double a[3], b[3];
        for (int c = 0; c < 3; c++) {
            a[c] = (double)p[3 * i + c] - p[3 * (i - 1) + c];
            b[c] = (double)p[3 * (i + 1) + c] - p[3 * i + c];
        }
        double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
        double angle = atan2(sqrt(cx * cx + cy * cy + cz * cz), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
        double len = 0.5 * (sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) + sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]));
        kappa[i] = len > 0.0 ? (float)(angle / len) : 0.0f;
    }
    if (n >= 3) {
        kappa[0] = kappa[1];
        kappa[n - 1] = kappa[n - 2];
    }
}

static sl_status bundle_generate(const double *values, sl_dataset **out, sl_err *err)
{
    size_t lines = (size_t)values[K_LINES], points = (size_t)values[K_POINTS];
    uint64_t seed = (uint64_t)values[K_SEED];
    double twist = values[K_TWIST], spread = values[K_SPREAD];
    if ((double)lines * (double)points > SL_MAX_VERTICES)
        return sl_err_set(err, SL_ERR_LIMIT, "bundle: lines * points = %zu exceeds the limit of %u vertices",
                          lines * points, SL_MAX_VERTICES);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "bundle");
    double *frames = malloc(points * 9 * sizeof *frames);
    if (!ds || !frames) {
        free(frames);
        sl_dataset_destroy(ds);
        return sl_err_set(err, SL_ERR_NOMEM, "bundle: out of memory");
    }
    sl_lines *l = &ds->lines;
    float *curv = NULL, *radial = NULL, *index = NULL;
    if (sl_lines_alloc(l, lines, lines * points, 0, 0, err) != SL_OK ||
        !(curv = sl_lines_add_attribute(l, "curvature", 0, err)) ||
        !(radial = sl_lines_add_attribute(l, "radial", 0, err)) ||
        !(index = sl_lines_add_attribute(l, "fiber_index", 1, err)))
        goto fail;
    axis_frames(points, frames);
    for (size_t j = 0; j < lines; j++) {
        sl_rng rng;
        sl_rng_seed(&rng, seed, j);
        double u = sqrt(sl_rng_uniform(&rng)), phi = sl_rng_range(&rng, 0.0, 2.0 * SL_BUNDLE_PI);
        double w_amp = 0.15 * spread * sl_rng_uniform(&rng);
        double w_freq[2] = {sl_rng_range(&rng, 1.0, 4.0), sl_rng_range(&rng, 1.0, 4.0)};
        double w_phase[2] = {sl_rng_range(&rng, 0.0, 6.3), sl_rng_range(&rng, 0.0, 6.3)};
        size_t base = j * points;
        l->line_offsets[j] = (uint32_t)base;
        index[j] = (float)j;
        for (size_t i = 0; i < points; i++) {
            double t = (double)i / (double)(points - 1);
            const double *c = frames + 9 * i, *n = c + 3, *b = c + 6;
            double fan = 1.0 + 0.8 * (2.0 * t - 1.0) * (2.0 * t - 1.0);
            double ang = phi + 2.0 * SL_BUNDLE_PI * twist * t;
            double on = spread * u * fan * cos(ang) + w_amp * sin(2.0 * SL_BUNDLE_PI * w_freq[0] * t + w_phase[0]);
            double ob = spread * u * fan * sin(ang) + w_amp * sin(2.0 * SL_BUNDLE_PI * w_freq[1] * t + w_phase[1]);
            for (int k = 0; k < 3; k++)
                l->positions[3 * (base + i) + k] = (float)(c[k] + on * n[k] + ob * b[k]);
            radial[base + i] = (float)u;
        }
        line_curvature(l->positions + 3 * base, points, curv + base);
    }
    l->line_offsets[lines] = (uint32_t)(lines * points);
    if (sl_dataset_finish_lines(ds, err) != SL_OK)
        goto fail;
    free(frames);
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "bundle");
    free(frames);
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_bundle = {
    .name = "bundle",
    .kind = SL_DATASET_LINES,
    .description = "fibres twisting around one curved axis, fanning at the ends; attributes curvature, radial, fiber_index (per line)",
    .keys_help = "lines = fibres (1..1000000, default 2000), points per fibre (2..10000, default 100), seed, "
                 "twist turns (0..20, default 1.5), spread radius (0.01..1, default 0.25)",
    .key_count = 5,
    .keys = {
        {.name = "lines", .type = SL_GEN_INT, .min = 1, .max = 1000000, .def = 2000},
        {.name = "points", .type = SL_GEN_INT, .min = 2, .max = 10000, .def = 100},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
        {.name = "twist", .type = SL_GEN_NUMBER, .min = 0, .max = 20, .def = 1.5},
        {.name = "spread", .type = SL_GEN_NUMBER, .min = 0.01, .max = 1, .def = 0.25},
    },
    .generate = bundle_generate,
};
