/* test_lines_prep.c — the shared CPU line preparation (renderer/lines/sl_lines_prep.h).
 *
 * Expected values are worked out by hand or from closed forms, not from the
 * module: tangents of both rules on small lines; transported normals unit
 * and orthogonal on tornado, and bit-identical to a copy of the frame loop
 * tubes_mesh_build.c had before the move (the golden images depend on it);
 * given normals projected, sign-aligned, and the fallback when parallel or
 * NaN; zero-length, collinear, one-segment and one-vertex lines; chunks that
 * never cross a line, sum to the segment count and bound their points;
 * trapezoid sums on a helix (R = h s), exact on linear data, NaN -> 0 and
 * the clamp; the frustum box test in, out, behind and across the near plane.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sl_test.h"
#include "core/sl_camera.h"
#include "data/sl_generate.h"
#include "lines/sl_lines_prep.h"

/* A line set of the given lines (vertex counts) and positions; no attributes. */
static sl_dataset *make_lines(size_t line_count, const size_t *counts, const float *positions)
{
    sl_err err;
    size_t nv = 0;
    for (size_t k = 0; k < line_count; k++)
        nv += counts[k];
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "t");
    if (!ds || sl_lines_alloc(&ds->lines, line_count, nv, 0, 0, &err) != SL_OK) {
        SL_CHECK(0);
        sl_dataset_destroy(ds);
        return NULL;
    }
    memcpy(ds->lines.positions, positions, nv * 3 * sizeof(float));
    ds->lines.line_offsets[0] = 0;
    for (size_t k = 0; k < line_count; k++)
        ds->lines.line_offsets[k + 1] = ds->lines.line_offsets[k] + (uint32_t)counts[k];
    return ds;
}

#define CHECK_V3(a, x, y, z, tol) do { \
    SL_CHECK_NEAR((a)[0], (x), (tol)); SL_CHECK_NEAR((a)[1], (y), (tol)); SL_CHECK_NEAR((a)[2], (z), (tol)); \
} while (0)

static double dot3(const float *a, const float *b) { return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2]; }
static double len3(const float *a) { return sqrt(dot3(a, a)); }

static void test_tangents(void)
{
    /* 0: corner; 1: reversal; 2: zero-length first segment; 3: collapsed; 4: one vertex; 5: one segment */
    const size_t counts[6] = {3, 3, 3, 3, 1, 2};
    const float p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0,
                       0, 0, 0, 1, 0, 0, 0, 0, 0,
                       0, 0, 0, 0, 0, 0, 2, 0, 0,
                       5, 5, 5, 5, 5, 5, 5, 5, 5,
                       7, 7, 7,
                       0, 0, 0, 0, 0, 3};
    sl_dataset *ds = make_lines(6, counts, p);
    if (!ds)
        return;
    const sl_lines *l = &ds->lines;
    float t[16 * 3];
    size_t segs = sl_lines_tangents(l, SL_LINES_TANGENT_BISECTOR, t);
    SL_CHECK(segs == 2 + 2 + 1 + 0 + 0 + 1);
    const float h = (float)(1.0 / sqrt(2.0));
    CHECK_V3(&t[0], 1, 0, 0, 0);
    CHECK_V3(&t[3], h, h, 0, 1e-7);
    CHECK_V3(&t[6], 0, 1, 0, 0);
    CHECK_V3(&t[12], 1, 0, 0, 0); /* reversal: the incoming direction */
    CHECK_V3(&t[15], -1, 0, 0, 0);
    CHECK_V3(&t[18], 1, 0, 0, 0); /* zero-length: the duplicate copies its kept vertex */
    CHECK_V3(&t[21], 1, 0, 0, 0);
    CHECK_V3(&t[24], 1, 0, 0, 0);
    for (int v = 9; v < 13; v++)  /* collapsed and one-vertex lines */
        CHECK_V3(&t[3 * v], 0, 0, 0, 0);
    CHECK_V3(&t[39], 0, 0, 1, 0);
    CHECK_V3(&t[42], 0, 0, 1, 0);

    size_t kept[3];
    SL_CHECK(sl_lines_kept(l, 2, kept) == 2 && kept[0] == 6 && kept[1] == 8);
    SL_CHECK(sl_lines_kept(l, 3, kept) == 1 && kept[0] == 9);
    SL_CHECK(sl_lines_kept(l, 4, kept) == 1 && kept[0] == 12);

    /* Catmull-Rom: (x[i+1] - x[i-1]) / 2 inside, one-sided at the ends, over every vertex. */
    SL_CHECK(sl_lines_tangents(l, SL_LINES_TANGENT_CATMULL_ROM, t) == segs);
    CHECK_V3(&t[0], 1, 0, 0, 0);
    CHECK_V3(&t[3], 0.5, 0.5, 0, 0);
    CHECK_V3(&t[6], 0, 1, 0, 0);
    CHECK_V3(&t[18], 0, 0, 0, 0);     /* a zero-length segment is not skipped here */
    CHECK_V3(&t[21], 1, 0, 0, 0);
    CHECK_V3(&t[24], 2, 0, 0, 0);
    CHECK_V3(&t[36], 0, 0, 0, 0);     /* one vertex */
    CHECK_V3(&t[39], 0, 0, 3, 0);
    sl_dataset_destroy(ds);
}

/* tubes_mesh_build.c before the move, reduced to the frames it put at kept vertices. */
typedef struct ov { float x, y, z; } ov;
static ov osub(ov a, ov b) { return (ov){a.x - b.x, a.y - b.y, a.z - b.z}; }
static ov oadd(ov a, ov b) { return (ov){a.x + b.x, a.y + b.y, a.z + b.z}; }
static ov oscale(ov a, float s) { return (ov){a.x * s, a.y * s, a.z * s}; }
static float odot(ov a, ov b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static ov ocross(ov a, ov b) { return (ov){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static float olen(ov a) { return sqrtf(odot(a, a)); }
static ov onorm(ov a) { float l = olen(a); return l > 0.0f ? oscale(a, 1.0f / l) : (ov){0, 0, 0}; }
static ov oload(const float *p) { return (ov){p[0], p[1], p[2]}; }
static ov oany_orthogonal(ov t)
{
    ov axis = fabsf(t.x) < 0.6f ? (ov){1, 0, 0} : (fabsf(t.y) < 0.6f ? (ov){0, 1, 0} : (ov){0, 0, 1});
    return onorm(ocross(t, axis));
}

/* Compares the old loop's t and normal bit for bit with the module's at every kept vertex. */
static size_t compare_with_old_loop(const sl_lines *lines, const float *t3, const float *n3)
{
    size_t *kept = malloc((lines->vertex_count ? lines->vertex_count : 1) * sizeof *kept), differ = 0;
    for (size_t li = 0; li < lines->line_count; li++) {
        size_t first = lines->line_offsets[li], end = lines->line_offsets[li + 1];
        size_t n = 0;
        for (size_t v = first; v < end; v++) {
            if (n > 0 && olen(osub(oload(&lines->positions[3 * v]), oload(&lines->positions[3 * kept[n - 1]]))) == 0.0f)
                continue;
            kept[n++] = v;
        }
        if (n < 2)
            continue;
        ov normal = {0, 0, 0};
        for (size_t k = 0; k < n; k++) {
            ov p = oload(&lines->positions[3 * kept[k]]);
            ov d_in = k > 0 ? onorm(osub(p, oload(&lines->positions[3 * kept[k - 1]]))) : (ov){0, 0, 0};
            ov d_out = k + 1 < n ? onorm(osub(oload(&lines->positions[3 * kept[k + 1]]), p)) : (ov){0, 0, 0};
            ov t = onorm(oadd(d_in, d_out));
            if (olen(t) < 1e-6f)
                t = k > 0 ? d_in : d_out;
            normal = k == 0 ? oany_orthogonal(t) : onorm(osub(normal, oscale(t, odot(normal, t))));
            if (olen(normal) < 0.5f)
                normal = oany_orthogonal(t);
            float old[6] = {t.x, t.y, t.z, normal.x, normal.y, normal.z};
            differ += memcmp(old, &t3[3 * kept[k]], 3 * sizeof(float)) != 0 ||
                      memcmp(old + 3, &n3[3 * kept[k]], 3 * sizeof(float)) != 0;
        }
    }
    free(kept);
    return differ;
}

static void check_frames(const char *what, const sl_lines *l)
{
    size_t nv = l->vertex_count ? l->vertex_count : 1;
    float *t = malloc(nv * 3 * sizeof *t), *n = malloc(nv * 3 * sizeof *n);
    if (!t || !n) {
        SL_CHECK(0);
        free(t);
        free(n);
        return;
    }
    sl_lines_tangents(l, SL_LINES_TANGENT_BISECTOR, t);
    sl_lines_transport_normals(l, t, NULL, n);
    double worst_len = 0.0, worst_dot = 0.0;
    for (size_t v = 0; v < l->vertex_count; v++) {
        if (len3(&t[3 * v]) == 0.0)
            continue;
        worst_len = fmax(worst_len, fabs(len3(&n[3 * v]) - 1.0));
        worst_dot = fmax(worst_dot, fabs(dot3(&n[3 * v], &t[3 * v])));
    }
    SL_CHECK_MSG(worst_len <= 1e-6 && worst_dot <= 1e-6, "%s: |n| - 1 up to %g, n.t up to %g", what, worst_len,
                 worst_dot);
    size_t differ = compare_with_old_loop(l, t, n);
    SL_CHECK_MSG(differ == 0, "%s: %zu kept vertices differ from the old tubes_mesh_build frames", what, differ);
    free(t);
    free(n);
}

static void test_transport(void)
{
    sl_err err;
    sl_dataset *ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"tornado\",\"lines\":100,\"seed\":1}", &ds, &err) == SL_OK);
    if (ds) {
        SL_CHECK(ds->lines.vertex_count > 1000);
        check_frames("tornado", &ds->lines);
        sl_dataset_destroy(ds);
    }
    ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"random_walk\",\"lines\":20,\"seed\":3}", &ds, &err) == SL_OK);
    if (ds) {
        check_frames("random_walk", &ds->lines);
        sl_dataset_destroy(ds);
    }
    /* Sharp corners, reversals, duplicates, a collinear run, one segment, one vertex. */
    const size_t counts[5] = {8, 4, 2, 1, 3};
    const float p[] = {0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 1, 0, 1, 1, 1, 1, 1, 1,
                       0, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0, 3,
                       1, 2, 3, 1, 2, 4,
                       9, 9, 9,
                       0, 0, 0, 0, 0, 0, 0, 0, 0};
    sl_dataset *hand = make_lines(5, counts, p);
    if (!hand)
        return;
    const sl_lines *l = &hand->lines;
    check_frames("hand-made", l);
    float t[18 * 3], n[18 * 3];
    sl_lines_tangents(l, SL_LINES_TANGENT_BISECTOR, t);
    sl_lines_transport_normals(l, t, NULL, n);
    /* Collinear line along z: one constant normal, any_orthogonal((0,0,1)) = (0,0,1) x (1,0,0) = (0,1,0). */
    for (int v = 8; v < 12; v++)
        CHECK_V3(&n[3 * v], 0, 1, 0, 0);
    CHECK_V3(&n[42], 1, 0, 0, 0);        /* one vertex: (1,0,0) */
    for (int v = 15; v < 18; v++)        /* collapsed line */
        CHECK_V3(&n[3 * v], 1, 0, 0, 0);
    SL_CHECK(memcmp(&n[3], &n[6], 3 * sizeof(float)) == 0); /* a duplicate copies its kept vertex */
    /* A seed is projected off t0 and then transported: straight line along z, seed (1, 0, 5) -> (1, 0, 0). */
    float seed[18 * 3] = {0};
    seed[24] = 1, seed[26] = 5;
    sl_lines_transport_normals(l, t, seed, n);
    for (int v = 8; v < 12; v++)
        CHECK_V3(&n[3 * v], 1, 0, 0, 0);
    sl_dataset_destroy(hand);
}

static void test_project_normals(void)
{
    /* Straight line along x, six points. */
    const size_t counts[1] = {6};
    const float p[] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0, 0, 5, 0, 0};
    sl_dataset *ds = make_lines(1, counts, p);
    if (!ds)
        return;
    float t[18], n[18];
    sl_lines_tangents(&ds->lines, SL_LINES_TANGENT_BISECTOR, t);
    const float given[18] = {2, 3, 0,         /* projected off x and normalized: (0, 1, 0) */
                             0, -1, 0,        /* flips to follow (0, 1, 0) */
                             5, 0, 0,         /* parallel to t: falls back to the previous */
                             NAN, 0, 1,       /* non-finite: falls back */
                             1e-4f, 0, 1,     /* z: projection 1 of length 1: kept */
                             1, 1e-4f, 0};    /* projection 1e-4 < 1e-3 of |n|: falls back */
    size_t fallbacks = sl_lines_project_normals(&ds->lines, t, given, n);
    SL_CHECK(fallbacks == 3);
    CHECK_V3(&n[0], 0, 1, 0, 1e-7);
    CHECK_V3(&n[3], 0, 1, 0, 0);
    CHECK_V3(&n[6], 0, 1, 0, 1e-7);
    CHECK_V3(&n[9], 0, 1, 0, 1e-7);
    CHECK_V3(&n[12], 0, 0, 1, 1e-7);
    CHECK_V3(&n[15], 0, 0, 1, 1e-7);
    /* Parallel at the first point: any vector orthogonal to t, unit. */
    const float parallel[18] = {1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    SL_CHECK(sl_lines_project_normals(&ds->lines, t, parallel, n) == 1);
    SL_CHECK_NEAR(len3(&n[0]), 1.0, 1e-6);
    SL_CHECK_NEAR(dot3(&n[0], &t[0]), 0.0, 1e-6);
    sl_dataset_destroy(ds);
}

static void test_chunks(void)
{
    sl_err err;
    sl_dataset *ds = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"tornado\",\"lines\":50,\"seed\":2}", &ds, &err) == SL_OK);
    if (!ds)
        return;
    const sl_lines *l = &ds->lines;
    size_t want_segments = 0;
    for (size_t k = 0; k < l->line_count; k++) {
        size_t len = l->line_offsets[k + 1] - l->line_offsets[k];
        want_segments += len >= 2 ? len - 1 : 0;
    }
    const uint32_t sizes[3] = {1, 7, 64};
    for (int s = 0; s < 3; s++) {
        sl_line_chunk *c = NULL;
        size_t count = 0;
        SL_CHECK(sl_lines_chunks_build(l, sizes[s], &c, &count, &err) == SL_OK);
        size_t sum = 0, crossing = 0, outside = 0, too_big = 0, gaps = 0;
        uint32_t next_point = 0, line = 0;
        for (size_t i = 0; i < count; i++) {
            uint32_t lo = l->line_offsets[c[i].line], hi = l->line_offsets[c[i].line + 1];
            crossing += c[i].first_point < lo || c[i].first_point + c[i].segments >= hi;
            too_big += c[i].segments == 0 || c[i].segments > sizes[s];
            /* Chunks follow each other: a new line starts at its first point, a chunk of the same line at the
             * previous chunk's last point. */
            if (i == 0 || c[i].line != line)
                gaps += c[i].first_point != lo;
            else
                gaps += c[i].first_point != next_point;
            line = c[i].line;
            next_point = c[i].first_point + c[i].segments;
            sum += c[i].segments;
            for (uint32_t v = c[i].first_point; v <= c[i].first_point + c[i].segments; v++)
                for (int a = 0; a < 3; a++)
                    outside += l->positions[3 * (size_t)v + a] < c[i].lo[a] || l->positions[3 * (size_t)v + a] > c[i].hi[a];
        }
        SL_CHECK_MSG(sum == want_segments && crossing == 0 && outside == 0 && too_big == 0 && gaps == 0,
                     "chunks of %u: %zu segments of %zu, %zu cross a line, %zu points outside their box, "
                     "%zu oversized, %zu gaps", sizes[s], sum, want_segments, crossing, outside, too_big, gaps);
        free(c);
    }
    /* Hand-made: a 5-segment line in chunks of 2 -> 2 + 2 + 1; one-vertex lines give none. */
    const size_t counts[3] = {1, 6, 1};
    const float p[] = {9, 9, 9, 0, 0, 0, 1, 0, 0, 2, 5, 0, 3, 0, 0, 4, 0, -1, 5, 0, 0, 8, 8, 8};
    sl_dataset *hand = make_lines(3, counts, p);
    if (hand) {
        sl_line_chunk *c = NULL;
        size_t count = 0;
        SL_CHECK(sl_lines_chunks_build(&hand->lines, 2, &c, &count, &err) == SL_OK && count == 3);
        if (count == 3) {
            SL_CHECK(c[0].first_point == 1 && c[0].segments == 2 && c[0].line == 1);
            SL_CHECK(c[1].first_point == 3 && c[1].segments == 2);
            SL_CHECK(c[2].first_point == 5 && c[2].segments == 1);
            CHECK_V3(c[0].lo, 0, 0, 0, 0);
            CHECK_V3(c[0].hi, 2, 5, 0, 0);
            CHECK_V3(c[1].lo, 2, 0, -1, 0);
            CHECK_V3(c[1].hi, 4, 5, 0, 0);
        }
        free(c);
        SL_CHECK(sl_lines_chunks_build(&hand->lines, 0, &c, &count, &err) == SL_ERR_INVALID && !c && count == 0);
        sl_dataset_destroy(hand);
    }
    sl_dataset_destroy(ds);
}

static void test_accumulate(void)
{
    /* Helix of radius a and pitch 2 pi c: arc length s = theta sqrt(a^2 + c^2); constant h gives R = h s. */
    enum { N = 12001 };
    const double a = 0.3, c = 0.5 / (2.0 * SL_PI), turns = 3.0, h = 4.0;
    float *p = malloc(N * 3 * sizeof *p), *values = malloc(N * sizeof *values);
    float *r = malloc(N * sizeof *r), *d = malloc(N * sizeof *d);
    if (!p || !values || !r || !d) {
        SL_CHECK(0);
        free(p), free(values), free(r), free(d);
        return;
    }
    for (int i = 0; i < N; i++) {
        double th = 2.0 * SL_PI * turns * i / (N - 1);
        p[3 * i] = (float)(a * cos(th)), p[3 * i + 1] = (float)(a * sin(th)), p[3 * i + 2] = (float)(c * th);
        values[i] = (float)h;
    }
    const size_t counts[1] = {N};
    sl_dataset *ds = make_lines(1, counts, p);
    if (ds) {
        sl_lines_accumulate(&ds->lines, values, INFINITY, r, d);
        /* Relative to R at the end: one short float segment alone is only good to ~1e-4. */
        double worst = 0.0, worst_d = 0.0, s_end = 2.0 * SL_PI * turns * sqrt(a * a + c * c);
        for (int i = 1; i < N; i++) {
            double s = 2.0 * SL_PI * turns * i / (N - 1) * sqrt(a * a + c * c);
            worst = fmax(worst, fabs(r[i] - h * s) / (h * s_end));
            worst_d = fmax(worst_d, fabs(d[i] - h) / h);
        }
        SL_CHECK_MSG(worst <= 1e-6 && r[0] == 0.0f, "helix: R(s) vs h s: relative error %g", worst);
        SL_CHECK_MSG(worst_d <= 1e-5, "helix: dR/ds vs h: relative error %g", worst_d);
        /* values NULL: the arc length itself */
        sl_lines_accumulate(&ds->lines, NULL, INFINITY, r, NULL);
        SL_CHECK_NEAR(r[N - 1] / s_end, 1.0, 1e-6);
        sl_dataset_destroy(ds);
    }
    free(p), free(values), free(r), free(d);

    /* Linear v = 2x + 1 on uneven steps along x: trapezoids are exact, R = x^2 + x. A second line restarts at 0. */
    const size_t lc[2] = {4, 3};
    const float lp[] = {0, 0, 0, 1, 0, 0, 3, 0, 0, 6, 0, 0,
                        0, 0, 0, 0, 1, 0, 0, 2, 0};
    sl_dataset *lin = make_lines(2, lc, lp);
    if (!lin)
        return;
    float v[7] = {1, 3, 7, 13, 1, NAN, 1}, out[7], dds[7];
    sl_lines_accumulate(&lin->lines, v, INFINITY, out, dds);
    SL_CHECK_NEAR(out[0], 0, 0);
    SL_CHECK_NEAR(out[1], 2, 1e-6);
    SL_CHECK_NEAR(out[2], 12, 1e-6);
    SL_CHECK_NEAR(out[3], 42, 1e-5);
    SL_CHECK_NEAR(dds[0], 2, 1e-6);          /* one-sided: (2 - 0) / 1 */
    SL_CHECK_NEAR(dds[1], 12.0 / 3.0, 1e-6); /* central over arc length: (12 - 0) / (3 - 0) */
    SL_CHECK_NEAR(dds[3], 30.0 / 3.0, 1e-6); /* one-sided end: (42 - 12) / (6 - 3) */
    /* NaN counts as 0: (1 + 0) / 2 and (0 + 1) / 2 per unit segment. */
    SL_CHECK_NEAR(out[4], 0, 0);
    SL_CHECK_NEAR(out[5], 0.5, 1e-7);
    SL_CHECK_NEAR(out[6], 1.0, 1e-7);
    /* Huge values are clamped to the limit at every partial sum. */
    float huge[7] = {1e30f, 1e30f, 1e30f, -1e30f, 1, 1, 1};
    sl_lines_accumulate(&lin->lines, huge, 1e6, out, NULL);
    SL_CHECK_NEAR(out[1], 1e6, 0);
    SL_CHECK_NEAR(out[2], 1e6, 0);
    SL_CHECK_NEAR(out[3], 1e6, 0); /* (1e30 - 1e30) / 2 x 3 = 0 added to the clamped 1e6 */
    SL_CHECK_NEAR(out[6], 2.0, 1e-6);
    sl_dataset_destroy(lin);
}

static void test_box_visible(void)
{
    sl_err err;
    sl_view view;
    memset(&view, 0, sizeof view);
    view.camera = (sl_camera){.eye = {0, 0, 5}, .target = {0, 0, 0}, .up = {0, 1, 0}, .fov_y_deg = 90.0};
    view.width = view.height = 100;
    view.near_plane = 0.1;
    SL_CHECK(sl_view_init(&view, 1.0, &err) == SL_OK);
    const sl_vec3 o = {0, 0, 0}, shifted = {100, 0, 0};
    /* tan(45 deg) = 1: at eye distance 5 (z = 0) the frustum spans x, y in [-5, 5]. */
    SL_CHECK(sl_lines_box_visible(&view, o, (float[3]){-0.1f, -0.1f, -0.1f}, (float[3]){0.1f, 0.1f, 0.1f}, 0.0));
    SL_CHECK(!sl_lines_box_visible(&view, o, (float[3]){5.5f, -0.1f, -0.1f}, (float[3]){6, 0.1f, 0.1f}, 0.0));
    SL_CHECK(sl_lines_box_visible(&view, o, (float[3]){5.5f, -0.1f, -0.1f}, (float[3]){6, 0.1f, 0.1f}, 1.0));
    SL_CHECK(!sl_lines_box_visible(&view, o, (float[3]){-0.1f, 5.5f, -0.1f}, (float[3]){0.1f, 6, 0.1f}, 0.0));
    SL_CHECK(!sl_lines_box_visible(&view, o, (float[3]){-6, -0.1f, -0.1f}, (float[3]){-5.5f, 0.1f, 0.1f}, 0.0));
    SL_CHECK(!sl_lines_box_visible(&view, o, (float[3]){-0.1f, -6, -0.1f}, (float[3]){0.1f, -5.5f, 0.1f}, 0.0));
    /* Behind the eye (z > 5), and in front of it but closer than the near plane. */
    SL_CHECK(!sl_lines_box_visible(&view, o, (float[3]){-1, -1, 6}, (float[3]){1, 1, 8}, 0.0));
    SL_CHECK(!sl_lines_box_visible(&view, o, (float[3]){-0.01f, -0.01f, 4.95f}, (float[3]){0.01f, 0.01f, 4.96f}, 0.0));
    /* Straddling the near plane (and the eye). */
    SL_CHECK(sl_lines_box_visible(&view, o, (float[3]){-0.5f, -0.5f, 4}, (float[3]){0.5f, 0.5f, 6}, 0.0));
    /* The origin is added: the same box 100 units to the right is out, and back in view from there. */
    SL_CHECK(!sl_lines_box_visible(&view, shifted, (float[3]){-0.1f, -0.1f, -0.1f}, (float[3]){0.1f, 0.1f, 0.1f}, 0.0));
    SL_CHECK(sl_lines_box_visible(&view, shifted, (float[3]){-100.1f, -0.1f, -0.1f}, (float[3]){-99.9f, 0.1f, 0.1f},
                                  0.0));
}

static void test_radii_and_bounds(void)
{
    sl_err err;
    const size_t counts[1] = {4};
    const float p[] = {1, -2, 3, -4, 5, 0, 2, 2, 2, 0, 9, -7};
    sl_dataset *ds = make_lines(1, counts, p);
    if (!ds)
        return;
    float *a = sl_lines_add_attribute(&ds->lines, "w", 0, &err);
    SL_CHECK(a != NULL);
    if (a) {
        const float values[4] = {-2, NAN, INFINITY, 0.5f};
        memcpy(a, values, sizeof values);
        float out[8] = {9, 9, 9, 9, 9, 9, 9, 9};
        sl_lines_attribute_radii(&ds->lines, 0, out, 2);
        SL_CHECK(out[0] == 2 && out[2] == 0 && out[4] == 0 && out[6] == 0.5f);
        SL_CHECK(out[1] == 9 && out[7] == 9); /* the stride leaves the rest alone */
    }
    double lo[3], hi[3];
    sl_lines_position_bounds(&ds->lines, lo, hi);
    SL_CHECK(lo[0] == -4 && lo[1] == -2 && lo[2] == -7 && hi[0] == 2 && hi[1] == 9 && hi[2] == 3);
    sl_dataset_destroy(ds);
    sl_lines empty = {0};
    sl_lines_position_bounds(&empty, lo, hi);
    SL_CHECK(lo[0] == 0 && hi[2] == 0);
}

int main(void)
{
    test_tangents();
    test_transport();
    test_project_normals();
    test_chunks();
    test_accumulate();
    test_box_visible();
    test_radii_and_bounds();
    SL_TEST_END();
}
