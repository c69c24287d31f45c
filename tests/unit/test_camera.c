/* test_camera.c — the camera spec (scene.md, sl_camera.h) and the sl_math.h helpers it uses.
 *
 * An independent double-precision transcription of the spec (own vector
 * code, own column-major matrix product) gives the pixel-centre ray of pixel
 * (i, j); points along it must land, through sl_view's view_projection, on
 * NDC (2(i+.5)/W - 1, 1 - 2(j+.5)/H) — row 0 at NDC +1, since images are
 * read back top-down — for many sizes (1x1, thin, non-square), fovs from 1
 * to 179 degrees and random eyes/targets/ups (bound: 1e-7 in double; the
 * worst case, 1 degree fov at 1e6 units, loses ~1e-8 to cancellation). With
 * the dataset origin 1e6 away, the float matrices the GPU gets must still
 * hit 2e-5 in NDC (and absolute-coordinate float matrices must not: a
 * control that shows the check can fail). Also: reversed infinite-far depth
 * and sl_view_depth_to_distance against the Euclidean distance, sl_view_ray_dir,
 * the orbit conventions, rejection of degenerate cameras without NaN, and
 * the one set of defaults (sl_orbit_default) and sl_camera_spec_resolve.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/sl_camera.h"
#include "core/sl_math.h"
#include "sl_test.h"

/* ---- independent reference (does not use sl_math.h) ---------------------- */

typedef struct dv { double x, y, z; } dv;

static dv d3(double x, double y, double z) { return (dv){x, y, z}; }
static dv dsub(dv a, dv b) { return d3(a.x - b.x, a.y - b.y, a.z - b.z); }
static dv dadd(dv a, dv b) { return d3(a.x + b.x, a.y + b.y, a.z + b.z); }
static dv dmul(dv a, double s) { return d3(a.x * s, a.y * s, a.z * s); }
static double ddot(dv a, dv b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv dcross(dv a, dv b) { return d3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static double dlen(dv a) { return sqrt(ddot(a, a)); }
static dv dnorm(dv a) { return dmul(a, 1.0 / dlen(a)); }
static dv from_sl(sl_vec3 v) { return d3(v.x, v.y, v.z); }
static sl_vec3 to_sl(dv v) { return sl_v3(v.x, v.y, v.z); }

typedef struct ref_cam { dv eye, F, R, U; double tanh_, aspect; int w, h; } ref_cam;

static ref_cam ref_make(dv eye, dv target, dv up, double fov_deg, int w, int h)
{
    ref_cam c;
    c.eye = eye;
    c.F = dnorm(dsub(target, eye));
    c.R = dnorm(dcross(c.F, up));
    c.U = dcross(c.R, c.F);
    c.tanh_ = tan(fov_deg * 0.5 * 3.14159265358979323846 / 180.0);
    c.aspect = (double)w / (double)h;
    c.w = w;
    c.h = h;
    return c;
}

/* The spec's unnormalized direction and its normalization. */
static dv ref_dir(const ref_cam *c, double i, double j)
{
    double sx = (2.0 * (i + 0.5) / c->w - 1.0) * c->tanh_ * c->aspect;
    double sy = (1.0 - 2.0 * (j + 0.5) / c->h) * c->tanh_;
    return dnorm(dadd(c->F, dadd(dmul(c->R, sx), dmul(c->U, sy))));
}

/* Column-major m[col*4+row] times (p, 1), then divided by w. */
static void ref_project(const double m[16], dv p, double ndc[3], double *w_out)
{
    double v[4];
    for (int r = 0; r < 4; r++)
        v[r] = m[r] * p.x + m[4 + r] * p.y + m[8 + r] * p.z + m[12 + r];
    ndc[0] = v[0] / v[3];
    ndc[1] = v[1] / v[3];
    ndc[2] = v[2] / v[3];
    if (w_out)
        *w_out = v[3];
}

static void ref_project_float(const float m[16], const float p[3], float ndc[3])
{
    float v[4];
    for (int r = 0; r < 4; r++)
        v[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
    for (int k = 0; k < 3; k++)
        ndc[k] = v[k] / v[3];
}

static uint32_t rng = 12345u;
static double urand(double lo, double hi)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return lo + (hi - lo) * (double)rng / 4294967296.0;
}

static int vec_finite(sl_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
static int mat_finite(const sl_mat4 *m)
{
    for (int k = 0; k < 16; k++)
        if (!isfinite(m->m[k]))
            return 0;
    return 1;
}

static sl_status make_view(sl_view *v, dv eye, dv target, dv up, double fov, int w, int h, dv origin,
                           double near_plane, double radius, sl_err *err)
{
    memset(v, 0, sizeof *v);
    v->camera = (sl_camera){to_sl(eye), to_sl(target), to_sl(up), fov};
    v->width = w;
    v->height = h;
    v->origin = to_sl(origin);
    v->near_plane = near_plane;
    return sl_view_init(v, radius, err);
}

/* ---- sl_math.h ------------------------------------------------------------ */

static void test_math(void)
{
    sl_vec3 a = sl_v3(1, 2, 3), b = sl_v3(-4, 0.5, 2);
    sl_vec3 s = sl_v3_add(a, b), d = sl_v3_sub(a, b), k = sl_v3_scale(a, -2);
    SL_CHECK(s.x == -3 && s.y == 2.5 && s.z == 5);
    SL_CHECK(d.x == 5 && d.y == 1.5 && d.z == 1);
    SL_CHECK(k.x == -2 && k.y == -4 && k.z == -6);
    SL_CHECK_NEAR(sl_v3_dot(a, b), -4 + 1 + 6, 0.0);
    sl_vec3 c = sl_v3_cross(a, b); /* (2*2-3*0.5, 3*-4-1*2, 1*0.5-2*-4) */
    SL_CHECK(c.x == 2.5 && c.y == -14 && c.z == 8.5);
    sl_vec3 z = sl_v3_cross(sl_v3(1, 0, 0), sl_v3(0, 1, 0));
    SL_CHECK_MSG(z.x == 0 && z.y == 0 && z.z == 1, "x cross y must be +z (right-handed)");
    SL_CHECK_NEAR(sl_v3_length(sl_v3(3, 4, 12)), 13.0, 0.0);
    sl_vec3 n = sl_v3_normalize(sl_v3(0, -5, 0));
    SL_CHECK(n.x == 0 && n.y == -1 && n.z == 0);
    n = sl_v3_normalize(sl_v3(1e-3, 2e-3, -7e-3));
    SL_CHECK_NEAR(sl_v3_length(n), 1.0, 1e-15);
    n = sl_v3_normalize(sl_v3(0, 0, 0));
    SL_CHECK_MSG(n.x == 0 && n.y == 0 && n.z == 0, "normalize(0) must be 0, not NaN");
    SL_CHECK(sl_v3_is_finite(a));
    SL_CHECK(!sl_v3_is_finite(sl_v3(0, NAN, 0)));
    SL_CHECK(!sl_v3_is_finite(sl_v3(0, 0, -INFINITY)));
    SL_CHECK(!sl_v3_is_finite(sl_v3(INFINITY, 0, 0)));

    sl_mat4 id = sl_mat4_identity();
    int ok = 1;
    for (int i = 0; i < 16; i++)
        ok &= id.m[i] == ((i % 5 == 0) ? 1.0 : 0.0);
    SL_CHECK(ok);

    /* Column-major: a translation lives in m[12..14]; scale then translate. */
    sl_mat4 t = sl_mat4_identity(), sc = sl_mat4_identity();
    t.m[12] = 10; t.m[13] = 20; t.m[14] = 30;
    sc.m[0] = 2; sc.m[5] = 3; sc.m[10] = 4;
    sl_vec3 p = sl_mat4_transform_point(sl_mat4_mul(t, sc), sl_v3(1, 1, 1)); /* t * (sc * p) */
    SL_CHECK(p.x == 12 && p.y == 23 && p.z == 34);
    p = sl_mat4_transform_point(sl_mat4_mul(sc, t), sl_v3(1, 1, 1));        /* sc * (t * p) */
    SL_CHECK(p.x == 22 && p.y == 63 && p.z == 124);
    /* Projective divide. */
    sl_mat4 w = sl_mat4_identity();
    w.m[15] = 0; w.m[11] = -1;     /* w' = -z */
    p = sl_mat4_transform_point(w, sl_v3(2, 4, -2));
    SL_CHECK(p.x == 1 && p.y == 2 && p.z == -1);

    /* Product against a reference on random matrices. */
    sl_mat4 A, B;
    for (int i = 0; i < 16; i++) {
        A.m[i] = urand(-3, 3);
        B.m[i] = urand(-3, 3);
    }
    sl_mat4 AB = sl_mat4_mul(A, B);
    double maxerr = 0;
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++) {
            double sum = 0;
            for (int k2 = 0; k2 < 4; k2++)
                sum += A.m[k2 * 4 + row] * B.m[col * 4 + k2];
            maxerr = fmax(maxerr, fabs(sum - AB.m[col * 4 + row]));
        }
    SL_CHECK_NEAR(maxerr, 0.0, 1e-13);
    float f[16];
    sl_mat4_to_float(A, f);
    int same = 1;
    for (int i = 0; i < 16; i++)
        same &= f[i] == (float)A.m[i];
    SL_CHECK(same);
}

/* ---- rays and matrices ---------------------------------------------------- */

static double worst_ndc_seen, worst_float_seen, best_control_seen = INFINITY; /* reported at the end */

/* Checks every sampled pixel of one camera; returns the worst NDC error. */
static double check_camera(dv eye, dv target, dv up, double fov, int w, int h, dv origin, const char *label)
{
    sl_view v;
    sl_err err = {0};
    sl_status st = make_view(&v, eye, target, up, fov, w, h, origin, 0.0, 1.0, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", label, err.message);
    if (st != SL_OK)
        return INFINITY;
    ref_cam c = ref_make(eye, target, up, fov, w, h);
    double near = v.near_plane;
    SL_CHECK_MSG(near > 0 && isfinite(near), "%s: near %g", label, near);

    /* Derived basis equals the spec's. */
    double basis = fmax(dlen(dsub(from_sl(v.forward), c.F)),
                        fmax(dlen(dsub(from_sl(v.right), c.R)), dlen(dsub(from_sl(v.upv), c.U))));
    SL_CHECK_MSG(basis < 1e-12, "%s: basis differs by %g", label, basis);

    /* The composite equals projection * view (own product). */
    double comp = 0;
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++) {
            double sum = 0;
            for (int k = 0; k < 4; k++)
                sum += v.projection.m[k * 4 + row] * v.view_matrix.m[col * 4 + k];
            comp = fmax(comp, fabs(sum - v.view_projection.m[col * 4 + row]));
        }
    SL_CHECK_MSG(comp < 1e-12 * (1 + fabs(v.view_projection.m[12]) + fabs(v.view_projection.m[13])),
                 "%s: view_projection != projection * view_matrix (%g)", label, comp);

    /* Pixels: the four corners, the centre, and some random ones. */
    double px[12][2] = {{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}, {(w - 1) / 2, (h - 1) / 2}};
    for (int k = 5; k < 12; k++) {
        px[k][0] = floor(urand(0, w));
        px[k][1] = floor(urand(0, h));
    }
    const double dists[] = {2.0 * near, 0.37, 1.0, 8.5, 1e3, 1e6};
    double worst = 0, worst_z = 0, worst_dir = 0, worst_dist = 0;
    for (int k = 0; k < 12; k++) {
        double i = px[k][0], j = px[k][1];
        dv dir = ref_dir(&c, i, j);
        double want_x = 2.0 * (i + 0.5) / w - 1.0, want_y = 1.0 - 2.0 * (j + 0.5) / h;
        worst_dir = fmax(worst_dir, dlen(dsub(from_sl(sl_view_ray_dir(&v, i, j)), dir)));
        for (size_t q = 0; q < sizeof dists / sizeof dists[0]; q++) {
            double t = dists[q] / ddot(dir, c.F); /* distance along F is dists[q] */
            /* The point relative to the origin, formed without the huge world coordinates. */
            dv pr = dadd(dsub(eye, origin), dmul(dir, t));
            double ndc[3], wclip;
            ref_project(v.view_projection.m, pr, ndc, &wclip);
            worst = fmax(worst, fmax(fabs(ndc[0] - want_x), fabs(ndc[1] - want_y)));
            /* Reversed infinite Z: depth = near / (distance along F), w = that distance. */
            worst_z = fmax(worst_z, fabs(ndc[2] - near / dists[q]) / (near / dists[q]));
            worst_z = fmax(worst_z, fabs(wclip - dists[q]) / dists[q]);
            double dist = sl_view_depth_to_distance(&v, i, j, ndc[2]);
            double euclid = dlen(dmul(dir, t));
            worst_dist = fmax(worst_dist, fabs(dist - euclid) / euclid);
        }
    }
    worst_ndc_seen = fmax(worst_ndc_seen, worst);
    SL_CHECK_MSG(worst < 1e-7, "%s (%dx%d, fov %g): NDC off the pixel centre by %g", label, w, h, fov, worst);
    SL_CHECK_MSG(worst_z < 1e-9, "%s: depth/w relative error %g", label, worst_z);
    SL_CHECK_MSG(worst_dir < 1e-12, "%s: sl_view_ray_dir differs by %g", label, worst_dir);
    SL_CHECK_MSG(worst_dist < 1e-9, "%s: depth_to_distance relative error %g", label, worst_dist);
    return worst;
}

static dv rand_dv(double lo, double hi) { return d3(urand(lo, hi), urand(lo, hi), urand(lo, hi)); }

static void test_rays(void)
{
    /* Fixed cameras: the canonical one, a sideways one, looking straight down with up = -z. */
    const int sizes[][2] = {{1, 1}, {2, 1}, {1, 3}, {7, 5}, {640, 480}, {33, 1000}, {8192, 1}, {256, 256}};
    const double fovs[] = {1.0, 20.0, 45.0, 90.0, 150.0, 179.0};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        for (size_t f = 0; f < sizeof fovs / sizeof fovs[0]; f++) {
            check_camera(d3(0, 0, 5), d3(0, 0, 0), d3(0, 1, 0), fovs[f], sizes[s][0], sizes[s][1], d3(0, 0, 0), "canonical");
            check_camera(d3(3, -1, 2), d3(-2, 0.5, 7), d3(0.2, 3, -0.1), fovs[f], sizes[s][0], sizes[s][1],
                         d3(1, 2, 3), "sideways");
            check_camera(d3(0, 10, 0), d3(0, 0, 0), d3(0, 0, -1), fovs[f], sizes[s][0], sizes[s][1], d3(0, 0, 0), "down");
        }
    /* Random eyes, targets, ups (any length, not within ~3 degrees of the view direction). */
    for (int n = 0; n < 200; n++) {
        dv eye = rand_dv(-20, 20), target = rand_dv(-20, 20);
        if (dlen(dsub(target, eye)) < 0.5)
            continue;
        dv up = dmul(rand_dv(-1, 1), pow(10.0, urand(-3, 3)));
        if (dlen(dcross(dnorm(dsub(target, eye)), dnorm(up))) < 0.05)
            continue;
        int w = 1 + (int)urand(0, 700), h = 1 + (int)urand(0, 700);
        check_camera(eye, target, up, urand(5, 170), w, h, rand_dv(-5, 5), "random");
    }

    /* Concrete spot checks of the conventions, without the reference. */
    sl_view v;
    sl_err err = {0};
    SL_CHECK(make_view(&v, d3(0, 0, 5), d3(0, 0, 0), d3(0, 1, 0), 90.0, 3, 3, d3(0, 0, 0), 0.5, 1, &err) == SL_OK);
    sl_vec3 r = sl_view_ray_dir(&v, 1, 1);
    SL_CHECK(fabs(r.x) < 1e-15 && fabs(r.y) < 1e-15 && fabs(r.z + 1) < 1e-15); /* centre pixel looks along -z */
    r = sl_view_ray_dir(&v, 2, 1);                                             /* right: +x (R = F x up) */
    SL_CHECK_MSG(r.x > 0.5 && fabs(r.y) < 1e-15, "right pixel dir (%g %g %g)", r.x, r.y, r.z);
    r = sl_view_ray_dir(&v, 1, 0);                                             /* row 0 is the top: +y */
    SL_CHECK_MSG(r.y > 0.5 && fabs(r.x) < 1e-15, "top pixel dir (%g %g %g)", r.x, r.y, r.z);
    /* fov 90, 3x3: the right pixel centre is at sx = 2/3, so its direction is normalize(2/3, 0, -1). */
    r = sl_view_ray_dir(&v, 2, 1);
    SL_CHECK_NEAR(r.x, (2.0 / 3.0) / sqrt(1 + 4.0 / 9.0), 1e-15);
    /* Depth: the near plane maps to 1, farther is smaller (GL_GREATER), 0 is reached only at infinity. */
    SL_CHECK_NEAR(v.near_plane, 0.5, 0.0);
    sl_vec3 q = sl_mat4_transform_point(v.view_projection, sl_v3(0, 0, 4.5));
    SL_CHECK_NEAR(q.z, 1.0, 1e-15);
    q = sl_mat4_transform_point(v.view_projection, sl_v3(0, 0, 0));
    SL_CHECK_NEAR(q.z, 0.1, 1e-15);
    q = sl_mat4_transform_point(v.view_projection, sl_v3(0, 0, -1e30));
    SL_CHECK(q.z > 0.0 && q.z < 1e-30);
    /* The view matrix: the eye at the eye-space origin, the target on -z. */
    sl_vec3 e = sl_mat4_transform_point(v.view_matrix, sl_v3(0, 0, 5));
    SL_CHECK(fabs(e.x) + fabs(e.y) + fabs(e.z) < 1e-15);
    e = sl_mat4_transform_point(v.view_matrix, sl_v3(0, 0, 0));
    SL_CHECK_NEAR(e.z, -5.0, 1e-15);
    /* depth_to_distance: nothing hit, negative or NaN depth -> 0; on axis, distance = near / depth. */
    SL_CHECK(sl_view_depth_to_distance(&v, 1, 1, 0.0) == 0.0);
    SL_CHECK(sl_view_depth_to_distance(&v, 1, 1, -0.5) == 0.0);
    SL_CHECK(sl_view_depth_to_distance(&v, 1, 1, NAN) == 0.0);
    SL_CHECK_NEAR(sl_view_depth_to_distance(&v, 1, 1, 0.1), 5.0, 1e-14);
    SL_CHECK_NEAR(sl_view_depth_to_distance(&v, 2, 1, 0.1), 5.0 * sqrt(1 + 4.0 / 9.0), 1e-14);
    SL_CHECK_NEAR(sl_view_depth_to_distance(&v, 2, 0, 0.1), 5.0 * sqrt(1 + 8.0 / 9.0), 1e-14);

    /* The default near plane follows the scene radius; a given one is kept. */
    SL_CHECK(make_view(&v, d3(0, 0, 5), d3(0, 0, 0), d3(0, 1, 0), 45, 4, 4, d3(0, 0, 0), 0.0, 200.0, &err) == SL_OK);
    SL_CHECK(v.near_plane > 0.0 && v.near_plane < 200.0);
    double near200 = v.near_plane;
    SL_CHECK(make_view(&v, d3(0, 0, 5), d3(0, 0, 0), d3(0, 1, 0), 45, 4, 4, d3(0, 0, 0), 0.0, 2.0, &err) == SL_OK);
    SL_CHECK_NEAR(v.near_plane * 100.0, near200, 1e-12 * near200);
    SL_CHECK(make_view(&v, d3(0, 0, 5), d3(0, 0, 0), d3(0, 1, 0), 45, 4, 4, d3(0, 0, 0), NAN, NAN, &err) == SL_OK);
    SL_CHECK(v.near_plane > 0.0 && isfinite(v.near_plane) && mat_finite(&v.view_projection));
}

/* Far from the world origin: the matrices are relative to the dataset origin,
 * so float matrices applied to float origin-relative positions stay accurate. */
static void test_big_offset(void)
{
    const double offsets[] = {1e6, -3.5e6, 1e8};
    for (size_t o = 0; o < sizeof offsets / sizeof offsets[0]; o++) {
        dv origin = d3(offsets[o], -0.5 * offsets[o], 0.25 * offsets[o]);
        dv eye = dadd(origin, d3(2.5, 1.5, 4.0)), target = dadd(origin, d3(0.1, -0.2, 0.3));
        dv up = d3(0, 1, 0);
        const int sizes[][2] = {{640, 480}, {1, 1}, {100, 300}};
        for (int s = 0; s < 3; s++) {
            int w = sizes[s][0], h = sizes[s][1];
            check_camera(eye, target, up, 45.0, w, h, origin, "offset");
            sl_view v;
            sl_err err = {0};
            if (make_view(&v, eye, target, up, 45.0, w, h, origin, 0.0, 2.0, &err) != SL_OK) {
                SL_CHECK_MSG(0, "offset view: %s", err.message);
                continue;
            }
            ref_cam c = ref_make(eye, target, up, 45.0, w, h);
            /* The same matrices in absolute world coordinates (what relative matrices avoid). */
            sl_mat4 to_rel = sl_mat4_identity();
            to_rel.m[12] = -origin.x; to_rel.m[13] = -origin.y; to_rel.m[14] = -origin.z;
            float rel[16], abs_[16];
            sl_mat4_to_float(v.view_projection, rel);
            sl_mat4_to_float(sl_mat4_mul(v.view_projection, to_rel), abs_);
            double worst_rel = 0, worst_abs = 0;
            for (int k = 0; k < 40; k++) {
                double i = floor(urand(0, w)), j = floor(urand(0, h));
                dv dir = ref_dir(&c, i, j);
                double t = urand(1.0, 12.0);            /* points in and around the data */
                dv pr = dadd(dsub(eye, origin), dmul(dir, t));
                dv p = dadd(eye, dmul(dir, t));
                float prf[3] = {(float)pr.x, (float)pr.y, (float)pr.z};
                float paf[3] = {(float)p.x, (float)p.y, (float)p.z};
                float ndc[3];
                double want_x = 2.0 * (i + 0.5) / w - 1.0, want_y = 1.0 - 2.0 * (j + 0.5) / h;
                ref_project_float(rel, prf, ndc);
                worst_rel = fmax(worst_rel, fmax(fabs(ndc[0] - want_x), fabs(ndc[1] - want_y)));
                ref_project_float(abs_, paf, ndc);
                double e = fmax(fabs(ndc[0] - want_x), fabs(ndc[1] - want_y));
                worst_abs = fmax(worst_abs, isfinite(e) ? e : 1e9);
            }
            worst_float_seen = fmax(worst_float_seen, worst_rel);
            best_control_seen = fmin(best_control_seen, worst_abs);
            SL_CHECK_MSG(worst_rel < 2e-5, "offset %g, %dx%d: float NDC error %g", offsets[o], w, h, worst_rel);
            SL_CHECK_MSG(worst_abs > 1e-3, "control: absolute float matrices at offset %g should lose precision (%g)",
                         offsets[o], worst_abs);
        }
    }
}

/* ---- orbit ---------------------------------------------------------------- */

static void orbit_ref(double az, double el, double d, dv lo, dv hi, dv *eye)
{
    dv centre = dmul(dadd(lo, hi), 0.5);
    double r = 0.5 * dlen(dsub(hi, lo));
    double a = az * 3.14159265358979323846 / 180.0, e = el * 3.14159265358979323846 / 180.0;
    *eye = dadd(centre, dmul(d3(cos(e) * sin(a), sin(e), cos(e) * cos(a)), d * r));
}

static void test_orbit(void)
{
    sl_err err = {0};
    sl_camera cam;
    dv lo = d3(-1, 2, 3), hi = d3(3, 4, 11), centre = d3(1, 3, 7);
    double radius = 0.5 * sqrt(16.0 + 4.0 + 64.0);

    /* az 0, el 0: on +z of the centre; az 90: +x; az 180: -z; az -90: -x. */
    struct { double az, el; dv dir; } axes[] = {
        {0, 0, {0, 0, 1}}, {90, 0, {1, 0, 0}}, {180, 0, {0, 0, -1}}, {-90, 0, {-1, 0, 0}}, {270, 0, {-1, 0, 0}},
        {0, 45, {0, sqrt(0.5), sqrt(0.5)}}, {90, -30, {sqrt(0.75), -0.5, 0}},
    };
    for (size_t k = 0; k < sizeof axes / sizeof axes[0]; k++) {
        sl_orbit o = {axes[k].az, axes[k].el, 2.0, 45.0};
        sl_status st = sl_camera_from_orbit(&o, to_sl(lo), to_sl(hi), &cam, &err);
        SL_CHECK_MSG(st == SL_OK, "orbit %g/%g: %s", o.azimuth_deg, o.elevation_deg, err.message);
        dv want = dadd(centre, dmul(axes[k].dir, 2.0 * radius));
        SL_CHECK_MSG(dlen(dsub(from_sl(cam.eye), want)) < 1e-12, "orbit %g/%g: eye (%g %g %g), want (%g %g %g)",
                     o.azimuth_deg, o.elevation_deg, cam.eye.x, cam.eye.y, cam.eye.z, want.x, want.y, want.z);
        SL_CHECK(dlen(dsub(from_sl(cam.target), centre)) < 1e-15);
        SL_CHECK(cam.up.x == 0 && cam.up.y == 1 && cam.up.z == 0);
        SL_CHECK(cam.fov_y_deg == 45.0);
    }

    /* General angles against the reference; distance in bounding-sphere radii. */
    for (int n = 0; n < 100; n++) {
        double az = urand(-720, 720), el = urand(-89, 89), d = pow(10.0, urand(-1, 2));
        sl_orbit o = {az, el, d, urand(10, 120)};
        dv want;
        orbit_ref(az, el, d, lo, hi, &want);
        SL_CHECK(sl_camera_from_orbit(&o, to_sl(lo), to_sl(hi), &cam, &err) == SL_OK);
        SL_CHECK_MSG(dlen(dsub(from_sl(cam.eye), want)) < 1e-12 * (1 + d * radius), "orbit %g/%g/%g", az, el, d);
        SL_CHECK_NEAR(dlen(dsub(from_sl(cam.eye), centre)), d * radius, 1e-12 * d * radius);
        SL_CHECK(cam.fov_y_deg == o.fov_y_deg);
    }

    /* At az 0, el 0 the image's right is +x and its top +y. */
    sl_orbit o = {0, 0, 3.0, 60.0};
    sl_view v;
    memset(&v, 0, sizeof v);
    SL_CHECK(sl_camera_from_orbit(&o, to_sl(lo), to_sl(hi), &v.camera, &err) == SL_OK);
    v.width = 5;
    v.height = 5;
    SL_CHECK(sl_view_init(&v, radius, &err) == SL_OK);
    SL_CHECK(fabs(v.right.x - 1) < 1e-15 && fabs(v.upv.y - 1) < 1e-15 && fabs(v.forward.z + 1) < 1e-15);

    /* Elevation beyond +-89.9 (the poles, where up = +y is parallel to the
     * view direction, and past them) is an error naming the field and the
     * range, not a silent clamp. */
    const double beyond[] = {90.0, -90.0, 89.90001, -89.90001, 90.0 + 1e-9, 135.0, -400.0};
    for (size_t k = 0; k < sizeof beyond / sizeof beyond[0]; k++) {
        sl_orbit p = {37.0, beyond[k], 2.5, 45.0};
        memset(&err, 0, sizeof err);
        sl_status st = sl_camera_from_orbit(&p, to_sl(lo), to_sl(hi), &cam, &err);
        SL_CHECK_MSG(st == SL_ERR_INVALID, "elevation %.9g accepted", beyond[k]);
        SL_CHECK_MSG(strstr(err.message, "camera.orbit.elevation must be in [-89.9, 89.9] degrees"), "%s",
                     err.message);
    }
    /* At the limits (and near them): no NaN; the eye stays at the orbit
     * distance, almost straight above (below) the centre, and a view can be built. */
    const double poles[] = {SL_ORBIT_MAX_ELEVATION, -SL_ORBIT_MAX_ELEVATION, 89.89999, -89.5};
    for (size_t k = 0; k < sizeof poles / sizeof poles[0]; k++) {
        sl_orbit p = {37.0, poles[k], 2.5, 45.0};
        sl_status st = sl_camera_from_orbit(&p, to_sl(lo), to_sl(hi), &v.camera, &err);
        SL_CHECK_MSG(st == SL_OK, "elevation %g: %s", poles[k], err.message);
        if (st != SL_OK)
            continue;
        SL_CHECK(vec_finite(v.camera.eye));
        SL_CHECK_NEAR(dlen(dsub(from_sl(v.camera.eye), centre)), 2.5 * radius, 1e-9);
        double sgn = poles[k] > 0 ? 1.0 : -1.0;
        SL_CHECK_MSG(sgn * (v.camera.eye.y - centre.y) > 0.9999 * 2.5 * radius, "elevation %g: eye.y %g",
                     poles[k], v.camera.eye.y);
        v.width = 64;
        v.height = 48;
        v.near_plane = 0;
        st = sl_view_init(&v, radius, &err);
        SL_CHECK_MSG(st == SL_OK, "elevation %g: view: %s", poles[k], err.message);
        if (st == SL_OK) {
            SL_CHECK(mat_finite(&v.view_projection) && vec_finite(v.right) && vec_finite(v.upv));
            SL_CHECK_NEAR(sl_v3_length(v.right), 1.0, 1e-9);
            sl_vec3 dir = sl_view_ray_dir(&v, 10, 40);
            SL_CHECK(vec_finite(dir) && fabs(sl_v3_length(dir) - 1) < 1e-12);
        }
    }

    /* Degenerate bounds (a single point): radius falls back to 1, as sl_dataset_radius does. */
    o = (sl_orbit){0, 0, 2.0, 45.0};
    SL_CHECK(sl_camera_from_orbit(&o, sl_v3(1, 2, 3), sl_v3(1, 2, 3), &cam, &err) == SL_OK);
    SL_CHECK(dlen(dsub(from_sl(cam.eye), d3(1, 2, 5))) < 1e-15);

    /* Bad orbits: named errors, out untouched where it matters (no NaN escapes). */
    const sl_orbit bad[] = {
        {NAN, 0, 2, 45}, {0, NAN, 2, 45}, {0, 0, NAN, 45}, {0, 0, 2, NAN}, {INFINITY, 0, 2, 45},
        {0, -INFINITY, 2, 45}, {0, 0, INFINITY, 45}, {0, 0, 0, 45}, {0, 0, -1, 45}, {0, 0, 2, 0},
        {0, 0, 2, 180}, {0, 0, 2, -10}, {0, 0, 1e308, 45},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        sl_err e = {0};
        sl_status st = sl_camera_from_orbit(&bad[k], to_sl(lo), to_sl(hi), &cam, &e);
        SL_CHECK_MSG(st == SL_ERR_INVALID, "bad orbit %zu: status %d", k, (int)st);
        SL_CHECK_MSG(strstr(e.message, "camera") != NULL, "bad orbit %zu: message '%s'", k, e.message);
    }
    sl_err e = {0};
    o = (sl_orbit){0, 0, -1, 45};
    sl_camera_from_orbit(&o, to_sl(lo), to_sl(hi), &cam, &e);
    SL_CHECK_MSG(strstr(e.message, "distance") != NULL, "%s", e.message);
    o = (sl_orbit){0, 0, 2, 200};
    sl_camera_from_orbit(&o, to_sl(lo), to_sl(hi), &cam, &e);
    SL_CHECK_MSG(strstr(e.message, "fov") != NULL, "%s", e.message);
}

/* ---- validation ----------------------------------------------------------- */

static int rejects(sl_camera c, const char *word)
{
    sl_err err = {0};
    sl_status st = sl_camera_validate(&c, &err);
    if (st != SL_ERR_INVALID) {
        fprintf(stderr, "  camera (%g %g %g)->(%g %g %g) up (%g %g %g) fov %g accepted\n", c.eye.x, c.eye.y, c.eye.z,
                c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg);
        return 0;
    }
    if (!strstr(err.message, word)) {
        fprintf(stderr, "  message '%s' does not name '%s'\n", err.message, word);
        return 0;
    }
    /* sl_view_init refuses it too and derives nothing from it. */
    sl_view v;
    memset(&v, 0, sizeof v);
    v.camera = c;
    v.width = v.height = 8;
    return sl_view_init(&v, 1.0, &err) == SL_ERR_INVALID;
}

static void test_validation(void)
{
    const sl_camera good = {sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1, 0), 45};
    sl_err err = {0};
    SL_CHECK(sl_camera_validate(&good, &err) == SL_OK);

    sl_camera c = good;
    c.target = c.eye;
    SL_CHECK(rejects(c, "eye"));
    c = good;
    c.eye = c.target = sl_v3(1e6, -1e6, 3);
    SL_CHECK(rejects(c, "target"));
    c = good;
    c.up = sl_v3(0, 0, 1);               /* along -F */
    SL_CHECK(rejects(c, "up"));
    c.up = sl_v3(0, 0, -7);              /* along F */
    SL_CHECK(rejects(c, "up"));
    c.up = sl_v3(0, 0, 0);
    SL_CHECK(rejects(c, "up"));
    c = good;
    c.eye = sl_v3(1, 2, 3);
    c.target = sl_v3(3, 6, 9);
    c.up = sl_v3(-0.5, -1, -1.5);        /* parallel, not axis-aligned */
    SL_CHECK(rejects(c, "up"));

    const double bad_fov[] = {0.0, -1.0, 180.0, 180.5, 1e300, NAN, INFINITY, -INFINITY};
    for (size_t k = 0; k < sizeof bad_fov / sizeof bad_fov[0]; k++) {
        c = good;
        c.fov_y_deg = bad_fov[k];
        SL_CHECK_MSG(rejects(c, "fov"), "fov %g", bad_fov[k]);
    }
    const double nonfinite[] = {NAN, INFINITY, -INFINITY};
    for (int f = 0; f < 3; f++)
        for (int comp = 0; comp < 3; comp++) {
            sl_camera cc[3] = {good, good, good};
            double *e = &cc[0].eye.x, *t = &cc[1].target.x, *u = &cc[2].up.x;
            e[comp] = nonfinite[f];
            t[comp] = nonfinite[f];
            u[comp] = nonfinite[f];
            SL_CHECK_MSG(rejects(cc[0], "eye"), "eye[%d] = %g", comp, nonfinite[f]);
            SL_CHECK_MSG(rejects(cc[1], "target"), "target[%d] = %g", comp, nonfinite[f]);
            SL_CHECK_MSG(rejects(cc[2], "up"), "up[%d] = %g", comp, nonfinite[f]);
        }

    /* Just inside the limits: accepted, and the view is finite and orthonormal. */
    const sl_camera edge[] = {
        {sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1, 0), 1e-3},
        {sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1, 0), 179.9},
        {sl_v3(0, 0, 1e-6), sl_v3(0, 0, 0), sl_v3(0, 1, 0), 45},      /* eye very close to the target */
        {sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1e-6, 1), 45},      /* up 1e-6 rad off the view axis */
        {sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1e-3, 0), 45},      /* short up */
        {sl_v3(0, 0, 5), sl_v3(0, 0, 0), sl_v3(0, 1e3, 1e3), 45},     /* long up */
        {sl_v3(1e7, 1e7, 1e7 + 5), sl_v3(1e7, 1e7, 1e7), sl_v3(0, 1, 0), 45},
    };
    for (size_t k = 0; k < sizeof edge / sizeof edge[0]; k++) {
        sl_view v;
        memset(&v, 0, sizeof v);
        v.camera = edge[k];
        v.width = 31;
        v.height = 17;
        sl_status st = sl_view_init(&v, 1.0, &err);
        SL_CHECK_MSG(st == SL_OK, "edge camera %zu: %s", k, err.message);
        if (st != SL_OK)
            continue;
        SL_CHECK(mat_finite(&v.view_projection));
        double ortho = fabs(sl_v3_dot(v.right, v.upv)) + fabs(sl_v3_dot(v.right, v.forward)) +
                       fabs(sl_v3_dot(v.upv, v.forward)) + fabs(sl_v3_length(v.right) - 1) +
                       fabs(sl_v3_length(v.upv) - 1) + fabs(sl_v3_length(v.forward) - 1);
        SL_CHECK_MSG(ortho < 1e-9, "edge camera %zu: basis not orthonormal (%g)", k, ortho);
        /* The right vector lies in the plane spanned by F and up's component off F: R.up = 0. */
        SL_CHECK_MSG(fabs(sl_v3_dot(v.right, sl_v3_normalize(edge[k].up))) < 1e-9, "edge camera %zu", k);
    }

    /* View sizes. */
    sl_view v;
    const int bad_sizes[][2] = {{0, 1}, {1, 0}, {-5, 10}, {10, -1}};
    for (int k = 0; k < 4; k++) {
        memset(&v, 0, sizeof v);
        v.camera = good;
        v.width = bad_sizes[k][0];
        v.height = bad_sizes[k][1];
        sl_err e = {0};
        SL_CHECK(sl_view_init(&v, 1.0, &e) == SL_ERR_INVALID);
        SL_CHECK_MSG(strstr(e.message, "size") != NULL, "%s", e.message);
    }
    /* A non-finite origin falls back to 0 instead of poisoning the matrices. */
    memset(&v, 0, sizeof v);
    v.camera = good;
    v.width = v.height = 4;
    v.origin = sl_v3(NAN, 0, 0);
    SL_CHECK(sl_view_init(&v, 1.0, &err) == SL_OK);
    SL_CHECK(mat_finite(&v.view_projection) && vec_finite(v.origin));
}

/* The defaults every caller takes (scene, session, the page through the
 * welcome) and the resolution of either form of sl_camera_spec. */
static void test_spec(void)
{
    SL_CHECK(sl_orbit_default.azimuth_deg == 30.0 && sl_orbit_default.elevation_deg == 20.0 &&
             sl_orbit_default.distance == 2.5 && sl_orbit_default.fov_y_deg == 45.0);
    SL_CHECK(SL_ORBIT_MAX_ELEVATION == 89.9);
    sl_camera_spec d = sl_camera_spec_default();
    SL_CHECK(d.is_orbit == 1 && memcmp(&d.orbit, &sl_orbit_default, sizeof d.orbit) == 0);
    sl_vec3 lo = sl_v3(-1, 0, 2), hi = sl_v3(3, 2, 6);
    sl_camera a, b;
    sl_err err = {0};
    SL_CHECK(sl_camera_spec_resolve(&d, lo, hi, &a, &err) == SL_OK);
    SL_CHECK(sl_camera_from_orbit(&sl_orbit_default, lo, hi, &b, &err) == SL_OK);
    SL_CHECK(memcmp(&a, &b, sizeof a) == 0);
    sl_camera_spec look = {.is_orbit = 0,
                           .look_at = {.eye = sl_v3(0, 0, 5), .target = sl_v3(0, 0, 0), .up = sl_v3(0, 1, 0),
                                       .fov_y_deg = 40.0}};
    SL_CHECK(sl_camera_spec_resolve(&look, lo, hi, &a, &err) == SL_OK);
    SL_CHECK(memcmp(&a, &look.look_at, sizeof a) == 0);   /* bounds do not move an eye/target camera */
    look.look_at.up = sl_v3(0, 0, 1);
    SL_CHECK(sl_camera_spec_resolve(&look, lo, hi, &a, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "camera.up") != NULL, "%s", err.message);
    d.orbit.elevation_deg = 90.0;
    SL_CHECK(sl_camera_spec_resolve(&d, lo, hi, &a, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "camera.orbit.elevation") != NULL, "%s", err.message);
}

int main(void)
{
    test_math();
    test_rays();
    test_big_offset();
    test_orbit();
    test_validation();
    test_spec();
    printf("worst NDC error of a pixel-centre ray: %.3g (double), %.3g (float, origin-relative);"
           " absolute float matrices: >= %.3g\n", worst_ndc_seen, worst_float_seen, best_control_seen);
    SL_TEST_END();
}
