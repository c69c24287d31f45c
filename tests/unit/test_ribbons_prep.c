/* test_ribbons_prep.c — frame resolution and point packing of `ribbons` (renderer/ribbons/ribbons_prep.h).
 *
 * The frame table on real generators (tornado carries helicity, furball does
 * not) and on a line set given normals; the error text of an explicit frame
 * the data cannot give; on an analytic helix with constant helicity h the
 * packed twist R = h s and its slope S = h (arc length s from the closed
 * form, not from the module); the packing of the w fields (radii, -1 without
 * radii); data normals projected off the tangent and unit.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sl_test.h"
#include "data/sl_generate.h"
#include "ribbons/ribbons_prep.h"

static void test_resolve(void)
{
    sl_err err;
    sl_dataset *tornado = NULL, *furball = NULL;
    SL_CHECK(sl_generate_json("{\"generator\":\"tornado\",\"lines\":20,\"seed\":1}", &tornado, &err) == SL_OK);
    SL_CHECK(sl_generate_json("{\"generator\":\"furball\",\"segments\":200,\"seed\":1}", &furball, &err) == SL_OK);
    if (!tornado || !furball) {
        sl_dataset_destroy(tornado);
        sl_dataset_destroy(furball);
        return;
    }
    sl_ribbons_frame f = SL_RIBBONS_FRAME_AUTO;
    SL_CHECK(sl_ribbons_frame_resolve(tornado, SL_RIBBONS_FRAME_AUTO, &f, &err) == SL_OK);
    SL_CHECK(f == SL_RIBBONS_FRAME_HELICITY);
    SL_CHECK(sl_ribbons_frame_resolve(furball, SL_RIBBONS_FRAME_AUTO, &f, &err) == SL_OK);
    SL_CHECK(f == SL_RIBBONS_FRAME_TRANSPORT);
    SL_CHECK(sl_ribbons_frame_resolve(tornado, SL_RIBBONS_FRAME_TRANSPORT, &f, &err) == SL_OK);
    SL_CHECK(f == SL_RIBBONS_FRAME_TRANSPORT);
    SL_CHECK(sl_ribbons_frame_resolve(tornado, SL_RIBBONS_FRAME_DATA, &f, &err) == SL_ERR_INVALID);
    SL_CHECK(f == SL_RIBBONS_FRAME_TRANSPORT);
    SL_CHECK(strstr(err.message, "frame 'data' needs per-vertex normals") != NULL);
    SL_CHECK(strstr(err.message, tornado->name) != NULL);
    SL_CHECK(sl_ribbons_frame_resolve(furball, SL_RIBBONS_FRAME_HELICITY, &f, &err) == SL_ERR_INVALID);
    SL_CHECK(strstr(err.message, "'helicity'") != NULL);
    /* Given normals: auto -> data. */
    size_t nv = furball->lines.vertex_count;
    furball->lines.normals = calloc(nv * 3, sizeof(float));
    if (furball->lines.normals) {
        SL_CHECK(sl_ribbons_frame_resolve(furball, SL_RIBBONS_FRAME_AUTO, &f, &err) == SL_OK);
        SL_CHECK(f == SL_RIBBONS_FRAME_DATA);
        SL_CHECK(sl_ribbons_frame_resolve(furball, SL_RIBBONS_FRAME_DATA, &f, &err) == SL_OK);
        SL_CHECK(f == SL_RIBBONS_FRAME_DATA);
    }
    sl_dataset_destroy(tornado);
    sl_dataset_destroy(furball);
}

/* A helix x = (a cos u, a sin u, c u), u = k du, with a constant `helicity` h
 * and given normals (the helix's binormal + a tangent component that the
 * projection must remove). */
static sl_dataset *make_helix(size_t nv, double a, double c, double du, float h)
{
    sl_err err;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "helix");
    if (!ds || sl_lines_alloc(&ds->lines, 1, nv, 1, 0, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    ds->lines.line_offsets[0] = 0;
    ds->lines.line_offsets[1] = (uint32_t)nv;
    float *hv = sl_lines_add_attribute(&ds->lines, "helicity", 0, &err);
    ds->lines.normals = malloc(nv * 3 * sizeof(float));
    if (!hv || !ds->lines.normals) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    for (size_t i = 0; i < nv; i++) {
        double u = (double)i * du;
        ds->lines.positions[3 * i] = (float)(a * cos(u));
        ds->lines.positions[3 * i + 1] = (float)(a * sin(u));
        ds->lines.positions[3 * i + 2] = (float)(c * u);
        ds->lines.radii[i] = 0.01f * (float)(i % 7);
        hv[i] = h;
        /* radial direction (⊥ t) plus 0.5 t */
        double L = sqrt(a * a + c * c);
        double t[3] = {-a * sin(u) / L, a * cos(u) / L, c / L};
        ds->lines.normals[3 * i] = (float)(cos(u) + 0.5 * t[0]);
        ds->lines.normals[3 * i + 1] = (float)(sin(u) + 0.5 * t[1]);
        ds->lines.normals[3 * i + 2] = (float)(0.5 * t[2]);
    }
    return ds;
}

static void test_helix(void)
{
    const double a = 0.3, c = 0.5 / (2.0 * M_PI), du = 2.0 * M_PI / 100.0;
    const float h = 4.0f;
    const size_t nv = 301;
    sl_dataset *ds = make_helix(nv, a, c, du, h);
    SL_CHECK(ds != NULL);
    if (!ds)
        return;
    sl_err err;
    sl_ribbons_points p;
    SL_CHECK(sl_ribbons_points_init(&p, &ds->lines, SL_RIBBONS_FRAME_HELICITY, -1, &err) == SL_OK);
    SL_CHECK(p.count == nv);
    /* Chord length of one step, closed form; s_i = i * chord. */
    double chord = sqrt(2.0 * a * a * (1.0 - cos(du)) + c * c * du * du);
    double max_rel = 0.0, max_s = 0.0, max_t = 0.0;
    for (size_t i = 1; i < nv; i++) {
        double s = (double)i * chord;
        max_rel = fmax(max_rel, fabs(p.normal_twist[4 * i + 3] - h * s) / (h * s));
        max_s = fmax(max_s, fabs(p.tangent_slope[4 * i + 3] - h) / h);
    }
    for (size_t i = 0; i < nv; i++) {
        const float *t = p.tangent_slope + 4 * i;
        max_t = fmax(max_t, fabs(sqrt((double)t[0] * t[0] + (double)t[1] * t[1] + (double)t[2] * t[2]) - 1.0));
    }
    SL_CHECK_NEAR(p.normal_twist[3], 0.0, 0.0);
    SL_CHECK_MSG(max_rel <= 1e-5, "R vs h s: max relative error %g", max_rel);
    SL_CHECK_MSG(max_s <= 1e-4, "S vs h: max relative error %g", max_s);
    SL_CHECK_MSG(max_t <= 1e-6, "tangent not unit: %g", max_t);
    /* Packing: xyz positions, w = radius as given. */
    for (size_t i = 0; i < nv; i += 37) {
        SL_CHECK(memcmp(p.pos_radius + 4 * i, ds->lines.positions + 3 * i, 3 * sizeof(float)) == 0);
        SL_CHECK(p.pos_radius[4 * i + 3] == ds->lines.radii[i]);
    }
    sl_ribbons_points_deinit(&p);

    /* Data frame: the given normals lose their tangent part, so n = the radial direction. */
    SL_CHECK(sl_ribbons_points_init(&p, &ds->lines, SL_RIBBONS_FRAME_DATA, -1, &err) == SL_OK);
    double max_n = 0.0, max_dot = 0.0;
    for (size_t i = 1; i + 1 < nv; i++) {
        double u = (double)i * du;
        const float *n = p.normal_twist + 4 * i, *t = p.tangent_slope + 4 * i;
        /* Expected: the given normal projected off the bisector tangent, which on this helix is
         * x[i+1] - x[i-1] ∝ (-a sin u sin du / du, a cos u sin du / du, c) (closed form). */
        double L = sqrt(a * a + c * c), k = sin(du) / du;
        double tb[3] = {-a * sin(u) * k, a * cos(u) * k, c}, lb = sqrt(tb[0] * tb[0] + tb[1] * tb[1] + c * c);
        double g[3] = {cos(u) - 0.5 * a * sin(u) / L, sin(u) + 0.5 * a * cos(u) / L, 0.5 * c / L};
        double gt = (g[0] * tb[0] + g[1] * tb[1] + g[2] * tb[2]) / (lb * lb);
        double e[3] = {g[0] - gt * tb[0], g[1] - gt * tb[1], g[2] - gt * tb[2]};
        double le = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        max_n = fmax(max_n, fabs(n[0] - e[0] / le) + fabs(n[1] - e[1] / le) + fabs(n[2] - e[2] / le));
        max_dot = fmax(max_dot, fabs((double)n[0] * t[0] + (double)n[1] * t[1] + (double)n[2] * t[2]));
    }
    SL_CHECK(p.frame == SL_RIBBONS_FRAME_DATA);
    SL_CHECK(p.normal_fallbacks == 0);
    SL_CHECK_MSG(max_n <= 1e-5, "data normal vs the projected given normal: %g", max_n);
    SL_CHECK_MSG(max_dot <= 1e-6, "n.t: %g", max_dot);
    sl_ribbons_points_deinit(&p);

    /* No radii: w = -1; radius_attribute: |attribute| (the helicity, 4). */
    free(ds->lines.radii);
    ds->lines.radii = NULL;
    SL_CHECK(sl_ribbons_points_init(&p, &ds->lines, SL_RIBBONS_FRAME_TRANSPORT, -1, &err) == SL_OK);
    SL_CHECK(p.pos_radius[3] == -1.0f && p.pos_radius[4 * (nv - 1) + 3] == -1.0f);
    /* transport still packs R (twist lines on a transport frame) */
    SL_CHECK(p.normal_twist[4 * (nv - 1) + 3] > 0.0f);
    sl_ribbons_points_deinit(&p);
    SL_CHECK(sl_ribbons_points_init(&p, &ds->lines, SL_RIBBONS_FRAME_TRANSPORT, 0, &err) == SL_OK);
    SL_CHECK(p.pos_radius[4 * 5 + 3] == 4.0f);
    sl_ribbons_points_deinit(&p);
    sl_ribbons_points_deinit(NULL);
    sl_dataset_destroy(ds);
}

/* Zero-length segments, one vertex and collinear lines: finite everything. */
static void test_degenerate(void)
{
    sl_err err;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "degenerate");
    const float pos[] = {0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 2, 0, 0, /* zero-length + collinear */
                         5, 5, 5,                                      /* one vertex */
                         3, 3, 3, 3, 3, 3};                            /* collapsed */
    if (!ds || sl_lines_alloc(&ds->lines, 3, 8, 0, 0, &err) != SL_OK) {
        SL_CHECK(0);
        sl_dataset_destroy(ds);
        return;
    }
    memcpy(ds->lines.positions, pos, sizeof pos);
    const uint32_t off[4] = {0, 5, 6, 8};
    memcpy(ds->lines.line_offsets, off, sizeof off);
    sl_ribbons_points p;
    SL_CHECK(sl_ribbons_points_init(&p, &ds->lines, SL_RIBBONS_FRAME_TRANSPORT, -1, &err) == SL_OK);
    int finite = 1;
    for (size_t i = 0; i < 8 * 4; i++)
        finite &= isfinite(p.pos_radius[i]) && isfinite(p.normal_twist[i]) && isfinite(p.tangent_slope[i]);
    SL_CHECK(finite);
    /* the zero-length first segment copies the tangent of the next */
    SL_CHECK_NEAR(p.tangent_slope[0], 1.0, 1e-6);
    SL_CHECK_NEAR(p.normal_twist[0] * p.tangent_slope[0], 0.0, 1e-6);
    sl_ribbons_points_deinit(&p);
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_resolve();
    test_helix();
    test_degenerate();
    SL_TEST_END();
}
