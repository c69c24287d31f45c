/* test_generate.c — the dataset generators, their key validation and sightline-info.
 *
 * Checks determinism (same call -> identical bytes, other seed -> other
 * bytes), counts against the keys, finiteness, the fields against
 * independent double-precision transcriptions of their formulas (tornado,
 * ABC, Marschner–Lobb, torus, ellipsoid with its u16/u8 mapping, anisotropy,
 * slices, plateau and sheet), the RK4 tracer against an exact circle, the
 * hotroom radius/segment invariant, key errors naming the key, and runs
 * bin/sightline-info as a process (SIGHTLINE_BINARY_DIR) on a generator call.
 * Bounds: float storage of positions (~1e-7 relative) dominates every
 * tolerance below; each states its own.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/sl_clock.h"
#include "data/gen_family.h"
#include "data/gen_random.h"
#include "data/gen_tornado.h"
#include "data/gen_trace.h"
#include "data/sl_generate.h"
#include "sl_test.h"

#if defined(__SANITIZE_ADDRESS__)
#define SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SANITIZED 1
#endif
#endif
#ifndef SANITIZED
#define SANITIZED 0
#endif

#define PI 3.141592653589793

static sl_dataset *gen(const char *json)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_generate_json(json, &ds, &err);
    SL_CHECK_MSG(st == SL_OK && ds, "%s -> %s", json, err.message);
    return st == SL_OK ? ds : NULL;
}

static int arrays_equal(const void *a, const void *b, size_t bytes)
{
    if (!a || !b)
        return a == b;
    return memcmp(a, b, bytes) == 0;
}

/* Byte-identical datasets (arrays, origin, bounds, attribute ranges). */
static int datasets_equal(const sl_dataset *a, const sl_dataset *b)
{
    if (a->kind != b->kind || memcmp(&a->origin, &b->origin, sizeof a->origin) ||
        memcmp(&a->bounds_min, &b->bounds_min, sizeof a->bounds_min) ||
        memcmp(&a->bounds_max, &b->bounds_max, sizeof a->bounds_max))
        return 0;
    if (a->kind == SL_DATASET_LINES) {
        const sl_lines *x = &a->lines, *y = &b->lines;
        size_t n = x->vertex_count;
        if (x->line_count != y->line_count || n != y->vertex_count ||
            x->attribute_count != y->attribute_count || x->line_attribute_count != y->line_attribute_count)
            return 0;
        if (!arrays_equal(x->line_offsets, y->line_offsets, (x->line_count + 1) * 4) ||
            !arrays_equal(x->positions, y->positions, n * 12) || !arrays_equal(x->radii, y->radii, n * 4) ||
            !arrays_equal(x->tangents, y->tangents, n * 12) || !arrays_equal(x->normals, y->normals, n * 12))
            return 0;
        for (int i = 0; i < x->attribute_count; i++)
            if (strcmp(x->attributes[i].name, y->attributes[i].name) ||
                !arrays_equal(x->attributes[i].values, y->attributes[i].values, n * 4))
                return 0;
        for (int i = 0; i < x->line_attribute_count; i++)
            if (!arrays_equal(x->line_attributes[i].values, y->line_attributes[i].values, x->line_count * 4))
                return 0;
        return 1;
    }
    const sl_volume *x = &a->volume, *y = &b->volume;
    if (memcmp(x->dims, y->dims, sizeof x->dims) || x->type != y->type || x->components != y->components)
        return 0;
    size_t bytes = (size_t)x->dims[0] * x->dims[1] * x->dims[2] * x->components * sl_voxel_type_size(x->type);
    return arrays_equal(x->data, y->data, bytes);
}

static int all_finite(const sl_dataset *ds)
{
    if (ds->kind != SL_DATASET_LINES)
        return sl_v3_is_finite(ds->bounds_min) && sl_v3_is_finite(ds->bounds_max) &&
               isfinite(ds->volume.value_min) && isfinite(ds->volume.value_max);
    const sl_lines *l = &ds->lines;
    for (size_t i = 0; i < 3 * l->vertex_count; i++)
        if (!isfinite(l->positions[i]) || (l->tangents && !isfinite(l->tangents[i])))
            return 0;
    for (size_t i = 0; l->radii && i < l->vertex_count; i++)
        if (!isfinite(l->radii[i]) || !(l->radii[i] > 0.0f))
            return 0;
    for (int a = 0; a < l->attribute_count; a++)
        for (size_t i = 0; i < l->vertex_count; i++)
            if (!isfinite(l->attributes[a].values[i]))
                return 0;
    return 1;
}

static void world(const sl_dataset *ds, size_t v, double p[3])
{
    p[0] = ds->origin.x + ds->lines.positions[3 * v];
    p[1] = ds->origin.y + ds->lines.positions[3 * v + 1];
    p[2] = ds->origin.z + ds->lines.positions[3 * v + 2];
}

/* Each family: twice the same call, then another seed. */
static void test_determinism(void)
{
    static const char *calls[][2] = {
        {"{\"generator\":\"tornado\",\"lines\":40,\"points\":50}", "{\"generator\":\"tornado\",\"lines\":40,\"points\":50,\"seed\":2}"},
        {"{\"generator\":\"abc\",\"lines\":40,\"points\":50}", "{\"generator\":\"abc\",\"lines\":40,\"points\":50,\"seed\":2}"},
        {"{\"generator\":\"bundle\",\"lines\":40,\"points\":50}", "{\"generator\":\"bundle\",\"lines\":40,\"points\":50,\"seed\":2}"},
        {"{\"generator\":\"furball\",\"segments\":5000}", "{\"generator\":\"furball\",\"segments\":5000,\"seed\":2}"},
        {"{\"generator\":\"hotroom\",\"lines\":500}", "{\"generator\":\"hotroom\",\"lines\":500,\"seed\":2}"},
        {"{\"generator\":\"random_walk\",\"lines\":40,\"points\":50}", "{\"generator\":\"random_walk\",\"lines\":40,\"points\":50,\"seed\":2}"},
        {"{\"generator\":\"marschner_lobb\",\"size\":16,\"noise\":0.1}", "{\"generator\":\"marschner_lobb\",\"size\":16,\"noise\":0.1,\"seed\":2}"},
        {"{\"generator\":\"torus\",\"size\":16,\"noise\":0.1}", "{\"generator\":\"torus\",\"size\":16,\"noise\":0.1,\"seed\":2}"},
        {"{\"generator\":\"head\",\"size\":16,\"noise\":0.5}", "{\"generator\":\"head\",\"size\":16,\"noise\":0.5,\"seed\":2}"},
    };
    for (size_t i = 0; i < sizeof calls / sizeof calls[0]; i++) {
        sl_dataset *a = gen(calls[i][0]), *b = gen(calls[i][0]), *c = gen(calls[i][1]);
        if (a && b && c) {
            SL_CHECK_MSG(datasets_equal(a, b), "%s: two calls differ", calls[i][0]);
            SL_CHECK_MSG(!datasets_equal(a, c), "%s: seed 2 gives the same data", calls[i][0]);
            SL_CHECK_MSG(all_finite(a), "%s: non-finite values", calls[i][0]);
        }
        sl_dataset_destroy(a);
        sl_dataset_destroy(b);
        sl_dataset_destroy(c);
    }
    /* The tornado's time phase moves the vortex. */
    sl_dataset *t0 = gen("{\"generator\":\"tornado\",\"lines\":5,\"points\":20}");
    sl_dataset *t1 = gen("{\"generator\":\"tornado\",\"lines\":5,\"points\":20,\"time\":40}");
    if (t0 && t1)
        SL_CHECK(!datasets_equal(t0, t1));
    sl_dataset_destroy(t0);
    sl_dataset_destroy(t1);
    /* The extreme seeds are accepted and differ from each other. */
    sl_dataset *lo = gen("{\"generator\":\"furball\",\"segments\":100,\"seed\":0}");
    sl_dataset *hi = gen("{\"generator\":\"furball\",\"segments\":100,\"seed\":9007199254740991}");
    if (lo && hi)
        SL_CHECK(!datasets_equal(lo, hi));
    sl_dataset_destroy(lo);
    sl_dataset_destroy(hi);
}

/* Lines families with lines/points keys: exact counts, every line `points` long. */
static void test_counts(void)
{
    static const char *names[] = {"tornado", "abc", "bundle", "random_walk"};
    for (int f = 0; f < 4; f++) {
        char json[256];
        snprintf(json, sizeof json, "{\"generator\":\"%s\",\"lines\":37,\"points\":23,\"seed\":5}", names[f]);
        sl_dataset *ds = gen(json);
        if (!ds)
            continue;
        const sl_lines *l = &ds->lines;
        SL_CHECK(ds->kind == SL_DATASET_LINES);
        SL_CHECK(strcmp(ds->name, names[f]) == 0);
        SL_CHECK(l->line_count == 37);
        SL_CHECK(l->vertex_count == 37 * 23);
        int uniform = 1;
        for (size_t k = 0; k < l->line_count; k++)
            uniform &= l->line_offsets[k + 1] - l->line_offsets[k] == 23;
        SL_CHECK_MSG(uniform, "%s: a line is not 23 points long", names[f]);
        sl_dataset_destroy(ds);
    }
    /* Minimal sizes. */
    sl_dataset *ds = gen("{\"generator\":\"tornado\",\"lines\":1,\"points\":2}");
    if (ds)
        SL_CHECK(ds->lines.line_count == 1 && ds->lines.vertex_count == 2);
    sl_dataset_destroy(ds);
    ds = gen("{\"generator\":\"hotroom\",\"lines\":777}");
    if (ds) {
        SL_CHECK(ds->lines.line_count == 777);
        int ok = 1;
        for (size_t k = 0; k < 777; k++) {
            uint32_t n = ds->lines.line_offsets[k + 1] - ds->lines.line_offsets[k];
            ok &= n >= 2 && n <= 5;
        }
        SL_CHECK_MSG(ok, "hotroom line with fewer than 2 or more than 5 points");
    }
    sl_dataset_destroy(ds);
}

static size_t segment_count(const sl_lines *l)
{
    size_t s = 0;
    for (size_t k = 0; k < l->line_count; k++)
        s += l->line_offsets[k + 1] - l->line_offsets[k] - 1;
    return s;
}

/* random_walk: inside the box (mirrored steps), segment lengths of the
 * benchmark's description, radii in their range, a reversed range refused. */
static void test_random_walk(void)
{
    sl_dataset *ds = gen("{\"generator\":\"random_walk\",\"lines\":200,\"points\":200,\"half\":3,"
                         "\"radius_min\":0.04,\"radius_max\":0.06,\"seed\":4}");
    if (ds) {
        const sl_lines *l = &ds->lines;
        SL_CHECK(l->radii != NULL && l->line_count == 200 && l->vertex_count == 40000);
        double sum = 0.0, inside = 0.0;
        size_t segs = 0, short_or_long = 0;
        for (size_t k = 0; k < l->line_count; k++)
            for (uint32_t i = l->line_offsets[k]; i + 1 < l->line_offsets[k + 1]; i++) {
                double a[3], b[3], d2 = 0.0;
                world(ds, i, a);
                world(ds, i + 1, b);
                for (int c = 0; c < 3; c++)
                    d2 += (b[c] - a[c]) * (b[c] - a[c]);
                double len = sqrt(d2);
                sum += len;
                short_or_long += len < 0.005 || len > 0.1;
                segs++;
            }
        for (size_t v = 0; v < l->vertex_count; v++) {
            double p[3];
            world(ds, v, p);
            inside += fabs(p[0]) <= 3.0 + 1e-6 && fabs(p[1]) <= 3.0 + 1e-6 && fabs(p[2]) <= 3.0 + 1e-6;
            SL_CHECK_MSG(l->radii[v] >= 0.04f - 1e-7f && l->radii[v] <= 0.06f + 1e-7f, "radius %g", l->radii[v]);
        }
        double mean = sum / (double)segs;
        SL_CHECK_MSG(mean > 0.02 && mean < 0.04, "mean segment length %g, want about 0.03", mean);
        SL_CHECK_MSG(short_or_long < segs / 20, "%zu of %zu segments outside [0.005, 0.1]", short_or_long, segs);
        SL_CHECK_MSG(inside == (double)l->vertex_count, "%.0f of %zu vertices inside the box", inside, l->vertex_count);
    }
    sl_dataset_destroy(ds);
    sl_dataset *bad = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"random_walk\",\"radius_min\":0.2,\"radius_max\":0.1}", &bad, NULL) ==
                 SL_ERR_INVALID && !bad);
}

static void test_furball(void)
{
    static const int targets[] = {1, 39, 12345, 100000};
    for (size_t i = 0; i < sizeof targets / sizeof targets[0]; i++) {
        char json[128];
        snprintf(json, sizeof json, "{\"generator\":\"furball\",\"segments\":%d}", targets[i]);
        sl_dataset *ds = gen(json);
        if (!ds)
            continue;
        size_t s = segment_count(&ds->lines);
        SL_CHECK_MSG(fabs((double)s - targets[i]) <= 0.01 * targets[i], "%zu segments for %d", s, targets[i]);
        /* Curves stay near the unit ball (steering starts at 0.85). */
        double r = sl_v3_length(ds->bounds_max) > sl_v3_length(ds->bounds_min) ? sl_v3_length(ds->bounds_max)
                                                                                 : sl_v3_length(ds->bounds_min);
        SL_CHECK_MSG(r < 1.9, "furball bounds corner at %g", r); /* corner of a box around radius ~1.05 */
        SL_CHECK(sl_lines_find_attribute(&ds->lines, "arclength") >= 0);
        sl_dataset_destroy(ds);
    }
    double t0 = sl_clock_ms();
    sl_dataset *ds = gen("{\"generator\":\"furball\",\"segments\":787000}");
    double ms = sl_clock_ms() - t0;
    /* Printed, not asserted: a budget in ms would fail on a slow machine (speed belongs in bench/). */
    printf("furball 787000 segments: %.0f ms%s\n", ms, SANITIZED ? " (sanitized build)" : "");
    if (ds) {
        size_t s = segment_count(&ds->lines);
        SL_CHECK_MSG(fabs((double)s - 787000.0) <= 7870.0, "%zu segments", s);
        SL_CHECK(all_finite(ds));
    }
    sl_dataset_destroy(ds);
}

/* Independent transcription of Crawfis' tornado at time phase `phase`,
 * valid in the box. branch[] (may be NULL) receives the four quantities whose
 * sign picks a branch of the piecewise formula: |r - dist| - r2 (the
 * discontinuous scale switch), r - dist (the kink of |.|), 0.1 - dist z (the
 * clamp of z0 at 0) and dist (the axis). */
static void tornado_ref_full(const double p[3], double phase, double v[3], double branch[4])
{
    double x = p[0], y = p[1], z = p[2];
    double xc = 0.5 + 0.1 * sin(0.04 * phase + 10.0 * z), yc = 0.5 + 0.1 * cos(0.03 * phase + 3.0 * z);
    double r = 0.1 + 0.4 * z * z + 0.1 * z * sin(8.0 * z), r2 = 0.2 + 0.1 * z;
    double t = hypot(x - xc, y - yc);
    double s = fabs(r - t);
    if (branch) {
        branch[0] = s - r2;
        branch[1] = r - t;
        branch[2] = 0.1 - t * z;
        branch[3] = t;
    }
    s = s > r2 ? 0.8 - s : 1.0;
    double z0 = fmax(0.0, 0.1 * (0.1 - t * z));
    double t3 = sqrt(t * t + z0 * z0);
    s = (r + r2 - t3) * s / (t3 + 1e-11) / (1.0 + z);
    v[0] = s * (y - yc) + 0.1 * (x - xc);
    v[1] = -s * (x - xc) + 0.1 * (y - yc);
    v[2] = s * z0;
}

/* Time 0; *side is |r - dist| - r2 (see tornado_ref_full). */
static void tornado_ref(const double p[3], double v[3], double *side)
{
    double branch[4];
    tornado_ref_full(p, 0.0, v, branch);
    *side = branch[0];
}

static void abc_ref(const double p[3], double v[3])
{
    double a = sqrt(3.0), b = sqrt(2.0), c = 1.0;
    v[0] = a * sin(p[2]) + c * cos(p[1]);
    v[1] = b * sin(p[0]) + a * cos(p[2]);
    v[2] = c * sin(p[1]) + b * cos(p[0]);
}

/* Brute-force reference: follows the unit field of `ref` for arc length h
 * from a in n RK4 sub-steps; *crossed is set when the tornado's scale switch
 * (side) changes sign on the way (the field is discontinuous there). */
static void reference_step(void (*ref)(const double p[3], double v[3], double *side), const double a[3],
                           double h, int n, double out[3], int *crossed)
{
    double p[3] = {a[0], a[1], a[2]}, k[4][3], q[3], v[3], side0, side;
    ref(p, v, &side0);
    *crossed = 0;
    double dh = h / n;
    for (int i = 0; i < n; i++) {
        for (int s = 0; s < 4; s++) {
            static const double at[4] = {0.0, 0.5, 0.5, 1.0};
            for (int c = 0; c < 3; c++)
                q[c] = p[c] + (s ? at[s] * dh * k[s - 1][c] : 0.0);
            ref(q, v, &side);
            if ((side > 0.0) != (side0 > 0.0))
                *crossed = 1;
            double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            for (int c = 0; c < 3; c++)
                k[s][c] = len > 1e-9 ? v[c] / len : v[c] / 1e-9;
        }
        for (int c = 0; c < 3; c++)
            p[c] += dh / 6.0 * (k[0][c] + 2.0 * k[1][c] + 2.0 * k[2][c] + k[3][c]);
    }
    memcpy(out, p, sizeof p);
}

/* Tangent = field at the vertex; each vertex lies where the exact streamline
 * from the previous one arrives after arc length h. */
static void check_streamlines(const char *name, const sl_dataset *ds, double h,
                              void (*ref)(const double p[3], double v[3], double *side))
{
    const sl_lines *l = &ds->lines;
    size_t checked = 0, bad = 0, steps = 0, bad_step = 0;
    double worst = 0.0, worst_step = 0.0;
    for (size_t v = 0; v < l->vertex_count; v += 7) {
        double p[3], f[3], side = 1.0;
        world(ds, v, p);
        ref(p, f, &side);
        if (fabs(side) < 1e-3)
            continue; /* the tornado's scale switch is discontinuous; float positions may fall either side */
        double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), e = 0.0;
        for (int c = 0; c < 3; c++)
            e = fmax(e, fabs(l->tangents[3 * v + c] - f[c]));
        /* float position error ~1e-7 relative times a field gradient of O(10)
         * plus float storage of the tangent: 1e-4 absolute is generous. */
        if (e > 1e-4 + 1e-5 * fl)
            bad++;
        worst = fmax(worst, e);
        checked++;
    }
    for (size_t k = 0; k < l->line_count; k += 3)
        for (uint32_t v = l->line_offsets[k]; v + 1 < l->line_offsets[k + 1]; v++) {
            double a[3], b[3], r[3];
            int crossed;
            world(ds, v, a);
            world(ds, v + 1, b);
            reference_step(ref, a, h, 256, r, &crossed);
            if (crossed)
                continue;
            double e = sqrt((b[0] - r[0]) * (b[0] - r[0]) + (b[1] - r[1]) * (b[1] - r[1]) + (b[2] - r[2]) * (b[2] - r[2]));
            /* Float storage of both ends (~1e-7) plus the tracer's split RK4
             * error (measured ~3e-5 h): within 0.1% of the step. */
            if (e > 1e-3 * h)
                bad_step++;
            worst_step = fmax(worst_step, e / h);
            steps++;
        }
    printf("%s: worst tangent error %.2g, worst step error %.2g h over %zu steps\n", name, worst, worst_step, steps);
    SL_CHECK_MSG(checked > 50, "%s: only %zu vertices checked", name, checked);
    SL_CHECK_MSG(steps > 100, "%s: only %zu steps checked", name, steps);
    SL_CHECK_MSG(bad == 0, "%s: %zu of %zu tangents differ from the field (worst %g)", name, bad, checked, worst);
    SL_CHECK_MSG(bad_step == 0, "%s: %zu of %zu steps off the streamline by > 0.1%% of h (worst %.3g h)", name,
                 bad_step, steps, worst_step);
}

static void abc_ref3(const double p[3], double v[3], double *side)
{
    *side = 1.0;
    abc_ref(p, v);
}

static void test_fields(void)
{
    /* Seeds 15 and 20 put lines in the tight spiral around the vortex axis. */
    for (int seed = 15; seed <= 20; seed += 5) {
        char json[128];
        snprintf(json, sizeof json, "{\"generator\":\"tornado\",\"lines\":60,\"points\":100,\"seed\":%d}", seed);
        sl_dataset *t = gen(json);
        if (t)
            check_streamlines("tornado", t, 1.5 / 99.0, tornado_ref);
        sl_dataset_destroy(t);
    }
    sl_dataset *ds = gen("{\"generator\":\"tornado\",\"lines\":60,\"points\":100,\"seed\":3}");
    if (ds) {
        check_streamlines("tornado", ds, 1.5 / 99.0, tornado_ref);
        int s = sl_lines_find_attribute(&ds->lines, "speed");
        SL_CHECK(s >= 0);
        if (s >= 0) {
            double e = 0.0;
            for (size_t v = 0; v < ds->lines.vertex_count; v++) {
                const float *t = ds->lines.tangents + 3 * v;
                e = fmax(e, fabs(ds->lines.attributes[s].values[v] - sqrt((double)t[0] * t[0] + (double)t[1] * t[1] + (double)t[2] * t[2])));
            }
            SL_CHECK_NEAR(e, 0.0, 1e-6);
        }
        /* Kept lines lie in the re-seeding box [-0.25, 1.25]^2 x [0, 1]. */
        SL_CHECK(ds->bounds_min.x >= -0.25 && ds->bounds_min.y >= -0.25 && ds->bounds_min.z >= 0.0);
        SL_CHECK(ds->bounds_max.x <= 1.25 && ds->bounds_max.y <= 1.25 && ds->bounds_max.z <= 1.0);
    }
    sl_dataset_destroy(ds);

    ds = gen("{\"generator\":\"abc\",\"lines\":30,\"points\":200,\"seed\":4}");
    if (ds) {
        check_streamlines("abc", ds, 2.0 * PI / 199.0, abc_ref3);
        /* Divergence of the reference by central differences at vertices: the
         * flow is solenoidal, so it vanishes up to O(d^2) truncation. */
        double worst = 0.0, d = 1e-4;
        for (size_t v = 0; v < ds->lines.vertex_count; v += 97) {
            double p[3], q[3], a[3], b[3], div = 0.0;
            world(ds, v, p);
            for (int c = 0; c < 3; c++) {
                memcpy(q, p, sizeof q);
                q[c] = p[c] + d;
                abc_ref(q, a);
                q[c] = p[c] - d;
                abc_ref(q, b);
                div += (a[c] - b[c]) / (2.0 * d);
            }
            worst = fmax(worst, fabs(div));
        }
        SL_CHECK_NEAR(worst, 0.0, 1e-6);
    }
    sl_dataset_destroy(ds);
    /* Non-default coefficients reach the field: a = b = c = 0 is no flow. */
    ds = gen("{\"generator\":\"abc\",\"lines\":2,\"points\":5,\"a\":0,\"b\":0,\"c\":0}");
    if (ds)
        SL_CHECK(ds->lines.attributes[0].max == 0.0f);
    sl_dataset_destroy(ds);
}

/* ------------------------------------------------ helicity and vorticity */

static void abc_ref_k(const double p[3], const double k[3], double v[3])
{
    v[0] = k[0] * sin(p[2]) + k[2] * cos(p[1]);
    v[1] = k[1] * sin(p[0]) + k[0] * cos(p[2]);
    v[2] = k[2] * sin(p[1]) + k[1] * cos(p[0]);
}

/* Curl of a field by central differences of step h, in double. */
static void curl_fd(void (*f)(const double p[3], const void *ctx, double v[3]), const void *ctx, const double p[3],
                    double h, double w[3])
{
    double j[3][3]; /* j[c][a] = dv_c / dx_a */
    for (int a = 0; a < 3; a++) {
        double q[3] = {p[0], p[1], p[2]}, vp[3], vm[3];
        q[a] = p[a] + h;
        f(q, ctx, vp);
        q[a] = p[a] - h;
        f(q, ctx, vm);
        for (int c = 0; c < 3; c++)
            j[c][a] = (vp[c] - vm[c]) / (2.0 * h);
    }
    w[0] = j[2][1] - j[1][2];
    w[1] = j[0][2] - j[2][0];
    w[2] = j[1][0] - j[0][1];
}

static void abc_ctx_field(const double p[3], const void *ctx, double v[3])
{
    abc_ref_k(p, ctx, v);
}

static void tornado_ctx_field(const double p[3], const void *ctx, double v[3])
{
    tornado_ref_full(p, *(const double *)ctx, v, NULL);
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double dist3(const double a[3], const double b[3])
{
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(dot3(d, d));
}

/* Attribute 0 stays "speed"; helicity and vorticity_magnitude follow it. */
static void check_flow_attribute_order(const char *name, const sl_lines *l)
{
    SL_CHECK_MSG(l->attribute_count == 3, "%s: %d attributes, want 3", name, l->attribute_count);
    if (l->attribute_count < 3)
        return;
    SL_CHECK_MSG(strcmp(l->attributes[0].name, "speed") == 0, "%s: attribute 0 is '%s'", name, l->attributes[0].name);
    SL_CHECK_MSG(strcmp(l->attributes[1].name, SL_ATTR_HELICITY) == 0, "%s: attribute 1 is '%s'", name,
                 l->attributes[1].name);
    SL_CHECK_MSG(strcmp(l->attributes[2].name, SL_ATTR_VORTICITY) == 0, "%s: attribute 2 is '%s'", name,
                 l->attributes[2].name);
    SL_CHECK(sl_lines_find_attribute(l, SL_ATTR_HELICITY) == 1 && sl_lines_find_attribute(l, "vorticity_magnitude") == 2);
}

/* ABC: curl v = v (checked here by central differences of the reference, not
 * assumed), so helicity = |v|^2 and vorticity = |v| at every vertex.
 * Tolerances: the generator evaluates at the float position before
 * recentring, the test at origin + stored float (<= ~1e-6 apart in [0, 4 pi]);
 * |grad |v|^2| <= 2 |v| |grad v| <= 2 * 4.2 * 4.2 * sqrt(3) ~ 61, hence an
 * absolute 1e-4 on top of 1e-5 relative (float storage is 6e-8 relative). */
static void check_abc_flow(const char *json, const double k[3])
{
    sl_dataset *ds = gen(json);
    if (!ds)
        return;
    const sl_lines *l = &ds->lines;
    check_flow_attribute_order("abc", l);
    if (l->attribute_count < 3) {
        sl_dataset_destroy(ds);
        return;
    }
    const float *hel = l->attributes[1].values, *vor = l->attributes[2].values;
    double worst_curl = 0.0, worst_h = 0.0, worst_w = 0.0;
    size_t bad_h = 0, bad_w = 0;
    for (size_t i = 0; i < l->vertex_count; i++) {
        double p[3], v[3], w[3];
        world(ds, i, p);
        abc_ref_k(p, k, v);
        curl_fd(abc_ctx_field, k, p, 1e-5, w);
        worst_curl = fmax(worst_curl, dist3(w, v));
        double h = dot3(w, v), wm = sqrt(dot3(w, w));
        double eh = fabs(hel[i] - h), ew = fabs(vor[i] - wm);
        bad_h += eh > 1e-5 * fabs(h) + 1e-4;
        bad_w += ew > 1e-5 * wm + 1e-5;
        worst_h = fmax(worst_h, eh / (fabs(h) + 1e-3));
        worst_w = fmax(worst_w, ew / (wm + 1e-3));
    }
    printf("abc %s: |curl_fd v - v| <= %.2g; helicity rel err <= %.2g, vorticity rel err <= %.2g over %zu vertices\n",
           json, worst_curl, worst_h, worst_w, l->vertex_count);
    /* Central differences of sin/cos with h = 1e-5: truncation h^2/6 * 4.2 ~ 7e-11, rounding ~1e-16 * 4 / 1e-5. */
    SL_CHECK_MSG(worst_curl <= 1e-8, "abc: curl by central differences differs from v by %.3g", worst_curl);
    SL_CHECK_MSG(bad_h == 0, "abc: %zu of %zu vertices with helicity != |v|^2 (worst rel %.3g)", bad_h, l->vertex_count,
                 worst_h);
    SL_CHECK_MSG(bad_w == 0, "abc: %zu of %zu vertices with vorticity != |v| (worst rel %.3g)", bad_w, l->vertex_count,
                 worst_w);
    sl_dataset_destroy(ds);
}

/* The smallest |branch quantity| of the tornado at p. */
static double tornado_margin(const double p[3], double phase)
{
    double v[3], b[4];
    tornado_ref_full(p, phase, v, b);
    return fmin(fmin(fabs(b[0]), fabs(b[1])), fmin(fabs(b[2]), fabs(b[3])));
}

/* The generator's dual-number curl against central differences (h = 1e-6) of
 * the independent transcription, at random points of the box at least 1e-4
 * from every branch switch (every branch quantity has a gradient < 10, so the
 * stencil never crosses one). FD error: rounding ~2e-16 |v| / h ~ 1e-9 plus
 * truncation h^2 |v'''| / 6, |v'''| ~ 6 (r + r2) / d3^4 <= 2e8 at d3 >= z0 ~ 0.01:
 * ~3e-5 absolute where |curl| ~ 0.3 / d3^2 ~ 3e3, so 1e-5 relative to
 * max(|curl|, 1) holds with margin. */
static void test_tornado_curl(void)
{
    sl_rng rng;
    sl_rng_seed(&rng, 13, 0);
    const double phases[2] = {0.0, 40.0};
    const int counts[2] = {1000, 300};
    for (int ph = 0; ph < 2; ph++) {
        double phase = phases[ph], worst = 0.0, worst_v = 0.0;
        int n = 0, tried = 0, bad = 0, inner = 0, outer = 0, clamped = 0;
        while (n < counts[ph] && tried < 100 * counts[ph]) {
            tried++;
            double p[3] = {sl_rng_range(&rng, -0.25, 1.25), sl_rng_range(&rng, -0.25, 1.25), sl_rng_range(&rng, 0.0, 1.0)};
            /* Half of the points within the vortex core's reach, where the field varies fastest. */
            if (n % 2) {
                double cx = 0.5 + 0.1 * sin(0.04 * phase + 10.0 * p[2]), cy = 0.5 + 0.1 * cos(0.03 * phase + 3.0 * p[2]);
                double ang = sl_rng_range(&rng, 0.0, 2.0 * PI), rad = sl_rng_range(&rng, 0.0, 0.6);
                p[0] = cx + rad * cos(ang);
                p[1] = cy + rad * sin(ang);
            }
            if (tornado_margin(p, phase) < 1e-4)
                continue;
            double v[3], w[3], vr[3], b[4], wf[3];
            sl_gen_tornado_eval(p, phase, v, w);
            tornado_ref_full(p, phase, vr, b);
            curl_fd(tornado_ctx_field, &phase, p, 1e-6, wf);
            double e = dist3(w, wf) / fmax(sqrt(dot3(wf, wf)), 1.0);
            double ev = dist3(v, vr) / fmax(sqrt(dot3(vr, vr)), 1.0);
            worst = fmax(worst, e);
            worst_v = fmax(worst_v, ev);
            bad += e > 1e-5 || ev > 1e-12;
            inner += b[0] <= 0.0;
            outer += b[0] > 0.0;
            clamped += b[2] < 0.0;
            n++;
        }
        printf("tornado phase %g: dual curl vs central differences, worst rel %.2g (value %.2g) at %d points "
               "(%d inner, %d outer branch, %d with z0 clamped)\n",
               phase, worst, worst_v, n, inner, outer, clamped);
        SL_CHECK_MSG(n == counts[ph], "tornado: only %d points away from branch switches", n);
        SL_CHECK_MSG(bad == 0, "tornado phase %g: %d of %d points with the dual curl off by > 1e-5 (worst %.3g) or "
                     "the value off by > 1e-12 (worst %.3g)", phase, bad, n, worst, worst_v);
        SL_CHECK_MSG(inner >= 100 && outer >= 100 && clamped >= 50, "tornado: branches not all sampled (%d %d %d)",
                     inner, outer, clamped);
    }
    /* On the axis (dist = 0) the curl stays finite (sqrt's gradient at 0 is taken as 0). */
    double v[3], w[3];
    double axis[3] = {0.5 + 0.1 * sin(10.0 * 0.5), 0.5 + 0.1 * cos(3.0 * 0.5), 0.5};
    sl_gen_tornado_eval(axis, 0.0, v, w);
    SL_CHECK_MSG(isfinite(w[0]) && isfinite(w[1]) && isfinite(w[2]), "tornado: curl on the axis %g %g %g", w[0], w[1],
                 w[2]);
}

/* Tornado attributes at the vertices against v . curl and |curl| of the
 * reference by central differences at origin + stored position (the
 * generator evaluates at the float position before recentring: <= ~1e-7
 * apart, times |grad curl| ~ 1 / d3^3: a 1e-4 relative tolerance). */
static void test_tornado_flow(void)
{
    sl_dataset *ds = gen("{\"generator\":\"tornado\",\"lines\":60,\"points\":100,\"seed\":15}");
    if (!ds)
        return;
    const sl_lines *l = &ds->lines;
    check_flow_attribute_order("tornado", l);
    if (l->attribute_count >= 3) {
        const float *hel = l->attributes[1].values, *vor = l->attributes[2].values;
        double phase = 0.0, worst_h = 0.0, worst_w = 0.0;
        size_t checked = 0, bad = 0;
        int negative = 0, positive = 0;
        for (size_t i = 0; i < l->vertex_count; i++) {
            double p[3], v[3], w[3];
            world(ds, i, p);
            if (tornado_margin(p, phase) < 1e-3)
                continue;
            tornado_ref_full(p, phase, v, NULL);
            curl_fd(tornado_ctx_field, &phase, p, 1e-6, w);
            double h = dot3(v, w), wm = sqrt(dot3(w, w));
            double eh = fabs(hel[i] - h) / fmax(sqrt(dot3(v, v)) * wm, 1e-3);
            double ew = fabs(vor[i] - wm) / fmax(wm, 1e-3);
            bad += eh > 1e-4 || ew > 1e-4;
            worst_h = fmax(worst_h, eh);
            worst_w = fmax(worst_w, ew);
            negative += h < 0.0;
            positive += h > 0.0;
            checked++;
        }
        printf("tornado: helicity err <= %.2g |v||curl|, vorticity rel err <= %.2g at %zu vertices (%d h > 0, %d h < 0)\n",
               worst_h, worst_w, checked, positive, negative);
        SL_CHECK_MSG(checked > 3000, "tornado: only %zu vertices checked", checked);
        SL_CHECK_MSG(bad == 0, "tornado: %zu of %zu vertices with helicity / vorticity off (worst %.3g, %.3g)", bad,
                     checked, worst_h, worst_w);
        SL_CHECK_MSG(positive > 0 && negative > 0, "tornado: helicity of one sign only (%d > 0, %d < 0)", positive,
                     negative);
        SL_CHECK(all_finite(ds));
    }
    sl_dataset_destroy(ds);
}

static void test_flow_attributes(void)
{
    const double classic[3] = {sqrt(3.0), sqrt(2.0), 1.0}, other[3] = {0.5, 2.0, 1.5}, zero[3] = {0.0, 0.0, 0.0};
    check_abc_flow("{\"generator\":\"abc\",\"lines\":30,\"points\":200,\"seed\":4}", classic);
    check_abc_flow("{\"generator\":\"abc\",\"lines\":10,\"points\":100,\"seed\":2,\"a\":0.5,\"b\":2,\"c\":1.5}", other);
    check_abc_flow("{\"generator\":\"abc\",\"lines\":2,\"points\":5,\"a\":0,\"b\":0,\"c\":0}", zero);
    test_tornado_curl();
    test_tornado_flow();
}

/* v = (-y, x, 0): unit-speed circles; in arc length the exact point after
 * n steps of h on the unit circle is at angle n h. */
static void rotation(const double p[3], const void *ctx, double v[3])
{
    (void)ctx;
    v[0] = -p[1];
    v[1] = p[0];
    v[2] = 0.25;
}

static void test_tracer(void)
{
    enum { N = 101 };
    float pos[3 * N], tan[3 * N];
    const double start[3] = {1.0, 0.0, 0.0}, h = 0.05;
    SL_CHECK(sl_trace_rk4(rotation, NULL, start, h, N, NULL, NULL, pos, tan) == 1);
    /* Helix of radius 1, pitch speed 0.25: unit-speed parameter s, angle s / |v|. */
    double speed = sqrt(1.0 + 0.0625), worst = 0.0;
    for (int i = 0; i < N; i++) {
        double ang = i * h / speed;
        worst = fmax(worst, fabs(pos[3 * i] - cos(ang)));
        worst = fmax(worst, fabs(pos[3 * i + 1] - sin(ang)));
        worst = fmax(worst, fabs(pos[3 * i + 2] - 0.25 * i * h / speed));
    }
    SL_CHECK_NEAR(worst, 0.0, 1e-6); /* RK4 global error ~ h^4 * length ~ 3e-5 * ... measured far below */
    SL_CHECK_NEAR(tan[3 * 50 + 2], 0.25, 1e-7);
    /* A box stops the trace. */
    const double lo[3] = {-2, -2, -2}, hi[3] = {2, 2, 0.5};
    SL_CHECK(sl_trace_rk4(rotation, NULL, start, h, N, lo, hi, pos, tan) == 0);
    /* Centred: the start point is the middle vertex and the line runs with the flow. */
    SL_CHECK(sl_trace_rk4_centred(rotation, NULL, start, h, 11, NULL, NULL, pos, tan) == 1);
    SL_CHECK_NEAR(pos[3 * 5], 1.0, 1e-7);
    SL_CHECK_NEAR(pos[3 * 5 + 1], 0.0, 1e-7);
    SL_CHECK(pos[3 * 6 + 2] > pos[3 * 5 + 2] && pos[3 * 4 + 2] < pos[3 * 5 + 2]);
    SL_CHECK_NEAR(pos[3 * 0 + 1], -sin(5 * h / speed), 1e-6);
}

static void test_hotroom(void)
{
    sl_dataset *ds = gen("{\"generator\":\"hotroom\",\"lines\":3000,\"seed\":9}");
    if (!ds)
        return;
    const sl_lines *l = &ds->lines;
    SL_CHECK(l->radii != NULL);
    size_t bad = 0, segs = 0;
    for (size_t k = 0; l->radii && k < l->line_count; k++)
        for (uint32_t v = l->line_offsets[k]; v + 1 < l->line_offsets[k + 1]; v++, segs++) {
            double a[3], b[3];
            world(ds, v, a);
            world(ds, v + 1, b);
            double len = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
            if (!(l->radii[v] > len && l->radii[v + 1] > len))
                bad++;
        }
    SL_CHECK(segs > 3000);
    SL_CHECK_MSG(bad == 0, "%zu of %zu segments longer than a radius", bad, segs);
    SL_CHECK(sl_lines_find_attribute(l, "temperature") >= 0);
    /* Bounds include the radii: the room is 4 x 4 x 3 m. */
    SL_CHECK(ds->bounds_max.x - ds->bounds_min.x < 4.5 && ds->bounds_max.z - ds->bounds_min.z < 3.5);
    sl_dataset_destroy(ds);
}

static double ml_ref(double x, double y, double z)
{
    double fm = 6.0, alpha = 0.25, r = sqrt(x * x + y * y);
    double rr = cos(2.0 * PI * fm * cos(PI * r / 2.0));
    return (1.0 - sin(PI * z / 2.0) + alpha * (1.0 + rr)) / (2.0 * (1.0 + alpha));
}

static void test_volumes(void)
{
    sl_dataset *ds = gen("{\"generator\":\"marschner_lobb\",\"size\":41}");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK(ds->kind == SL_DATASET_VOLUME && v->type == SL_VOXEL_F32 && v->components == 1);
        SL_CHECK(v->dims[0] == 41 && v->dims[1] == 41 && v->dims[2] == 41);
        SL_CHECK_NEAR(ds->bounds_min.x, -1.0, 1e-12);
        SL_CHECK_NEAR(ds->bounds_max.z, 1.0, 1e-12);
        /* Centre voxel (20,20,20) is the point 0: (1 + alpha (1 + cos(2 pi fM))) / (2 (1 + alpha)) = 0.6. */
        SL_CHECK_NEAR(sl_volume_value(v, 20, 20, 20, 0), ml_ref(0, 0, 0), 1e-7);
        SL_CHECK_NEAR(ml_ref(0, 0, 0), 0.6, 1e-12);
        double worst = 0.0;
        for (int k = 0; k < 41; k += 3)
            for (int j = 0; j < 41; j += 5)
                for (int i = 0; i < 41; i += 7)
                    worst = fmax(worst, fabs(sl_volume_value(v, i, j, k, 0) -
                                             ml_ref(-1.0 + i * 0.05, -1.0 + j * 0.05, -1.0 + k * 0.05)));
        SL_CHECK_NEAR(worst, 0.0, 1e-6); /* float storage of values in [0,1] */
        SL_CHECK(v->value_min >= 0.0 && v->value_max <= 1.0 && v->value_max > 0.99);
    }
    sl_dataset_destroy(ds);

    ds = gen("{\"generator\":\"torus\",\"size\":33}");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK(v->dims[0] == 33 && v->type == SL_VOXEL_F32);
        double worst = 0.0, step = 2.0 / 32.0;
        for (int k = 0; k < 33; k += 4)
            for (int j = 0; j < 33; j += 3)
                for (int i = 0; i < 33; i += 5) {
                    double x = -1 + i * step, y = -1 + j * step, z = -1 + k * step;
                    double dt = hypot(hypot(x, y) - 0.55, z) - 0.2;
                    double dsph = sqrt((x - 0.55) * (x - 0.55) + y * y + z * z) - 0.3;
                    worst = fmax(worst, fabs(sl_volume_value(v, i, j, k, 0) - fmin(dt, dsph)));
                }
        SL_CHECK_NEAR(worst, 0.0, 1e-6);
        SL_CHECK(v->value_min < -0.25 && v->value_max > 1.0); /* inside the sphere; far corner */
    }
    sl_dataset_destroy(ds);

    ds = gen("{\"generator\":\"head\",\"size\":64}");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK(v->type == SL_VOXEL_U16 && v->dims[2] == 64);
        SL_CHECK_NEAR(v->value_min, 24.0, 0.0);   /* air, -1000 HU + 1024 */
        SL_CHECK(v->value_max > 1900.0 && v->value_max <= 2024.0); /* bone */
        SL_CHECK_NEAR(sl_volume_value(v, 0, 0, 0, 0), 24.0, 0.0);
        /* Brain tissue (35 HU) 3 cm above the centre, clear of the ventricles. */
        double brain = sl_volume_value(v, 32, 32, 32 + 12, 0);
        SL_CHECK_NEAR(brain, 1024.0 + 35.0, 1.0);
        SL_CHECK_NEAR(ds->bounds_max.x - ds->bounds_min.x, 220.0, 1e-9);
    }
    sl_dataset_destroy(ds);
    ds = gen("{\"generator\":\"head\",\"size\":24,\"voxel_type\":\"u8\"}");
    if (ds)
        SL_CHECK(ds->volume.type == SL_VOXEL_U8 && ds->volume.value_max <= 255.0 && ds->volume.value_max > 100.0);
    sl_dataset_destroy(ds);
}

/* The ellipsoid's f by its formula, independent of gen_ellipsoid.c's loops. */
static double ellipsoid_f(double x, double y, double z, double a, double b, double c)
{
    return 1.0 - sqrt((x / a) * (x / a) + (y / b) * (y / b) + (z / c) * (z / c));
}

/* World position of voxel (i, j, k) from the dataset's own origin and spacing. */
static void voxel_world(const sl_dataset *ds, int i, int j, int k, double p[3])
{
    p[0] = ds->origin.x + i * ds->volume.spacing[0];
    p[1] = ds->origin.y + j * ds->volume.spacing[1];
    p[2] = ds->origin.z + k * ds->volume.spacing[2];
}

/* Largest |stored - expected| over the whole grid, expected = map(f(x)). */
static double ellipsoid_worst(const sl_dataset *ds, double a, double b, double c, double levels)
{
    const sl_volume *v = &ds->volume;
    double worst = 0.0;
    for (int k = 0; k < v->dims[2]; k++)
        for (int j = 0; j < v->dims[1]; j++)
            for (int i = 0; i < v->dims[0]; i++) {
                double p[3];
                voxel_world(ds, i, j, k, p);
                double f = ellipsoid_f(p[0], p[1], p[2], a, b, c);
                double want = f;
                if (levels > 0.0)
                    want = (fmin(fmax(f, -1.5), 1.0) + 1.5) / 2.5 * levels;
                worst = fmax(worst, fabs(sl_volume_value(v, i, j, k, 0) - want));
            }
    return worst;
}

static void test_ellipsoid(void)
{
    /* Defaults: 64^3 f32 sphere of radius 0.6 on [-1, 1]^3. */
    sl_dataset *ds = gen("{\"generator\":\"ellipsoid\"}");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK(v->type == SL_VOXEL_F32 && v->dims[0] == 64 && v->dims[1] == 64 && v->dims[2] == 64);
        SL_CHECK_NEAR(v->spacing[2], 2.0 / 63.0, 1e-15);
        SL_CHECK_NEAR(ds->bounds_min.z, -1.0, 1e-12);
        SL_CHECK_NEAR(ds->bounds_max.z, 1.0, 1e-12);
        SL_CHECK_NEAR(ellipsoid_worst(ds, 0.6, 0.6, 0.6, 0.0), 0.0, 1e-6);
    }
    sl_dataset_destroy(ds);

    /* Distinct axes, odd size so voxel 32 is the centre; the axes must not be swapped. */
    ds = gen("{\"generator\":\"ellipsoid\",\"size\":65,\"a\":0.5,\"b\":0.4,\"c\":0.25}");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK_NEAR(sl_volume_value(v, 32, 32, 32, 0), 1.0, 0.0);
        /* 16 voxels = 0.5 along each axis: f = 1 - 0.5 / axis. */
        SL_CHECK_NEAR(sl_volume_value(v, 48, 32, 32, 0), 0.0, 1e-6);
        SL_CHECK_NEAR(sl_volume_value(v, 32, 48, 32, 0), 1.0 - 0.5 / 0.4, 1e-6);
        SL_CHECK_NEAR(sl_volume_value(v, 32, 32, 48, 0), 1.0 - 0.5 / 0.25, 1e-6);
        SL_CHECK_NEAR(sl_volume_value(v, 16, 32, 32, 0), 0.0, 1e-6);
        SL_CHECK_NEAR(sl_volume_value(v, 40, 32, 32, 0), 0.5, 1e-6);  /* x = 0.25: iso 0.5 at semi-axis (1 - 0.5) a */
        SL_CHECK_NEAR(ellipsoid_worst(ds, 0.5, 0.4, 0.25, 0.0), 0.0, 1e-6);
        SL_CHECK_NEAR(v->value_max, 1.0, 0.0);
    }
    sl_dataset_destroy(ds);

    /* u16 / u8: the integers round((clamp(f, -1.5, 1) + 1.5) / 2.5 M); the clamp is reached at the corners. */
    static const struct { const char *call; sl_voxel_type type; double levels; } quant[] = {
        {"{\"generator\":\"ellipsoid\",\"size\":33,\"a\":0.375,\"b\":0.5,\"c\":0.7,\"voxel_type\":\"u16\"}", SL_VOXEL_U16, 65535.0},
        {"{\"generator\":\"ellipsoid\",\"size\":33,\"a\":0.375,\"b\":0.5,\"c\":0.7,\"voxel_type\":\"u8\"}", SL_VOXEL_U8, 255.0},
    };
    for (int q = 0; q < 2; q++) {
        ds = gen(quant[q].call);
        if (!ds)
            continue;
        const sl_volume *v = &ds->volume;
        SL_CHECK(v->type == quant[q].type);
        SL_CHECK_MSG(ellipsoid_worst(ds, 0.375, 0.5, 0.7, quant[q].levels) <= 0.5 + 1e-9, "%s", quant[q].call);
        SL_CHECK_NEAR(sl_volume_value(v, 16, 16, 16, 0), quant[q].levels, 0.0);  /* f = 1 */
        SL_CHECK_NEAR(v->value_min, 0.0, 0.0);                                   /* f <= -1.5 */
        SL_CHECK_NEAR(v->value_max, quant[q].levels, 0.0);
        /* x = 0.375 = a: f = 0 -> 1.5 / 2.5 M (39321 u16, 153 u8), and the documented iso 0.5 -> 0.8 M. */
        SL_CHECK_NEAR(sl_volume_value(v, 16 + 6, 16, 16, 0), round(0.6 * quant[q].levels), 0.0);
        SL_CHECK_NEAR((0.5 + 1.5) / 2.5 * quant[q].levels, q == 0 ? 52428.0 : 204.0, 1e-9);
        sl_dataset_destroy(ds);
    }

    /* Anisotropy: z spacing and slice count, centred slices, f in world units. */
    static const struct { double an; int size, dims_z; } aniso[] = {
        {2.0, 65, 33}, {3.0, 65, 22}, {0.5, 33, 65}, {0.25, 9, 33}, {4.0, 8, 3},
    };
    for (size_t t = 0; t < sizeof aniso / sizeof aniso[0]; t++) {
        char call[160];
        snprintf(call, sizeof call, "{\"generator\":\"ellipsoid\",\"size\":%d,\"anisotropy\":%g,\"c\":0.4}", aniso[t].size,
                 aniso[t].an);
        ds = gen(call);
        if (!ds)
            continue;
        const sl_volume *v = &ds->volume;
        double h = 2.0 / (aniso[t].size - 1);
        SL_CHECK_MSG(v->dims[0] == aniso[t].size && v->dims[1] == aniso[t].size && v->dims[2] == aniso[t].dims_z,
                     "%s: dims %d %d %d", call, v->dims[0], v->dims[1], v->dims[2]);
        SL_CHECK_MSG(fabs(v->spacing[0] - h) < 1e-15 && fabs(v->spacing[2] - aniso[t].an * h) < 1e-15, "%s: spacing", call);
        SL_CHECK_NEAR(ds->origin.z, -0.5 * (aniso[t].dims_z - 1) * aniso[t].an * h, 1e-12);
        SL_CHECK_NEAR(ds->bounds_min.z + ds->bounds_max.z, 0.0, 1e-12);
        SL_CHECK_NEAR(ellipsoid_worst(ds, 0.6, 0.6, 0.4, 0.0), 0.0, 1e-6);
        sl_dataset_destroy(ds);
    }

    /* slices: exactly that many; 1 is one slice at z = 0 holding the equator. */
    ds = gen("{\"generator\":\"ellipsoid\",\"size\":33,\"slices\":1}");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK(v->dims[0] == 33 && v->dims[2] == 1);
        SL_CHECK_NEAR(ds->origin.z, 0.0, 0.0);
        SL_CHECK_NEAR(sl_volume_value(v, 16, 16, 0, 0), 1.0, 0.0);
        SL_CHECK_NEAR(ellipsoid_worst(ds, 0.6, 0.6, 0.6, 0.0), 0.0, 1e-6);
    }
    sl_dataset_destroy(ds);
    ds = gen("{\"generator\":\"ellipsoid\",\"size\":33,\"slices\":5,\"anisotropy\":2}");
    if (ds) {
        SL_CHECK(ds->volume.dims[2] == 5);
        SL_CHECK_NEAR(ds->origin.z, -2.0 * 2.0 * (2.0 / 32.0), 1e-15);
        SL_CHECK_NEAR(sl_volume_value(&ds->volume, 16, 16, 2, 0), 1.0, 0.0);
    }
    sl_dataset_destroy(ds);

    /* plateau: the linear field where above 0.5, exactly 0.5 elsewhere. */
    ds = gen("{\"generator\":\"ellipsoid\",\"size\":33,\"profile\":\"plateau\"}");
    if (ds) {
        const sl_volume *v = &ds->volume;
        SL_CHECK_NEAR(v->value_min, 0.5, 0.0);
        SL_CHECK_NEAR(sl_volume_value(v, 0, 0, 0, 0), 0.5, 0.0);
        SL_CHECK_NEAR(sl_volume_value(v, 16, 16, 16, 0), 1.0, 0.0);
        SL_CHECK_NEAR(sl_volume_value(v, 16 + 2, 16, 16, 0), 1.0 - 0.125 / 0.6, 1e-6);
        SL_CHECK_NEAR(sl_volume_value(v, 16 + 6, 16, 16, 0), 0.5, 0.0);  /* q = 0.625 */
        size_t flat = 0, n = 33 * 33 * 33;
        for (size_t i = 0; i < n; i++)
            flat += ((const float *)v->data)[i] == 0.5f;
        SL_CHECK(flat > n / 2);
    }
    sl_dataset_destroy(ds);

    /* sheet: 1 on one slice inside the ellipse (x/a)^2 + (y/b)^2 <= 1, 0 elsewhere; odd and even slice counts. */
    static const struct { const char *call; int dims_z, slice; double a, b; } sheets[] = {
        {"{\"generator\":\"ellipsoid\",\"size\":33,\"profile\":\"sheet\",\"a\":0.7,\"b\":0.4}", 33, 16, 0.7, 0.4},
        {"{\"generator\":\"ellipsoid\",\"size\":32,\"profile\":\"sheet\",\"a\":0.7,\"b\":0.4}", 32, 15, 0.7, 0.4},
        {"{\"generator\":\"ellipsoid\",\"size\":33,\"profile\":\"sheet\",\"slices\":1}", 1, 0, 0.6, 0.6},
    };
    for (size_t t = 0; t < sizeof sheets / sizeof sheets[0]; t++) {
        ds = gen(sheets[t].call);
        if (!ds)
            continue;
        const sl_volume *v = &ds->volume;
        SL_CHECK(v->dims[2] == sheets[t].dims_z);
        size_t wrong = 0, ones = 0;
        for (int k = 0; k < v->dims[2]; k++)
            for (int j = 0; j < v->dims[1]; j++)
                for (int i = 0; i < v->dims[0]; i++) {
                    double p[3];
                    voxel_world(ds, i, j, k, p);
                    double e = (p[0] / sheets[t].a) * (p[0] / sheets[t].a) + (p[1] / sheets[t].b) * (p[1] / sheets[t].b);
                    double want = k == sheets[t].slice && e <= 1.0 ? 1.0 : 0.0;
                    double got = sl_volume_value(v, i, j, k, 0);
                    wrong += got != want && fabs(e - 1.0) > 1e-9;
                    ones += got == 1.0;
                }
        SL_CHECK_MSG(wrong == 0, "%s: %zu voxels differ", sheets[t].call, wrong);
        /* The disk's area pi a b in voxels of (2 / (size - 1))^2, to 5 %. */
        double h = v->spacing[0], area = PI * sheets[t].a * sheets[t].b / (h * h);
        SL_CHECK_MSG(fabs((double)ones - area) < 0.05 * area, "%s: %zu ones, disk %.0f", sheets[t].call, ones, area);
        sl_dataset_destroy(ds);
    }
}

/* An error: status INVALID or LIMIT, *out NULL, message containing every needle. */
static void expect_error(const char *json, sl_status want, const char *n1, const char *n2)
{
    sl_dataset *ds = (sl_dataset *)&ds; /* poisoned: must come back NULL */
    sl_err err = {0};
    sl_status st = sl_generate_json(json, &ds, &err);
    SL_CHECK_MSG(st == want, "%s: status %d, want %d (%s)", json ? json : "(null)", st, want, err.message);
    SL_CHECK_MSG(ds == NULL, "%s: out not NULL on error", json ? json : "(null)");
    SL_CHECK_MSG(!n1 || strstr(err.message, n1), "%s: message '%s' lacks '%s'", json ? json : "(null)", err.message, n1);
    SL_CHECK_MSG(!n2 || strstr(err.message, n2), "%s: message '%s' lacks '%s'", json ? json : "(null)", err.message, n2);
    if (st == SL_OK)
        sl_dataset_destroy(ds);
}

static void test_errors(void)
{
    const sl_status I = SL_ERR_INVALID;
    expect_error("{\"generator\":\"tornado\",\"lnes\":10}", I, "'lnes'", "lines, points, seed, time");
    expect_error("{\"generator\":\"tornado\",\"lines\":\"10\"}", I, "'lines'", "a string");
    expect_error("{\"generator\":\"tornado\",\"lines\":0}", I, "'lines'", "1..1000000");
    expect_error("{\"generator\":\"tornado\",\"lines\":1000001}", I, "'lines'", "out of range");
    expect_error("{\"generator\":\"tornado\",\"points\":1}", I, "'points'", "2..10000");
    expect_error("{\"generator\":\"tornado\",\"lines\":1.5}", I, "'lines'", "an integer");
    expect_error("{\"generator\":\"tornado\",\"seed\":-1}", I, "'seed'", NULL);
    expect_error("{\"generator\":\"tornado\",\"seed\":true}", I, "'seed'", "a boolean");
    expect_error("{\"generator\":\"tornado\",\"lines\":5,\"lines\":6}", I, "'lines'", "twice");
    expect_error("{\"generator\":\"furball\",\"segments\":10000001}", I, "'segments'", "1..10000000");
    expect_error("{\"generator\":\"abc\",\"a\":null}", I, "'a'", "null");
    expect_error("{\"generator\":\"abc\",\"a\":11}", I, "'a'", "0..10");
    expect_error("{\"generator\":\"marschner_lobb\",\"size\":7}", I, "'size'", "8..512");
    expect_error("{\"generator\":\"head\",\"voxel_type\":\"f64\"}", I, "'voxel_type'", "\"u8\"");
    expect_error("{\"generator\":\"head\",\"voxel_type\":8}", I, "'voxel_type'", "a number");
    expect_error("{\"generator\":\"ellipsoid\",\"profile\":\"cube\"}", I, "'profile'", "\"sheet\"");
    expect_error("{\"generator\":\"ellipsoid\",\"a\":0.01}", I, "'a'", "0.05..0.95");
    expect_error("{\"generator\":\"ellipsoid\",\"anisotropy\":5}", I, "'anisotropy'", "0.25..4");
    expect_error("{\"generator\":\"ellipsoid\",\"seed\":1}", I, "'seed'", "profile");
    expect_error("{\"generator\":\"ellipsoid\",\"slices\":2049}", I, "'slices'", "0..2048");
    expect_error("{\"generator\":\"volcano\"}", I, "volcano", "tornado");
    expect_error("{\"generator\":7}", I, "'generator'", NULL);
    expect_error("{\"lines\":7}", I, "'generator'", NULL);
    expect_error("[1,2]", I, "JSON object", NULL);
    expect_error("{\"generator\":\"tornado\"", I, "not valid JSON", NULL);
    expect_error("{\"generator\":\"tornado\"} trailing", I, "not valid JSON", NULL);
    expect_error("", I, "not valid JSON", NULL);
    expect_error(NULL, I, NULL, NULL);
    /* Each key valid on its own, the product over the vertex limit. */
    expect_error("{\"generator\":\"tornado\",\"lines\":1000000,\"points\":10000}", SL_ERR_LIMIT, "lines * points", NULL);
    expect_error("{\"generator\":\"bundle\",\"lines\":1000000,\"points\":100}", SL_ERR_LIMIT, "lines * points", NULL);
    /* A NULL err is allowed. */
    sl_dataset *ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"x\"}", &ds, NULL) == SL_ERR_INVALID && !ds);
}

static void test_catalog(void)
{
    int n = 0;
    const sl_generator_info *g = sl_generator_list(&n);
    SL_CHECK(n == 11);
    static const sl_gen_family *fams[] = {&sl_gen_tornado, &sl_gen_abc,           &sl_gen_bundle,
                                          &sl_gen_furball, &sl_gen_hotroom,       &sl_gen_random_walk,
                                          &sl_gen_marschner_lobb, &sl_gen_torus, &sl_gen_head, &sl_gen_ellipsoid,
                                          &sl_gen_lr_field};
    for (int i = 0; i < 11; i++) {
        int listed = 0;
        for (int j = 0; j < n; j++)
            listed |= strcmp(g[j].name, fams[i]->name) == 0 && g[j].kind == fams[i]->kind;
        SL_CHECK_MSG(listed, "%s not listed", fams[i]->name);
        int has_seed = 0;
        for (int k = 0; k < fams[i]->key_count; k++) {
            SL_CHECK_MSG(strstr(fams[i]->keys_help, fams[i]->keys[k].name) != NULL, "%s: keys_help lacks '%s'",
                         fams[i]->name, fams[i]->keys[k].name);
            has_seed |= strcmp(fams[i]->keys[k].name, "seed") == 0;
            if (fams[i]->keys[k].type != SL_GEN_CHOICE && strcmp(fams[i]->keys[k].name, "seed") != 0) {
                char range[64];
                snprintf(range, sizeof range, "%.16g..%.16g", fams[i]->keys[k].min, fams[i]->keys[k].max);
                SL_CHECK_MSG(strstr(fams[i]->keys_help, range) != NULL, "%s: keys_help lacks the range %s of '%s'",
                             fams[i]->name, range, fams[i]->keys[k].name);
            }
            if (fams[i]->keys[k].type != SL_GEN_CHOICE)
                SL_CHECK_MSG(fams[i]->keys[k].def >= fams[i]->keys[k].min && fams[i]->keys[k].def <= fams[i]->keys[k].max,
                             "%s: default of '%s' out of its range", fams[i]->name, fams[i]->keys[k].name);
        }
        /* The ellipsoid has no randomness and no seed (its 8 keys are the SL_GEN_MAX_KEYS limit). */
        SL_CHECK_MSG(has_seed != (fams[i] == &sl_gen_ellipsoid || fams[i] == &sl_gen_lr_field), "%s: seed key %s", fams[i]->name,
                     has_seed ? "present, not expected" : "missing");
    }
    const sl_builtin_dataset *b = sl_builtin_datasets(&n);
    SL_CHECK(n >= 8);
    for (int i = 0; i < n; i++) {
        SL_CHECK(sl_builtin_lookup(b[i].name) == b[i].generator_json);
        double t0 = sl_clock_ms();
        sl_dataset *ds = gen(b[i].generator_json);
        double ms = sl_clock_ms() - t0;
        printf("built-in %-16s %8.1f ms\n", b[i].name, ms);
        if (ds)
            SL_CHECK_MSG(all_finite(ds), "built-in %s", b[i].name);
        sl_dataset_destroy(ds);
    }
    SL_CHECK(sl_builtin_lookup("tornado") != NULL);
    SL_CHECK(sl_builtin_lookup("no-such-dataset") == NULL);
    SL_CHECK(sl_builtin_lookup(NULL) == NULL);
}

/* xoshiro256** known answers (state 1,2,3,4; the first two check by hand:
 * rotl(2 * 5, 7) * 9 = 11520, then s[1] becomes 0) and distribution sanity
 * at 5 sigma. */
static void test_random(void)
{
    sl_rng r = {{1, 2, 3, 4}};
    SL_CHECK(sl_rng_next(&r) == 11520u);
    SL_CHECK(sl_rng_next(&r) == 0u);
    SL_CHECK(sl_rng_next(&r) == 1509978240u);
    SL_CHECK(sl_rng_next(&r) == 1215971899390074240u);
    sl_rng a, b;
    sl_rng_seed(&a, 1, 0);
    sl_rng_seed(&b, 1, 1);
    SL_CHECK(sl_rng_next(&a) != sl_rng_next(&b)); /* streams differ */
    enum { N = 100000 };
    double sum = 0.0, nsum = 0.0, nsq = 0.0;
    int hist[7] = {0}, in_ball = 1, on_sphere = 1, in_unit = 1;
    for (int i = 0; i < N; i++) {
        double u = sl_rng_uniform(&a), g = sl_rng_normal(&a), p[3], d[3];
        in_unit &= u >= 0.0 && u < 1.0;
        sum += u;
        nsum += g;
        nsq += g * g;
        int64_t k = sl_rng_int(&a, -3, 3);
        if (k >= -3 && k <= 3)
            hist[k + 3]++;
        sl_rng_in_ball(&a, p);
        in_ball &= p[0] * p[0] + p[1] * p[1] + p[2] * p[2] <= 1.0;
        sl_rng_on_sphere(&a, d);
        on_sphere &= fabs(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1.0) < 1e-12;
    }
    SL_CHECK(in_unit && in_ball && on_sphere);
    SL_CHECK_NEAR(sum / N, 0.5, 5.0 * 0.2887 / sqrt(N));
    SL_CHECK_NEAR(nsum / N, 0.0, 5.0 / sqrt(N));
    SL_CHECK_NEAR(nsq / N, 1.0, 5.0 * sqrt(2.0) / sqrt(N));
    int all = 0;
    for (int k = 0; k < 7; k++) {
        all += hist[k];
        SL_CHECK_NEAR(hist[k], N / 7.0, 5.0 * sqrt(N / 7.0));
    }
    SL_CHECK(all == N); /* nothing outside [-3, 3] */
}

/* Runs bin/sightline-info with one argument; returns the exit status and stdout (caller frees). */
static int run_info(const char *arg, char **out)
{
    const char *bin = getenv("SIGHTLINE_BINARY_DIR");
    char cmd[1024];
    *out = NULL;
    if (arg)
        snprintf(cmd, sizeof cmd, "'%s/bin/sightline-info' '%s' 2>/dev/null", bin ? bin : "build", arg);
    else
        snprintf(cmd, sizeof cmd, "'%s/bin/sightline-info' 2>/dev/null", bin ? bin : "build");
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + len, 1, cap - 1 - len, p)) > 0)
        len += got;
    if (buf)
        buf[len] = '\0';
    int status = pclose(p);
    *out = buf;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static void test_info_tool(void)
{
    if (!getenv("SIGHTLINE_BINARY_DIR"))
        printf("SIGHTLINE_BINARY_DIR not set; trying ./build\n");
    char *out = NULL;
    int rc = run_info("{\"generator\":\"tornado\",\"lines\":25,\"points\":40,\"seed\":7}", &out);
    SL_CHECK_MSG(rc == 0, "sightline-info exit %d", rc);
    cJSON *root = out ? cJSON_Parse(out) : NULL;
    SL_CHECK_MSG(root != NULL, "sightline-info printed no JSON: %.200s", out ? out : "");
    if (root) {
        cJSON *kind = cJSON_GetObjectItem(root, "kind"), *counts = cJSON_GetObjectItem(root, "counts");
        SL_CHECK(cJSON_IsString(kind) && strcmp(kind->valuestring, "lines") == 0);
        SL_CHECK(cJSON_GetObjectItem(counts, "lines") && cJSON_GetObjectItem(counts, "lines")->valuedouble == 25);
        SL_CHECK(cJSON_GetObjectItem(counts, "vertices") && cJSON_GetObjectItem(counts, "vertices")->valuedouble == 1000);
        SL_CHECK(cJSON_GetObjectItem(counts, "segments") && cJSON_GetObjectItem(counts, "segments")->valuedouble == 975);
        cJSON *attrs = cJSON_GetObjectItem(root, "attributes");
        cJSON *a0 = cJSON_GetArrayItem(attrs, 0);
        SL_CHECK(a0 && strcmp(cJSON_GetObjectItem(a0, "name")->valuestring, "speed") == 0);
        SL_CHECK(a0 && cJSON_GetObjectItem(a0, "min")->valuedouble <= cJSON_GetObjectItem(a0, "max")->valuedouble &&
                 cJSON_GetObjectItem(a0, "max")->valuedouble > 0.0);
        /* The flow attributes follow speed; the tornado's helicity takes both signs. */
        cJSON *a1 = cJSON_GetArrayItem(attrs, 1), *a2 = cJSON_GetArrayItem(attrs, 2);
        SL_CHECK(cJSON_GetArraySize(attrs) == 3);
        SL_CHECK(a1 && strcmp(cJSON_GetObjectItem(a1, "name")->valuestring, SL_ATTR_HELICITY) == 0 &&
                 cJSON_GetObjectItem(a1, "min")->valuedouble < 0.0 && cJSON_GetObjectItem(a1, "max")->valuedouble > 0.0);
        SL_CHECK(a2 && strcmp(cJSON_GetObjectItem(a2, "name")->valuestring, SL_ATTR_VORTICITY) == 0 &&
                 cJSON_GetObjectItem(a2, "min")->valuedouble >= 0.0);
        /* Same call in process: same bounds. */
        sl_dataset *ds = gen("{\"generator\":\"tornado\",\"lines\":25,\"points\":40,\"seed\":7}");
        cJSON *bmin = cJSON_GetObjectItem(cJSON_GetObjectItem(root, "bounds"), "min");
        if (ds && cJSON_GetArraySize(bmin) == 3)
            SL_CHECK_NEAR(cJSON_GetArrayItem(bmin, 2)->valuedouble, ds->bounds_min.z, 1e-12);
        else
            SL_CHECK(0);
        SL_CHECK(cJSON_IsNumber(cJSON_GetObjectItem(root, "load_ms")));
        sl_dataset_destroy(ds);
        cJSON_Delete(root);
    }
    free(out);
    rc = run_info("marschner_lobb", &out);
    root = rc == 0 && out ? cJSON_Parse(out) : NULL;
    SL_CHECK_MSG(root != NULL, "sightline-info marschner_lobb exit %d", rc);
    if (root) {
        cJSON *dims = cJSON_GetObjectItem(root, "dims"), *range = cJSON_GetObjectItem(root, "value_range");
        SL_CHECK(cJSON_GetArraySize(dims) == 3 && cJSON_GetArrayItem(dims, 0)->valueint == 41);
        SL_CHECK(strcmp(cJSON_GetObjectItem(root, "voxel_type")->valuestring, "f32") == 0);
        SL_CHECK(cJSON_GetArraySize(range) == 2 && cJSON_GetArrayItem(range, 1)->valuedouble <= 1.0);
        SL_CHECK(strcmp(cJSON_GetObjectItem(root, "name")->valuestring, "marschner_lobb") == 0);
        cJSON_Delete(root);
    }
    free(out);
    rc = run_info("{\"generator\":\"tornado\",\"lines\":0}", &out);
    SL_CHECK_MSG(rc == 2, "bad generator call: exit %d, want 2", rc);
    root = out ? cJSON_Parse(out) : NULL;
    SL_CHECK(root && strstr(cJSON_GetObjectItem(root, "error")->valuestring, "'lines'"));
    cJSON_Delete(root);
    free(out);
    rc = run_info("/nonexistent/file.trk", &out);
    SL_CHECK_MSG(rc == 2, "missing file: exit %d, want 2", rc);
    free(out);
    /* A file goes through sl_load_file (here the OBJ loader). */
    char path[] = "/tmp/sl_test_generate_XXXXXX.obj";
    int fd = mkstemps(path, 4);
    SL_CHECK(fd >= 0);
    if (fd >= 0) {
        static const char obj[] = "v 0 0 0\nv 2 0 0\nv 2 1 0\nl 1 2 3\n";
        SL_CHECK(write(fd, obj, sizeof obj - 1) == (ssize_t)(sizeof obj - 1));
        close(fd);
        rc = run_info(path, &out);
        root = rc == 0 && out ? cJSON_Parse(out) : NULL;
        SL_CHECK_MSG(root != NULL, "sightline-info %s: exit %d", path, rc);
        if (root) {
            cJSON *counts = cJSON_GetObjectItem(root, "counts");
            SL_CHECK(cJSON_GetObjectItem(counts, "segments") && cJSON_GetObjectItem(counts, "segments")->valuedouble == 2);
            cJSON *bmax = cJSON_GetObjectItem(cJSON_GetObjectItem(root, "bounds"), "max");
            SL_CHECK(cJSON_GetArraySize(bmax) == 3 && cJSON_GetArrayItem(bmax, 0)->valuedouble == 2.0);
            cJSON_Delete(root);
        }
        free(out);
        unlink(path);
    }
    /* An LR-spline volume (the loader's seed file: one element of a 2x2x1 mesh split at u = 0.5). */
    rc = run_info("tests/fuzz/corpus/lr/refined.lr", &out);
    root = rc == 0 && out ? cJSON_Parse(out) : NULL;
    SL_CHECK_MSG(root != NULL, "sightline-info refined.lr: exit %d", rc);
    if (root) {
        cJSON *degree = cJSON_GetObjectItem(root, "degree"), *counts = cJSON_GetObjectItem(root, "counts");
        SL_CHECK(strcmp(cJSON_GetObjectItem(root, "kind")->valuestring, "lr_volume") == 0);
        SL_CHECK(cJSON_GetArraySize(degree) == 3 && cJSON_GetArrayItem(degree, 0)->valueint == 2 &&
                 cJSON_GetArrayItem(degree, 1)->valueint == 1 && cJSON_GetArrayItem(degree, 2)->valueint == 0);
        SL_CHECK(cJSON_GetObjectItem(root, "components")->valueint == 1);
        SL_CHECK(cJSON_GetObjectItem(counts, "elements")->valuedouble == 5 &&
                 cJSON_GetObjectItem(counts, "basis_functions")->valuedouble == 13 &&
                 cJSON_GetObjectItem(counts, "mesh_rectangles")->valuedouble == 9);
        SL_CHECK(cJSON_GetObjectItem(root, "refinement_levels")->valuedouble == 2.0); /* u sides 1/2 and 1 */
        cJSON *dmax = cJSON_GetObjectItem(cJSON_GetObjectItem(root, "domain"), "max");
        SL_CHECK(cJSON_GetArraySize(dmax) == 3 && cJSON_GetArrayItem(dmax, 0)->valuedouble == 2.0 &&
                 cJSON_GetArrayItem(dmax, 2)->valuedouble == 1.0);
        cJSON *range = cJSON_GetObjectItem(root, "value_range");
        SL_CHECK(cJSON_GetArraySize(range) == 2 &&
                 cJSON_GetArrayItem(range, 0)->valuedouble < cJSON_GetArrayItem(range, 1)->valuedouble);
        SL_CHECK(strstr(cJSON_GetObjectItem(root, "value_range_note")->valuestring, "sampled") != NULL);
        cJSON_Delete(root);
    }
    free(out);
    rc = run_info(NULL, &out);
    SL_CHECK_MSG(rc == 1, "no argument: exit %d, want 1", rc);
    free(out);
}

/* ------------------------------------------------ pinned fingerprints */

/* Cross-machine determinism. Counts and the line structure (FNV-1a of the
 * offsets) must match exactly. Float values come from libm (sin, cos, exp),
 * whose last bit may differ between libm versions and CPUs (and an FMA
 * could be fused on another architecture), so for each channel two sums are
 * pinned instead of the bytes: the plain sum and an order-sensitive
 * weighted sum (weights 1 + (i mod 13) / 13), each compared within 1e-5 of
 * the channel's sum of |x|. A 1-ulp libm difference moves them by ~1e-7 of
 * that scale; a changed formula, seed, order or count moves them by far
 * more. Regenerate the table with SL_PRINT_FINGERPRINTS=1 (prints it) only
 * when a generator is changed on purpose. */
typedef struct fingerprint {
    uint64_t count_a, count_b;  /* lines, vertices; or voxels, components */
    uint64_t structure;         /* FNV-1a of line_offsets; or of dims + type */
    double sums[4][3];          /* channels x (sum, weighted sum, sum |x|) */
} fingerprint;

enum { FP_POSITIONS, FP_RADII, FP_ATTRIBUTES, FP_TANGENTS }; /* volumes: FP_POSITIONS holds the voxel values */

static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

static void fp_add(double sums[3], size_t i, double x)
{
    sums[0] += x;
    sums[1] += x * (1.0 + (double)(i % 13) / 13.0);
    sums[2] += fabs(x);
}

static void fingerprint_of(const sl_dataset *ds, fingerprint *fp)
{
    memset(fp, 0, sizeof *fp);
    uint64_t h = 0xcbf29ce484222325ull;
    if (ds->kind == SL_DATASET_LINES) {
        const sl_lines *l = &ds->lines;
        fp->count_a = l->line_count;
        fp->count_b = l->vertex_count;
        fp->structure = fnv1a(h, l->line_offsets, (l->line_count + 1) * sizeof *l->line_offsets);
        const double o[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
        for (size_t i = 0; i < 3 * l->vertex_count; i++)
            fp_add(fp->sums[FP_POSITIONS], i, o[i % 3] + (double)l->positions[i]);
        for (size_t i = 0; l->radii && i < l->vertex_count; i++)
            fp_add(fp->sums[FP_RADII], i, l->radii[i]);
        size_t k = 0;
        for (int a = 0; a < l->attribute_count; a++)
            for (size_t i = 0; i < l->vertex_count; i++)
                fp_add(fp->sums[FP_ATTRIBUTES], k++, l->attributes[a].values[i]);
        for (int a = 0; a < l->line_attribute_count; a++)
            for (size_t i = 0; i < l->line_count; i++)
                fp_add(fp->sums[FP_ATTRIBUTES], k++, l->line_attributes[a].values[i]);
        for (size_t i = 0; l->tangents && i < 3 * l->vertex_count; i++)
            fp_add(fp->sums[FP_TANGENTS], i, l->tangents[i]);
        return;
    }
    const sl_volume *v = &ds->volume;
    fp->count_a = (uint64_t)v->dims[0] * (uint64_t)v->dims[1] * (uint64_t)v->dims[2];
    fp->count_b = (uint64_t)v->components;
    int32_t shape[5] = {v->dims[0], v->dims[1], v->dims[2], v->components, (int32_t)v->type};
    fp->structure = fnv1a(h, shape, sizeof shape);
    size_t i = 0;
    for (int z = 0; z < v->dims[2]; z++)
        for (int y = 0; y < v->dims[1]; y++)
            for (int x = 0; x < v->dims[0]; x++)
                for (int c = 0; c < v->components; c++, i++)
                    fp_add(fp->sums[FP_POSITIONS], i, sl_volume_value(v, (size_t)x, (size_t)y, (size_t)z, c));
    const double geo[9] = {ds->origin.x, ds->origin.y, ds->origin.z, v->spacing[0], v->spacing[1], v->spacing[2],
                           ds->bounds_max.x, ds->bounds_max.y, ds->bounds_max.z};
    for (size_t g = 0; g < 9; g++)
        fp_add(fp->sums[FP_RADII], g, geo[g]);
}

static void test_fingerprints(void)
{
    static const struct { const char *call; fingerprint fp; } pinned[] = {
        /* SL_PRINT_FINGERPRINTS=1 output (x86-64, Debian 12 glibc 2.36, clang). */
    {"{\"generator\":\"tornado\",\"lines\":12,\"points\":40,\"seed\":3}",
     {12u, 480u, 0x42c472b71a3e5c45ull, {{719.96560938144103, 1052.5344542675259, 726.44823130453005}, {0, 0, 0}, {1004.469667857833, 1470.8261437422723, 1204.1086947519507}, {-7.5544770321612305, -11.328233461377078, 119.58155572996111}}}},
    {"{\"generator\":\"abc\",\"lines\":12,\"points\":40,\"seed\":3}",
     {12u, 480u, 0x42c472b71a3e5c45ull, {{4402.1141907572746, 6429.4883923209636, 4671.4461830258369}, {0, 0, 0}, {5839.2904967069626, 8529.050227857535, 5839.2904967069626}, {154.46864795940928, 225.0093947214861, 1860.010295356391}}}},
    {"{\"generator\":\"bundle\",\"lines\":12,\"points\":40,\"seed\":3}",
     {12u, 480u, 0x42c472b71a3e5c45ull, {{106.74300057906657, 155.84213819985183, 624.44715165067464}, {0, 0, 0}, {1004.4982829913497, 1467.5604803149515, 1004.4982829913497}, {0, 0, 0}}}},
    {"{\"generator\":\"furball\",\"segments\":2000,\"seed\":3}",
     {22u, 2022u, 0x4405a83ab945811eull, {{-37.133226229809225, -54.776307078579578, 2012.9445473989472}, {0, 0, 0}, {1264.8359995484352, 1852.9864606516282, 1264.8359995484352}, {0, 0, 0}}}},
    {"{\"generator\":\"hotroom\",\"lines\":200,\"seed\":3}",
     {200u, 686u, 0x3ed736e9b7c4939dull, {{3636.4620711244643, 5311.3955915481492, 3636.4620711244643}, {54.04782940261066, 79.797361513743056, 54.04782940261066}, {15807.136465698481, 23091.225588784735, 15807.136465698481}, {92.990609086977202, 138.91184507710312, 791.37388523835398}}}},
    {"{\"generator\":\"random_walk\",\"lines\":12,\"points\":40,\"seed\":3}",
     {12u, 480u, 0x42c472b71a3e5c45ull, {{-273.75547290383838, -400.05450750638471, 2377.3196250933688}, {2.3986461558379233, 3.5046494975686069, 2.3986461558379233}, {0, 0, 0}, {0, 0, 0}}}},
    {"{\"generator\":\"marschner_lobb\",\"size\":12,\"noise\":0.1,\"seed\":3}",
     {1728u, 1u, 0xd143def6ecbf59cbull, {{861.74810269557929, 1258.0309063051918, 864.52593155986688}, {0.54545454545454497, 2.0979020979020984, 6.545454545454545}, {0, 0, 0}, {0, 0, 0}}}},
    {"{\"generator\":\"torus\",\"size\":12,\"noise\":0.1,\"seed\":3}",
     {1728u, 1u, 0xd143def6ecbf59cbull, {{843.7492492251331, 1232.8549426402255, 857.36787907441612}, {0.54545454545454497, 2.0979020979020984, 6.545454545454545}, {0, 0, 0}, {0, 0, 0}}}},
    {"{\"generator\":\"head\",\"size\":12,\"noise\":0.5,\"seed\":3}",
     {1728u, 1u, 0x914e86e64053e0a9ull, {{436699, 636569.69230769132, 436699}, {60, 230.7692307692308, 720}, {0, 0, 0}, {0, 0, 0}}}},
    {"{\"generator\":\"ellipsoid\",\"size\":12,\"a\":0.5,\"b\":0.4,\"c\":0.3,\"anisotropy\":1.5,\"voxel_type\":\"u16\"}",
     {1152u, 1u, 0x665c9567ab8cc36dull, {{7077488, 9887651.5384615287, 7077488}, {0.63636363636363613, 2.2027972027972034, 6.545454545454545}, {0, 0, 0}, {0, 0, 0}}}},
    };
    static const char *const calls[] = {
        "{\"generator\":\"tornado\",\"lines\":12,\"points\":40,\"seed\":3}",
        "{\"generator\":\"abc\",\"lines\":12,\"points\":40,\"seed\":3}",
        "{\"generator\":\"bundle\",\"lines\":12,\"points\":40,\"seed\":3}",
        "{\"generator\":\"furball\",\"segments\":2000,\"seed\":3}",
        "{\"generator\":\"hotroom\",\"lines\":200,\"seed\":3}",
        "{\"generator\":\"random_walk\",\"lines\":12,\"points\":40,\"seed\":3}",
        "{\"generator\":\"marschner_lobb\",\"size\":12,\"noise\":0.1,\"seed\":3}",
        "{\"generator\":\"torus\",\"size\":12,\"noise\":0.1,\"seed\":3}",
        "{\"generator\":\"head\",\"size\":12,\"noise\":0.5,\"seed\":3}",
        "{\"generator\":\"ellipsoid\",\"size\":12,\"a\":0.5,\"b\":0.4,\"c\":0.3,\"anisotropy\":1.5,\"voxel_type\":\"u16\"}",
    };
    const char *print = getenv("SL_PRINT_FINGERPRINTS");
    size_t n_calls = sizeof calls / sizeof calls[0];
    SL_CHECK_MSG(print || sizeof pinned / sizeof pinned[0] == n_calls, "%zu pinned fingerprints for %zu calls",
                 sizeof pinned / sizeof pinned[0], n_calls);
    static const char *const channel[4] = {"positions/values", "radii/geometry", "attributes", "tangents"};
    for (size_t k = 0; k < n_calls; k++) {
        sl_dataset *ds = gen(calls[k]);
        if (!ds)
            continue;
        fingerprint fp;
        fingerprint_of(ds, &fp);
        sl_dataset_destroy(ds);
        if (print) {
            /* C string literal of the call, then the fingerprint as an initializer. */
            printf("    {\"");
            for (const char *c = calls[k]; *c; c++)
                printf(*c == '"' ? "\\\"" : "%c", *c);
            printf("\",\n     {%lluu, %lluu, 0x%016llxull, {", (unsigned long long)fp.count_a,
                   (unsigned long long)fp.count_b, (unsigned long long)fp.structure);
            for (int c = 0; c < 4; c++)
                printf("{%.17g, %.17g, %.17g}%s", fp.sums[c][0], fp.sums[c][1], fp.sums[c][2], c < 3 ? ", " : "");
            printf("}}},\n");
            continue;
        }
        if (k >= sizeof pinned / sizeof pinned[0])
            break;
        const fingerprint *want = &pinned[k].fp;
        SL_CHECK_MSG(strcmp(pinned[k].call, calls[k]) == 0, "pinned entry %zu is for %s", k, pinned[k].call);
        SL_CHECK_MSG(fp.count_a == want->count_a && fp.count_b == want->count_b, "%s: counts %llu %llu, pinned %llu %llu",
                     calls[k], (unsigned long long)fp.count_a, (unsigned long long)fp.count_b,
                     (unsigned long long)want->count_a, (unsigned long long)want->count_b);
        SL_CHECK_MSG(fp.structure == want->structure, "%s: structure hash %016llx, pinned %016llx", calls[k],
                     (unsigned long long)fp.structure, (unsigned long long)want->structure);
        for (int c = 0; c < 4; c++) {
            double tol = 1e-5 * want->sums[c][2] + 1e-12;
            for (int s = 0; s < 3; s++)
                SL_CHECK_MSG(fabs(fp.sums[c][s] - want->sums[c][s]) <= tol,
                             "%s: %s sum %d is %.17g, pinned %.17g (tolerance %.3g)", calls[k], channel[c], s,
                             fp.sums[c][s], want->sums[c][s], tol);
        }
    }
}

int main(void)
{
    test_determinism();
    test_fingerprints();
    test_counts();
    test_furball();
    test_random_walk();
    test_fields();
    test_flow_attributes();
    test_random();
    test_tracer();
    test_hotroom();
    test_volumes();
    test_ellipsoid();
    test_errors();
    test_catalog();
    test_info_tool();
    SL_TEST_END();
}
