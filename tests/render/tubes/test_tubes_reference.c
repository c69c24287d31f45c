/* test_tubes_reference.c — checks the CPU reference intersector itself against closed forms.
 *
 * A zero-length segment with zero tangents is a sphere; a straight segment
 * with tangents equal to its chord and a constant radius is a capsule. Both
 * have analytic ray intersections, computed here independently; the
 * reference must match them to 1e-9 of the radius. Also: the quadratic and
 * cubic sweeps coincide on such a straight segment, and a sphere that
 * contains the eye is not seen (the near-plane rule). The reference's input
 * builders (tubes_reference_input.h) are checked on hand-computed segments:
 * Hermite JSON as given, polylines with Catmull-Rom, data-direction and exact
 * tangents, radii from the data, an attribute or the parameter, the radius
 * scale. Single thread; no GL.
 */
#include <math.h>
#include <stdlib.h>

#include <cjson/cJSON.h>

#include "sl_test.h"
#include "tubes_reference.h"
#include "tubes_reference_input.h"

#define W 48
#define H 40

static sl_view make_view(sl_vec3 eye, sl_vec3 target)
{
    sl_view v = {.camera = {.eye = eye, .target = target, .up = sl_v3(0, 1, 0), .fov_y_deg = 40.0},
                 .width = W, .height = H};
    sl_err err;
    sl_status st = sl_view_init(&v, 1.0, &err);
    SL_CHECK(st == SL_OK);
    return v;
}

/* One segment of constant radius r. */
static void make_segment(tubes_ref_segment *g, sl_vec3 a, sl_vec3 ta, sl_vec3 b, sl_vec3 tb, double r)
{
    *g = (tubes_ref_segment){.p0 = a, .t0 = ta, .p1 = b, .t1 = tb, .r0 = r, .r1 = r};
}

/* Entry distance of the ray o + l d (unit d) into the sphere (c, r), or INFINITY. */
static double ray_sphere(sl_vec3 o, sl_vec3 d, sl_vec3 c, double r)
{
    sl_vec3 w = sl_v3_sub(c, o);
    double b = sl_v3_dot(w, d), disc = b * b - sl_v3_dot(w, w) + r * r;
    if (disc < 0.0)
        return INFINITY;
    double l = b - sqrt(disc);
    return l > 0.0 ? l : INFINITY;
}

/* Entry into the capsule around segment [a, b] with radius r (eye outside). */
static double ray_capsule(sl_vec3 o, sl_vec3 d, sl_vec3 a, sl_vec3 b, double r)
{
    double best = fmin(ray_sphere(o, d, a, r), ray_sphere(o, d, b, r));
    sl_vec3 axis = sl_v3_sub(b, a);
    double len = sl_v3_length(axis);
    sl_vec3 u = sl_v3_scale(axis, 1.0 / len);
    sl_vec3 w = sl_v3_sub(o, a);
    sl_vec3 dp = sl_v3_sub(d, sl_v3_scale(u, sl_v3_dot(d, u)));
    sl_vec3 wp = sl_v3_sub(w, sl_v3_scale(u, sl_v3_dot(w, u)));
    double qa = sl_v3_dot(dp, dp), qb = 2.0 * sl_v3_dot(dp, wp), qc = sl_v3_dot(wp, wp) - r * r;
    double disc = qb * qb - 4.0 * qa * qc;
    if (qa > 0.0 && disc >= 0.0) {
        double l = (-qb - sqrt(disc)) / (2.0 * qa);
        double s = sl_v3_dot(sl_v3_add(w, sl_v3_scale(d, l)), u);
        if (l > 0.0 && s >= 0.0 && s <= len)
            best = fmin(best, l);
    }
    return best;
}

static void check_against(const tubes_ref_desc *desc, double r, int capsule, sl_vec3 a, sl_vec3 b)
{
    float *dist = calloc(W * H, sizeof *dist), *rad = calloc(W * H, sizeof *rad);
    int *seg = calloc(W * H, sizeof *seg);
    SL_CHECK(dist && rad && seg);
    if (!dist || !rad || !seg)
        goto done;
    tubes_ref_render(desc, dist, rad, seg);
    const sl_view *v = desc->view;
    int hits = 0, agree_coverage = 1;
    double max_err = 0.0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            sl_vec3 d = sl_view_ray_dir(v, i, j);
            double l = capsule ? ray_capsule(v->camera.eye, d, a, b, r) : ray_sphere(v->camera.eye, d, a, r);
            float got = dist[j * W + i];
            if (isfinite(l) != (got > 0.0f)) {
                /* only a ray within float rounding of the rim may differ */
                agree_coverage = 0;
                continue;
            }
            if (!isfinite(l))
                continue;
            hits++;
            max_err = fmax(max_err, fabs(l - got));
            SL_CHECK(seg[j * W + i] == 0);
            SL_CHECK(fabs(rad[j * W + i] - r) < 1e-6);
        }
    SL_CHECK_MSG(hits > W * H / 20, "only %d pixels hit", hits);
    SL_CHECK(agree_coverage);
    /* float output: the distance (~3) is stored as float, 2^-23 relative */
    SL_CHECK_MSG(max_err <= 4.0 * 3.0 / 8388608.0 + 1e-9 * r, "max error %g", max_err);
done:
    free(dist);
    free(rad);
    free(seg);
}

static int near3(sl_vec3 a, sl_vec3 b, double tol)
{
    return fabs(a.x - b.x) <= tol && fabs(a.y - b.y) <= tol && fabs(a.z - b.z) <= tol;
}

/* Hermite JSON as given: positions, tangents, radii (scaled), the scalar as radius. */
static void check_input_json(void)
{
    const char *text = "{\"nodes\":[{\"p\":[1,2,3],\"t\":[0.5,0,0],\"r\":0.2,\"dr\":0.1,\"c\":0.7,\"dc\":-0.3},"
                       "{\"p\":[2,2,3],\"t\":[0,1,0],\"r\":0.3}],\"segments\":[[0,1],[1,0]]}";
    cJSON *root = cJSON_Parse(text);
    tubes_ref_input in;
    char msg[256];
    SL_CHECK(tubes_ref_is_hermite_json(root));
    SL_CHECK(tubes_ref_input_hermite_json(root, 0, 9.0, 2.0, &in, msg, sizeof msg) == 0);
    SL_CHECK(in.count == 2);
    const tubes_ref_segment *g = &in.segments[0];
    SL_CHECK(near3(g->p0, sl_v3(1, 2, 3), 0) && near3(g->t0, sl_v3(0.5, 0, 0), 0) && near3(g->p1, sl_v3(2, 2, 3), 0));
    SL_CHECK(g->r0 == 0.4 && g->dr0 == 0.2 && g->r1 == 0.6 && g->dr1 == 0.0); /* x radius_scale 2 */
    SL_CHECK(near3(in.segments[1].p0, sl_v3(2, 2, 3), 0) && near3(in.segments[1].t1, sl_v3(0.5, 0, 0), 0));
    tubes_ref_input_free(&in);
    SL_CHECK(tubes_ref_input_hermite_json(root, 1, 9.0, 1.0, &in, msg, sizeof msg) == 0);
    SL_CHECK(in.segments[0].r0 == 0.7 && in.segments[0].dr0 == -0.3 && in.segments[0].r1 == 0.0);
    tubes_ref_input_free(&in);
    cJSON_Delete(root);
    root = cJSON_Parse("{\"nodes\":[{\"p\":[0,0,0],\"t\":[1,0,0],\"r\":1}],\"segments\":[[0,1]]}");
    SL_CHECK(tubes_ref_input_hermite_json(root, 0, 1.0, 1.0, &in, msg, sizeof msg) != 0 && in.count == 0);
    cJSON_Delete(root);
}

/* A 3-vertex polyline: Catmull-Rom tangents x1 - x0, (x2 - x0) / 2, x2 - x1;
 * data tangents by direction (auto) or as they are; radii and their finite
 * differences; the constant radius without data radii. */
static void check_input_lines(void)
{
    sl_err err;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "three");
    SL_CHECK(ds && sl_lines_alloc(&ds->lines, 1, 3, 1, 1, &err) == SL_OK);
    float pos[9] = {0, 0, 0, 1, 0, 0, 1, 2, 0}, rad[3] = {0.1f, -0.2f, 0.4f}, tan[9] = {0, 3, 0, 0, 0, 5, 1, 0, 0};
    for (int i = 0; i < 9; i++) {
        ds->lines.positions[i] = pos[i];
        ds->lines.tangents[i] = tan[i];
    }
    for (int i = 0; i < 3; i++)
        ds->lines.radii[i] = rad[i];
    ds->lines.line_offsets[0] = 0;
    ds->lines.line_offsets[1] = 3;
    tubes_ref_input in;
    char msg[256];
    SL_CHECK(tubes_ref_input_lines(ds, TUBES_REF_TANGENTS_CATMULL_ROM, -1, 9.0, 1.0, &in, msg, sizeof msg) == 0);
    SL_CHECK(in.count == 2);
    const tubes_ref_segment *a = &in.segments[0], *b = &in.segments[1];
    SL_CHECK(near3(a->t0, sl_v3(1, 0, 0), 1e-12) && near3(a->t1, sl_v3(0.5, 1, 0), 1e-12) &&
             near3(b->t0, sl_v3(0.5, 1, 0), 1e-12) && near3(b->t1, sl_v3(0, 2, 0), 1e-12));
    /* radii |r|, dr by the same differences: r1 - r0 = -0.3, (r2 - r0) / 2 = 0.15, r2 - r1 = 0.6 */
    SL_CHECK(fabs(a->r0 - 0.1) < 1e-7 && fabs(a->r1 - 0.2) < 1e-7 && fabs(a->dr0 + 0.3) < 1e-7 &&
             fabs(a->dr1 - 0.15) < 1e-7 && fabs(b->dr1 - 0.6) < 1e-7);
    tubes_ref_input_free(&in);
    /* auto: the data's direction with the Catmull-Rom length (|(0.5, 1, 0)| = sqrt(1.25) inside) */
    SL_CHECK(tubes_ref_input_lines(ds, TUBES_REF_TANGENTS_AUTO, -1, 9.0, 1.0, &in, msg, sizeof msg) == 0);
    SL_CHECK(near3(in.segments[0].t0, sl_v3(0, 1, 0), 1e-12) && near3(in.segments[0].t1, sl_v3(0, 0, sqrt(1.25)), 1e-12));
    tubes_ref_input_free(&in);
    SL_CHECK(tubes_ref_input_lines(ds, TUBES_REF_TANGENTS_DATA, -1, 9.0, 2.0, &in, msg, sizeof msg) == 0);
    SL_CHECK(near3(in.segments[1].t0, sl_v3(0, 0, 5), 0) && fabs(in.segments[1].r1 - 0.8) < 1e-6);
    tubes_ref_input_free(&in);
    /* an attribute as radius, with its derivative attribute */
    float *rv = sl_lines_add_attribute(&ds->lines, "w", 0, &err), *dv = sl_lines_add_attribute(&ds->lines, "w_derivative", 0, &err);
    SL_CHECK(rv && dv);
    for (int i = 0; i < 3; i++) {
        rv[i] = 0.5f * (float)(i + 1);
        dv[i] = 0.25f;
    }
    SL_CHECK(tubes_ref_input_lines(ds, TUBES_REF_TANGENTS_AUTO, 0, 9.0, 1.0, &in, msg, sizeof msg) == 0);
    SL_CHECK(in.segments[1].r1 == 1.5 && in.segments[1].dr1 == 0.25);
    tubes_ref_input_free(&in);
    /* no data radii: the constant radius, no derivative */
    free(ds->lines.radii);
    ds->lines.radii = NULL;
    SL_CHECK(tubes_ref_input_lines(ds, TUBES_REF_TANGENTS_AUTO, -1, 0.125, 4.0, &in, msg, sizeof msg) == 0);
    SL_CHECK(in.segments[0].r0 == 0.125 && in.segments[1].r1 == 0.125 && in.segments[0].dr1 == 0.0);
    tubes_ref_input_free(&in);
    sl_dataset_destroy(ds);
}

int main(void)
{
    tubes_ref_segment seg;

    /* A sphere: zero-length segment with zero tangents. */
    sl_vec3 c = sl_v3(0.1, -0.05, 0.2);
    make_segment(&seg, c, sl_v3(0, 0, 0), c, sl_v3(0, 0, 0), 0.4);
    sl_view v = make_view(sl_v3(0.5, 0.4, 2.8), sl_v3(0, 0, 0));
    tubes_ref_desc desc = {.view = &v, .segments = &seg, .segment_count = 1};
    check_against(&desc, 0.4f, 0, c, sl_v3(0, 0, 0));

    /* A capsule: straight segment, tangents equal to the chord, constant radius. */
    sl_vec3 a = sl_v3(-0.75, -0.25, 0.0), b = sl_v3(0.5, 0.375, -0.25);
    sl_vec3 chord = sl_v3_sub(b, a);
    make_segment(&seg, a, chord, b, chord, 0.25);
    v = make_view(sl_v3(0.25, 1.0, 2.5), sl_v3(0, 0, 0));
    check_against(&desc, 0.25, 1, a, b);
    /* The true cubic sweep of the same straight segment is the same capsule. */
    desc.cubic = 1;
    check_against(&desc, 0.25, 1, a, b);
    desc.cubic = 0;

    /* A sphere containing the eye is not seen: its entry is behind the eye. */
    make_segment(&seg, sl_v3(0, 0, 0), sl_v3(0, 0, 0), sl_v3(0, 0, 0), sl_v3(0, 0, 0), 5.0);
    v = make_view(sl_v3(0.5, 0.4, 2.8), sl_v3(0, 0, 0));
    float dist[W * H];
    tubes_ref_render(&desc, dist, NULL, NULL);
    int any = 0;
    for (int k = 0; k < W * H; k++)
        any |= dist[k] != 0.0f;
    SL_CHECK(!any);

    check_input_json();
    check_input_lines();
    SL_TEST_END();
}
