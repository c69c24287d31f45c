/* test_tubes_reference.c — checks the CPU reference intersector itself against closed forms.
 *
 * A zero-length segment with zero tangents is a sphere; a straight segment
 * with tangents equal to its chord and a constant radius is a capsule. Both
 * have analytic ray intersections, computed here independently; the
 * reference must match them to 1e-9 of the radius. Also: the quadratic and
 * cubic sweeps coincide on such a straight segment, and a sphere that
 * contains the eye is not seen (the near-plane rule). Single thread; no GL.
 */
#include <math.h>
#include <stdlib.h>

#include "sl_test.h"
#include "tubes_reference.h"

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

/* Two nodes, one segment; positions relative to origin. */
static void make_nodes(sl_tubes_nodes *n, float *geometry, uint32_t *segments, sl_vec3 a, sl_vec3 ta, sl_vec3 b,
                       sl_vec3 tb, float r)
{
    float g[16] = {(float)a.x, (float)a.y, (float)a.z, r, (float)ta.x, (float)ta.y, (float)ta.z, 0,
                   (float)b.x, (float)b.y, (float)b.z, r, (float)tb.x, (float)tb.y, (float)tb.z, 0};
    for (int i = 0; i < 16; i++)
        geometry[i] = g[i];
    segments[0] = 0;
    segments[1] = 1;
    *n = (sl_tubes_nodes){.node_count = 2, .segment_count = 1, .geometry = geometry, .segments = segments,
                          .has_radii = 1, .color_attribute = -1};
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

int main(void)
{
    float geometry[16];
    uint32_t segments[2];
    sl_tubes_nodes nodes;

    /* A sphere: zero-length segment with zero tangents. */
    sl_vec3 c = sl_v3(0.1, -0.05, 0.2);
    make_nodes(&nodes, geometry, segments, c, sl_v3(0, 0, 0), c, sl_v3(0, 0, 0), 0.4f);
    sl_view v = make_view(sl_v3(0.5, 0.4, 2.8), sl_v3(0, 0, 0));
    tubes_ref_desc desc = {.view = &v, .nodes = &nodes, .radius = 1.0, .radius_scale = 1.0};
    check_against(&desc, 0.4f, 0, sl_v3((float)c.x, (float)c.y, (float)c.z), sl_v3(0, 0, 0));

    /* A capsule: straight segment, tangents equal to the chord, constant radius. */
    sl_vec3 a = sl_v3(-0.75, -0.25, 0.0), b = sl_v3(0.5, 0.375, -0.25);
    sl_vec3 chord = sl_v3_sub(b, a);
    make_nodes(&nodes, geometry, segments, a, chord, b, chord, 0.25f);
    v = make_view(sl_v3(0.25, 1.0, 2.5), sl_v3(0, 0, 0));
    check_against(&desc, 0.25, 1, a, b);
    /* The true cubic sweep of the same straight segment is the same capsule. */
    desc.cubic = 1;
    check_against(&desc, 0.25, 1, a, b);
    desc.cubic = 0;

    /* The same data through the radius parameter (no data radii). */
    nodes.has_radii = 0;
    desc.radius = 0.125;
    check_against(&desc, 0.125, 1, a, b);
    nodes.has_radii = 1;

    /* A sphere containing the eye is not seen: its entry is behind the eye. */
    make_nodes(&nodes, geometry, segments, sl_v3(0, 0, 0), sl_v3(0, 0, 0), sl_v3(0, 0, 0), sl_v3(0, 0, 0), 5.0f);
    v = make_view(sl_v3(0.5, 0.4, 2.8), sl_v3(0, 0, 0));
    float dist[W * H];
    tubes_ref_render(&desc, dist, NULL, NULL);
    int any = 0;
    for (int k = 0; k < W * H; k++)
        any |= dist[k] != 0.0f;
    SL_CHECK(!any);
    SL_TEST_END();
}
