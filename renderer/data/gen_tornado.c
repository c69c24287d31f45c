/* gen_tornado.c — streamlines of Crawfis' analytic tornado vector field.
 *
 * The field (R. Crawfis' classic test data, tornadoSrc.c, Ohio State; written
 * here once from its formula, gen_tornado_field.h, and compiled for double
 * and for dual numbers that carry its exact derivatives): a helical vortex in
 * [0,1]^3 whose centre (xc, yc) moves with height z and whose radius grows
 * with z; outside
 * its core the flow rotates the other way and drifts upward. Lines are traced
 * with RK4 in arc length, backward and forward from a seeded random start
 * point (the forward flow spirals outward); a line that leaves the box
 * [-0.25, 1.25]^2 x [0, 1] (the field's height range) is re-seeded (up to SL_TORNADO_TRIES times; about 70% are
 * kept) so every line has exactly `points` vertices and the same length
 * SL_TORNADO_LENGTH whatever `points` is: more points = finer, not longer.
 * Stores the field value at each vertex as the tangent and |v| as "speed",
 * then "helicity" (curl v).v and "vorticity_magnitude" |curl v| at the stored
 * vertex, from exact derivatives of the same formula (gen_tornado.h).
 * `time` is the original's phase parameter: it rotates the vortex centre
 * (steady field for each value; 0 by default). Any thread.
 */
#include "gen_tornado.h"

#include "gen_dual.h"
#include "gen_family.h"
#include "gen_random.h"
#include "gen_trace.h"

#include <math.h>
#include <stdio.h>

#define SL_TORNADO_TRIES 64
#define SL_TORNADO_LENGTH 1.5 /* arc length of every line, world units */
#define SL_TORNADO_SEED_DISC 0.8 /* start points within this fraction of r + r2 of the axis */

enum { K_LINES, K_POINTS, K_SEED, K_TIME };

/* The formula twice from one text: plain double for the tracer, dual numbers for the curl. */
#define SL_TORNADO_NUM double
#define SL_TORNADO_SLICE tornado_slice
#define SL_TORNADO_FIELD tornado_real
#include "gen_tornado_field.h"

#define SL_TORNADO_NUM sl_dual3
#define SL_TORNADO_SLICE tornado_slice_dual
#define SL_TORNADO_FIELD tornado_dual
#include "gen_tornado_field.h"

static void tornado_field(const double p[3], const void *ctx, double v[3])
{
    tornado_real(p, *(const double *)ctx, v);
}

void sl_gen_tornado_eval(const double p[3], double phase, double v[3], double curl[3])
{
    sl_dual3 d[3];
    tornado_dual(p, phase, d);
    for (int c = 0; c < 3; c++)
        v[c] = d[c].v;
    curl[0] = d[2].d[1] - d[1].d[2];
    curl[1] = d[0].d[2] - d[2].d[0];
    curl[2] = d[1].d[0] - d[0].d[1];
}

static sl_status tornado_generate(const double *values, sl_dataset **out, sl_err *err)
{
    size_t lines = (size_t)values[K_LINES], points = (size_t)values[K_POINTS];
    uint64_t seed = (uint64_t)values[K_SEED];
    double phase = values[K_TIME];
    if ((double)lines * (double)points > SL_MAX_VERTICES)
        return sl_err_set(err, SL_ERR_LIMIT, "tornado: lines * points = %zu exceeds the limit of %u vertices",
                          lines * points, SL_MAX_VERTICES);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "tornado");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "tornado: out of memory");
    sl_lines *l = &ds->lines;
    sl_status st = sl_lines_alloc(l, lines, lines * points, 0, 1, err);
    float *speed = st == SL_OK ? sl_lines_add_attribute(l, "speed", 0, err) : NULL;
    float *helicity = speed ? sl_lines_add_attribute(l, SL_ATTR_HELICITY, 0, err) : NULL;
    float *vorticity = helicity ? sl_lines_add_attribute(l, SL_ATTR_VORTICITY, 0, err) : NULL;
    if (!vorticity)
        goto fail;
    const double lo[3] = {-0.25, -0.25, 0.0}, hi[3] = {1.25, 1.25, 1.0};
    double h = SL_TORNADO_LENGTH / (double)(points - 1);
    for (size_t k = 0; k < lines; k++) {
        sl_rng rng;
        sl_rng_seed(&rng, seed, k);
        size_t base = k * points;
        l->line_offsets[k] = (uint32_t)base;
        for (int attempt = 0; attempt < SL_TORNADO_TRIES; attempt++) {
            /* Uniform in a disc of SL_TORNADO_SEED_DISC (r + r2) around the
             * vortex centre at a uniform height: most such lines stay in the box. */
            double z = sl_rng_range(&rng, 0.0, 1.0), xc, yc, r, r2;
            tornado_slice(z, phase, &xc, &yc, &r, &r2);
            double ang = sl_rng_range(&rng, 0.0, 6.283185307179586);
            double rad = SL_TORNADO_SEED_DISC * (r + r2) * sqrt(sl_rng_uniform(&rng));
            double start[3] = {xc + rad * cos(ang), yc + rad * sin(ang), z};
            int last = attempt + 1 == SL_TORNADO_TRIES; /* keep it whole, wherever it goes */
            if (sl_trace_rk4_centred(tornado_field, &phase, start, h, points, last ? NULL : lo, last ? NULL : hi,
                                     l->positions + 3 * base, l->tangents + 3 * base))
                break;
        }
        for (size_t i = base; i < base + points; i++) {
            const float *t = l->tangents + 3 * i;
            speed[i] = (float)sqrt((double)t[0] * t[0] + (double)t[1] * t[1] + (double)t[2] * t[2]);
            /* Helicity and vorticity at the stored (float) position, in double. */
            const double q[3] = {l->positions[3 * i], l->positions[3 * i + 1], l->positions[3 * i + 2]};
            double v[3], w[3];
            sl_gen_tornado_eval(q, phase, v, w);
            helicity[i] = (float)(v[0] * w[0] + v[1] * w[1] + v[2] * w[2]);
            vorticity[i] = (float)sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        }
    }
    l->line_offsets[lines] = (uint32_t)(lines * points);
    st = sl_dataset_finish_lines(ds, err);
    if (st != SL_OK)
        goto fail;
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "tornado");
    sl_dataset_destroy(ds);
    return err->status;
}

const sl_gen_family sl_gen_tornado = {
    .name = "tornado",
    .kind = SL_DATASET_LINES,
    .description = "RK4 streamlines of Crawfis' analytic tornado vortex in [0,1]^3; tangents = velocity, attributes speed, helicity, vorticity_magnitude",
    .keys_help = "lines (1..1000000, default 1000), points per line (2..10000, default 200), seed (0..2^53-1, default 1), time phase (0..10000, default 0)",
    .key_count = 4,
    .keys = {
        {.name = "lines", .type = SL_GEN_INT, .min = 1, .max = 1000000, .def = 1000},
        {.name = "points", .type = SL_GEN_INT, .min = 2, .max = 10000, .def = 200},
        {.name = "seed", .type = SL_GEN_INT, .min = 0, .max = SL_GEN_SEED_MAX, .def = 1},
        {.name = "time", .type = SL_GEN_NUMBER, .min = 0, .max = 10000, .def = 0},
    },
    .generate = tornado_generate,
};
