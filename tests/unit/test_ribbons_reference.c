/* test_ribbons_reference.c — the ribbons CPU references (tests/support/ribbons_reference.h) against closed forms.
 *
 * Tangent points: the circle (w = 1) at beta +- acos(1 / rho); the plan's
 * worked example (w = 1, c = (2, 0, 1): (1/2, +-sqrt(3)/2)); ellipses through
 * the affine map (x / w, y) that takes them to the unit circle; cameras at
 * infinity (c_z = 0: the points where the tangent is parallel to c); inside,
 * on and just outside the ellipse; homogeneous scaling. Lambda: 0 mid-chord,
 * 1 at the tangent points, linear along the chord. Rays: axis-aligned
 * ellipses with known distances and cosines, oblique, caps, grazing rays
 * (touching: cos_in 0; 1e-9 outside: miss), origin inside, and a rotated
 * frame against the same ray in the axis-aligned one. The N-gon bound: tight
 * (ratio 1) for a head-on ray through an edge midpoint, and never exceeded by
 * an explicit polygon intersection over random rays. Twist: stripe centres
 * of a helix with constant helicity, the width correction against
 * w_r sqrt(1 + slope^2) and its 45-degree case. Single thread.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "ribbons_reference.h"
#include "sl_test.h"

#define PI 3.141592653589793

/* Angular distance on the circle. */
static double ang_dist(double a, double b)
{
    double d = fmod(fabs(a - b), 2.0 * PI);
    return fmin(d, 2.0 * PI - d);
}

/* Max error of the reference pair against the expected pair, either pairing. */
static double pair_error(const double got[2], double e0, double e1)
{
    double straight = fmax(ang_dist(got[0], e0), ang_dist(got[1], e1));
    double crossed = fmax(ang_dist(got[0], e1), ang_dist(got[1], e0));
    return fmin(straight, crossed);
}

/* Deterministic uniform in [0, 1) (LCG, 53 bits). */
static double uniform(unsigned long long *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static void test_tangent_circle(void)
{
    double th[2], worst = 0.0;
    /* The worked example of plan 1.4. */
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){2.0, 0.0, 1.0}, 1.0, th) == 2);
    SL_CHECK_NEAR(cos(th[0]), 0.5, 1e-14);
    SL_CHECK_NEAR(cos(th[1]), 0.5, 1e-14);
    SL_CHECK_NEAR(sin(th[0]), sqrt(3.0) / 2.0, 1e-14);
    SL_CHECK_NEAR(sin(th[1]), -sqrt(3.0) / 2.0, 1e-14);
    /* Circle: beta +- acos(1 / rho), for a spread of distances and directions. */
    static const double rhos[] = {1.001, 1.01, 1.5, 2.0, 10.0, 1e3, 1e6};
    for (size_t i = 0; i < sizeof rhos / sizeof rhos[0]; i++)
        for (int k = 0; k < 16; k++) {
            double beta = 2.0 * PI * k / 16.0 + 0.1, rho = rhos[i];
            double c[3] = {rho * cos(beta), rho * sin(beta), 1.0};
            int n = ribbons_ref_tangent_points(c, 1.0, th);
            SL_CHECK_MSG(n == 2, "circle rho %g beta %g: %d points", rho, beta, n);
            if (n == 2)
                worst = fmax(worst, pair_error(th, beta + acos(1.0 / rho), beta - acos(1.0 / rho)));
        }
    printf("circle tangent points: worst angular error %.3g rad\n", worst);
    SL_CHECK_MSG(worst < 1e-13, "circle tangent points off by %.3g rad", worst);
}

/* Ellipse (w cos t, sin t): the map (x, y) -> (x / w, y) takes it to the unit
 * circle with the same parameter t and keeps tangency, so the camera
 * (cx / w, cy) at distance rho' and angle beta' gives t = beta' +- acos(1 / rho'). */
static void test_tangent_ellipse(void)
{
    static const double ws[] = {1.0, 0.5, 0.25, 0.15, 0.05};
    unsigned long long s = 7;
    double worst = 0.0, worst_g = 0.0;
    int cameras = 0;
    for (size_t i = 0; i < sizeof ws / sizeof ws[0]; i++) {
        double w = ws[i];
        for (int k = 0; k < 200; k++) {
            double rho = exp(log(1.001) + uniform(&s) * (log(1e4) - log(1.001)));
            double beta = 2.0 * PI * uniform(&s);
            double cz = k % 3 == 0 ? 1.0 : (k % 3 == 1 ? 2.5 : -0.5); /* homogeneous scale, either sign */
            double c[3] = {w * rho * cos(beta) * cz, rho * sin(beta) * cz, cz};
            double th[2];
            int n = ribbons_ref_tangent_points(c, w, th);
            SL_CHECK_MSG(n == 2, "w %g rho %g: %d points", w, rho, n);
            if (n != 2)
                continue;
            worst = fmax(worst, pair_error(th, beta + acos(1.0 / rho), beta - acos(1.0 / rho)));
            /* Residual of the definition: the tangent at e(t) passes through the camera. */
            for (int j = 0; j < 2; j++) {
                double ex = w * cos(th[j]), ey = sin(th[j]), tx = -w * sin(th[j]), ty = cos(th[j]);
                double cx = c[0] / c[2] - ex, cy = c[1] / c[2] - ey;
                worst_g = fmax(worst_g, fabs(cx * ty - cy * tx) / (hypot(cx, cy) * hypot(tx, ty)));
            }
            cameras++;
        }
    }
    /* Near the ellipse the roots are ill-conditioned in rho (d t / d rho ~
     * 1 / sqrt(rho^2 - 1)), so the closed form itself carries ~1e-13 there. */
    printf("ellipse tangent points over %d cameras: worst %.3g rad, worst tangency residual %.3g\n", cameras, worst,
           worst_g);
    SL_CHECK_MSG(worst < 1e-11, "ellipse tangent points off by %.3g rad", worst);
    SL_CHECK_MSG(worst_g < 1e-12, "tangency residual %.3g", worst_g);
}

static void test_tangent_special(void)
{
    double th[2];
    /* Inside, at the centre, on the ellipse: none. */
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){0.0, 0.0, 1.0}, 0.25, th) == 0);
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){0.1, 0.9, 1.0}, 0.25, th) == 0);
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){0.25, 0.0, 1.0}, 0.25, th) == 0);
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){0.0, -1.0, 1.0}, 0.25, th) == 0);
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){0.0, 0.0, 0.0}, 1.0, th) == 0);
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){2.0, 0.0, 1.0}, 0.0, th) == 0);
    /* Just outside: two points close to the nearest point, at +-acos(1 / rho). */
    double rho = 1.0 + 1e-6;
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){0.0, rho, 1.0}, 0.5, th) == 2);
    SL_CHECK_NEAR(pair_error(th, PI / 2 + acos(1.0 / rho), PI / 2 - acos(1.0 / rho)), 0.0, 1e-9);
    /* On each axis of the ellipse (w = 0.25), 3 radii out. */
    double w = 0.25;
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){3.0 * w, 0.0, 1.0}, w, th) == 2);
    SL_CHECK_NEAR(pair_error(th, acos(1.0 / 3.0), -acos(1.0 / 3.0)), 0.0, 1e-13);
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){0.0, -3.0, 1.0}, w, th) == 2);
    SL_CHECK_NEAR(pair_error(th, -PI / 2 + acos(1.0 / 3.0), -PI / 2 - acos(1.0 / 3.0)), 0.0, 1e-13);
    /* Camera at infinity (c_z = 0, the mu = 0 branch of the construction):
     * tangent parallel to (dx, dy): -dx cos t - w dy sin t = 0. Circle:
     * beta +- pi/2; ellipse: t = atan2(-dx, w dy) and t + pi. */
    SL_CHECK(ribbons_ref_tangent_points((const double[3]){1.0, 0.0, 0.0}, 1.0, th) == 2);
    SL_CHECK_NEAR(pair_error(th, PI / 2, -PI / 2), 0.0, 1e-14);
    double worst = 0.0;
    for (int k = 0; k < 32; k++) {
        double beta = 2.0 * PI * k / 32.0 + 0.05, dx = cos(beta), dy = sin(beta);
        for (int scale = -1; scale <= 3; scale += 4) { /* -d and 3 d: neither sign nor length matters */
            double c[3] = {scale * dx, scale * dy, 0.0};
            if (ribbons_ref_tangent_points(c, w, th) != 2) {
                SL_CHECK_MSG(0, "camera at infinity beta %g: no points", beta);
                continue;
            }
            double t0 = atan2(-dx, w * dy);
            worst = fmax(worst, pair_error(th, t0, t0 + PI));
        }
    }
    printf("camera at infinity: worst angular error %.3g rad\n", worst);
    SL_CHECK_MSG(worst < 1e-13, "camera at infinity: off by %.3g rad", worst);
}

static void test_lambda(void)
{
    double lam;
    const double c[3] = {2.0, 0.0, 1.0};
    /* Worked example: p = (1, 0) meets the chord x = 1/2 at (1/2, 0), mid-chord. */
    SL_CHECK(ribbons_ref_lambda((const double[2]){1.0, 0.0}, c, 1.0, &lam) == 1);
    SL_CHECK_NEAR(lam, 0.0, 1e-14);
    SL_CHECK(ribbons_ref_lambda((const double[2]){-1.0, 0.0}, c, 1.0, &lam) == 1);
    SL_CHECK_NEAR(lam, 0.0, 1e-14);
    /* At a tangent point: 1. */
    SL_CHECK(ribbons_ref_lambda((const double[2]){0.5, sqrt(3.0) / 2.0}, c, 1.0, &lam) == 1);
    SL_CHECK_NEAR(lam, 1.0, 1e-12);
    /* Along the chord (x = 1/2, y = s sqrt(3)/2) lambda = |s|; points on the
     * same line through the camera share it: p = c + 2 (p' - c) has x = -1. */
    for (int k = -4; k <= 4; k++) {
        double sfrac = k / 4.0, y = sfrac * sqrt(3.0) / 2.0;
        SL_CHECK(ribbons_ref_lambda((const double[2]){0.5, y}, c, 1.0, &lam) == 1);
        SL_CHECK_NEAR(lam, fabs(sfrac), 1e-12);
        double far[2] = {2.0 + 2.0 * (0.5 - 2.0), 2.0 * y};
        SL_CHECK(ribbons_ref_lambda(far, c, 1.0, &lam) == 1);
        SL_CHECK_NEAR(lam, fabs(sfrac), 1e-12);
    }
    /* Camera at infinity along x on an ellipse: the chord is the diameter on
     * the y axis, lambda = |y| for every p. */
    SL_CHECK(ribbons_ref_lambda((const double[2]){0.1, 0.6}, (const double[3]){1.0, 0.0, 0.0}, 0.25, &lam) == 1);
    SL_CHECK_NEAR(lam, 0.6, 1e-12);
    /* Camera inside: no silhouette, lambda 0. */
    lam = 5.0;
    SL_CHECK(ribbons_ref_lambda((const double[2]){0.1, 0.2}, (const double[3]){0.0, 0.5, 1.0}, 1.0, &lam) == 0);
    SL_CHECK(lam == 0.0);
}

static ribbons_ref_segment axis_segment(double r, double w, double half_len)
{
    ribbons_ref_segment s = {
        .x0 = {0, 0, 0}, .n = {1, 0, 0}, .b = {0, 1, 0}, .t = {0, 0, 1}, .r = r, .w = w, .half_len = half_len};
    return s;
}

static void test_ray_axis_aligned(void)
{
    /* Semi-axes 1 along x (n) and 2 along y (b), z in [-1, 1]. */
    ribbons_ref_segment s = axis_segment(2.0, 0.5, 1.0);
    ribbons_ref_hit h;
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 0, 0}, (const double[3]){-1, 0, 0}, &s, &h) == 1);
    SL_CHECK_NEAR(h.distance, 4.0, 1e-14);
    SL_CHECK_NEAR(h.cos_in, 1.0, 1e-14);
    SL_CHECK_NEAR(h.cos_world, 1.0, 1e-14);
    SL_CHECK(h.part == RIBBONS_REF_MANTLE && !h.inside);
    /* Not normalized direction: distances stay world units. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){0, 5, 0}, (const double[3]){0, -7, 0}, &s, &h) == 1);
    SL_CHECK_NEAR(h.distance, 3.0, 1e-14);
    /* Off-centre along -x at height y0: x = sqrt(1 - y0^2 / 4); circle-space
     * cosine x, world normal (x, y0 / 4) normalised. */
    for (int k = 0; k < 8; k++) {
        double y0 = 0.25 * k, x = sqrt(1.0 - y0 * y0 / 4.0);
        SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, y0, 0.3}, (const double[3]){-1, 0, 0}, &s, &h) == 1);
        SL_CHECK_NEAR(h.distance, 5.0 - x, 1e-14);
        SL_CHECK_NEAR(h.cos_in, x, 1e-14);
        SL_CHECK_NEAR(h.cos_world, x / hypot(x, y0 / 4.0), 1e-14);
    }
    /* Oblique in z: from (5, 0, 1) along (-1, 0, -0.2): x = 1 at s = 4 sqrt(1.04), z = 0.2. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 0, 1}, (const double[3]){-1, 0, -0.2}, &s, &h) == 1);
    SL_CHECK_NEAR(h.distance, 4.0 * sqrt(1.04), 1e-13);
    SL_CHECK_NEAR(h.cos_in, 1.0, 1e-14);
    SL_CHECK_NEAR(h.cos_world, 1.0 / sqrt(1.04), 1e-14);
    /* Past the end of the span: miss. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 0, 1.5}, (const double[3]){-1, 0, 0}, &s, &h) == 0);
    SL_CHECK(h.distance == -1.0);
    /* Caps: straight down onto the end disk, and a ray down outside the ellipse. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){0.3, 0.5, 5}, (const double[3]){0, 0, -1}, &s, &h) == 1);
    SL_CHECK_NEAR(h.distance, 4.0, 1e-14);
    SL_CHECK(h.part == RIBBONS_REF_CAP_END);
    SL_CHECK_NEAR(h.cos_in, 1.0, 1e-15);
    SL_CHECK_NEAR(h.cos_world, 1.0, 1e-15);
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){0.3, 0.5, -5}, (const double[3]){0, 0, 2}, &s, &h) == 1);
    SL_CHECK(h.part == RIBBONS_REF_CAP_START && fabs(h.distance - 4.0) < 1e-14);
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){0.9, 1.9, 5}, (const double[3]){0, 0, -1}, &s, &h) == 0);
    /* A slanted ray entering through the cap, 45 degrees: from (-0.5, 0, 2)
     * along (1, 0, -1) / sqrt 2 it reaches z = 1 at x = 0.5, sqrt 2 away. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){-0.5, 0, 2}, (const double[3]){1, 0, -1}, &s, &h) == 1);
    SL_CHECK(h.part == RIBBONS_REF_CAP_END);
    SL_CHECK_NEAR(h.distance, sqrt(2.0), 1e-14);
    SL_CHECK_NEAR(h.cos_in, sqrt(0.5), 1e-14);
    /* Parallel to the axis, outside: miss. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){3, 0, 5}, (const double[3]){0, 0, -1}, &s, &h) == 0);
    /* Grazing: touching the wide side at (0, 2) is a hit with cos_in 0. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 2, 0}, (const double[3]){-1, 0, 0}, &s, &h) == 1);
    SL_CHECK_NEAR(h.distance, 5.0, 1e-12);
    SL_CHECK_NEAR(h.cos_in, 0.0, 1e-15);
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 2.0 + 1e-9, 0}, (const double[3]){-1, 0, 0}, &s, &h) == 0);
    /* 1e-6 inside the rim: cos_in = sqrt(1 - (1 - 5e-7)^2) ~ 1e-3. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 2.0 - 1e-6, 0}, (const double[3]){-1, 0, 0}, &s, &h) == 1);
    SL_CHECK_NEAR(h.cos_in, sqrt(1.0 - (1.0 - 5e-7) * (1.0 - 5e-7)), 1e-10);
    /* Grazing the thin side (semi-axis 1) along y. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){1, -5, 0}, (const double[3]){0, 1, 0}, &s, &h) == 1);
    SL_CHECK_NEAR(h.distance, 5.0, 1e-12);
    SL_CHECK_NEAR(h.cos_in, 0.0, 1e-15);
    /* Origin inside: the hit is the exit through the wall, cosines negative. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){0, 0, 0}, (const double[3]){1, 0, 0}, &s, &h) == 1);
    SL_CHECK(h.inside && h.part == RIBBONS_REF_MANTLE);
    SL_CHECK_NEAR(h.distance, 1.0, 1e-15);
    SL_CHECK_NEAR(h.cos_in, -1.0, 1e-15);
    SL_CHECK_NEAR(h.cos_world, -1.0, 1e-15);
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){0, 0, 0.5}, (const double[3]){0, 0, 1}, &s, &h) == 1);
    SL_CHECK(h.inside && h.part == RIBBONS_REF_CAP_END && fabs(h.distance - 0.5) < 1e-15);
    /* Behind the origin: miss. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 0, 0}, (const double[3]){1, 0, 0}, &s, &h) == 0);
    /* Bad input. */
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 0, 0}, (const double[3]){0, 0, 0}, &s, &h) == -1);
    ribbons_ref_segment flat = axis_segment(2.0, 0.0, 1.0);
    SL_CHECK(ribbons_ref_ray_ellipse((const double[3]){5, 0, 0}, (const double[3]){-1, 0, 0}, &flat, &h) == -1);
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int c = 0; c < 3; c++)
        v[c] /= l;
}

/* A rotated, offset frame gives what the axis-aligned one gives for the same
 * ray expressed in local coordinates. Offset 1e5: the world coordinates carry
 * ~1.5e-11 rounding, which near grazing (cos_in -> 0) moves the cosines by
 * ~1e-10 / cos_in (d cos = dD / (2 sqrt(A D))), so they are compared scaled
 * by cos_in there. */
static void test_ray_rotated(double offset)
{
    unsigned long long s = 99;
    double worst_d = 0.0, worst_c = 0.0;
    int hits = 0, misses_agree = 1;
    for (int k = 0; k < 2000; k++) {
        double t[3] = {uniform(&s) - 0.5, uniform(&s) - 0.5, uniform(&s) - 0.5}, a[3] = {0.3, -0.7, 0.2};
        normalize3(t);
        double n[3], b[3];
        cross3(a, t, n);
        normalize3(n);
        cross3(t, n, b);
        ribbons_ref_segment rot = {.x0 = {offset, -3.0, 2.0}, .r = 0.5, .w = 0.3, .half_len = 2.0};
        for (int c = 0; c < 3; c++) {
            rot.n[c] = n[c];
            rot.b[c] = b[c];
            rot.t[c] = t[c];
        }
        ribbons_ref_segment ax = axis_segment(0.5, 0.3, 2.0);
        /* From a box around the segment towards a point near its surface: most rays hit. */
        double lo[3] = {4.0 * (uniform(&s) - 0.5), 4.0 * (uniform(&s) - 0.5), 6.0 * (uniform(&s) - 0.5)};
        double aim[3] = {0.4 * (uniform(&s) - 0.5), 1.2 * (uniform(&s) - 0.5), 4.4 * (uniform(&s) - 0.5)};
        double ld[3] = {aim[0] - lo[0], aim[1] - lo[1], aim[2] - lo[2]};
        double wo[3], wd[3];
        for (int c = 0; c < 3; c++) {
            wo[c] = rot.x0[c] + lo[0] * n[c] + lo[1] * b[c] + lo[2] * t[c];
            wd[c] = ld[0] * n[c] + ld[1] * b[c] + ld[2] * t[c];
        }
        ribbons_ref_hit hr, ha;
        int gr = ribbons_ref_ray_ellipse(wo, wd, &rot, &hr), ga = ribbons_ref_ray_ellipse(lo, ld, &ax, &ha);
        if (gr != ga || hr.part != ha.part) {
            misses_agree = 0;
            continue;
        }
        if (gr == 1) {
            double scale = fmax(fabs(ha.cos_in), 1e-3);
            worst_d = fmax(worst_d, fabs(hr.distance - ha.distance));
            worst_c = fmax(worst_c, (fabs(hr.cos_in - ha.cos_in) + fabs(hr.cos_world - ha.cos_world)) * scale);
            hits++;
        }
    }
    printf("rotated frame at offset %g: %d hits, worst |distance difference| %.3g, worst |cosine difference| x "
           "cos_in %.3g\n", offset, hits, worst_d, worst_c);
    SL_CHECK_MSG(misses_agree, "rotated and axis-aligned frames disagree on hit / part");
    SL_CHECK(hits > 1000);
    double tol = offset > 10.0 ? 1e-9 : 1e-12;
    SL_CHECK_MSG(worst_d < tol && worst_c < tol, "rotated frame at offset %g differs by %.3g / %.3g", offset, worst_d,
                 worst_c);
}

/* Entry parameter of the ray (2D, circle space) into the regular N-gon with
 * vertices (cos 2 pi j / N, sin 2 pi j / N): the polygon is the intersection
 * of the half-planes q . m_j <= cos(pi / N), m_j the edge normals. */
static int polygon_entry(const double q[2], const double e[2], int sides, double *entry)
{
    double lo = -HUGE_VAL, hi = HUGE_VAL, h = cos(PI / sides);
    for (int j = 0; j < sides; j++) {
        double a = 2.0 * PI * (j + 0.5) / sides, m[2] = {cos(a), sin(a)};
        double num = h - (q[0] * m[0] + q[1] * m[1]), den = e[0] * m[0] + e[1] * m[1];
        if (den == 0.0) {
            if (num < 0.0)
                return 0;
        } else if (den > 0.0) {
            hi = fmin(hi, num / den);
        } else {
            lo = fmax(lo, num / den);
        }
    }
    *entry = lo;
    return lo <= hi;
}

static void test_polygon_bound(void)
{
    static const int sides[] = {4, 6, 8, 12, 16, 32};
    ribbons_ref_segment s = axis_segment(2.0, 0.25, 10.0); /* semi-axes 0.5 (x) and 2 (y) */
    for (size_t i = 0; i < sizeof sides / sizeof sides[0]; i++) {
        int N = sides[i];
        /* Head-on ray through the midpoint of the edge between vertices 0 and 1:
         * circle-space direction -(cos pi/N, sin pi/N), the polygon lies
         * 1 - cos(pi/N) deeper in circle units, i.e. that over |S d|. */
        double qa = PI / N, d[3] = {-0.5 * cos(qa), -2.0 * sin(qa), 0.0};
        double o[3] = {-3.0 * d[0], -3.0 * d[1], 0.3};
        ribbons_ref_hit h;
        SL_CHECK(ribbons_ref_ray_ellipse(o, d, &s, &h) == 1);
        SL_CHECK_NEAR(h.cos_in, 1.0, 1e-14);
        double bound = ribbons_ref_polygon_bound(d, &s, N, h.cos_in);
        double dl = sqrt(d[0] * d[0] + d[1] * d[1]);
        double e[2] = {d[0] / dl / 0.5, d[1] / dl / 2.0}, across = hypot(e[0], e[1]);
        SL_CHECK_NEAR(bound, (1.0 - cos(PI / N)) / across, 1e-14);
        double q0[2] = {o[0] / 0.5, o[1] / 2.0}, entry;
        SL_CHECK(polygon_entry(q0, e, N, &entry));
        double err = entry - h.distance;
        SL_CHECK_MSG(fabs(err / bound - 1.0) < 1e-10, "N = %d head-on through an edge midpoint: err / bound = %.12g",
                     N, err / bound);
        /* Random rays: the polygon is never nearer than the mantle nor farther
         * than the bound (where one exists). */
        unsigned long long seed = 5 + (unsigned long long)N;
        double worst = 0.0;
        int checked = 0, violations = 0;
        for (int k = 0; k < 5000; k++) {
            double ang = 2.0 * PI * uniform(&seed), off = 2.2 * (uniform(&seed) - 0.5);
            double dir[3] = {cos(ang), sin(ang), 0.6 * (uniform(&seed) - 0.5)};
            double org[3] = {-6.0 * dir[0] - off * sin(ang), -6.0 * dir[1] + off * cos(ang), 0.0};
            if (ribbons_ref_ray_ellipse(org, dir, &s, &h) != 1 || h.part != RIBBONS_REF_MANTLE)
                continue;
            double b = ribbons_ref_polygon_bound(dir, &s, N, h.cos_in);
            double l3 = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
            double ee[2] = {dir[0] / l3 / 0.5, dir[1] / l3 / 2.0}, qq[2] = {org[0] / 0.5, org[1] / 2.0};
            double ent;
            if (!polygon_entry(qq, ee, N, &ent))
                continue; /* passes between polygon and ellipse: no polygon hit */
            double er = ent - h.distance;
            violations += er < -1e-12 || (b < HUGE_VAL && er > b + 1e-12);
            if (b < HUGE_VAL)
                worst = fmax(worst, er / b);
            checked++;
        }
        printf("N = %2d: bound %.4g at the edge midpoint (ratio %.12g); %d random rays, max err / bound %.4f\n", N,
               bound, err / bound, checked, worst);
        SL_CHECK_MSG(violations == 0, "N = %d: %d rays outside [0, bound]", N, violations);
        SL_CHECK(checked > 1000 && worst <= 1.0 && worst > 0.5);
    }
    /* No bound when the ray passes outside the incircle, or runs along the axis. */
    SL_CHECK(ribbons_ref_polygon_bound((const double[3]){-1, 0, 0}, &s, 8, 0.3) == HUGE_VAL);
    SL_CHECK(ribbons_ref_polygon_bound((const double[3]){0, 0, 1}, &s, 8, 1.0) == HUGE_VAL);
    SL_CHECK(ribbons_ref_polygon_bound((const double[3]){-1, 0, 0}, &s, 2, 1.0) == HUGE_VAL);
}

static void test_twist(void)
{
    /* Helix with constant helicity h: R(s) = h s, stripes at f h s + 2 pi m / k. */
    double phi[8], h = 0.8, f = 1.5;
    for (int step = 0; step < 50; step++) {
        double sarc = 0.37 * step, theta = f * h * sarc;
        SL_CHECK(ribbons_ref_twist_stripes(h * sarc, f, 3, phi) == 3);
        SL_CHECK(phi[0] >= 0.0 && phi[0] < phi[1] && phi[1] < phi[2] && phi[2] < 2.0 * PI);
        for (int m = 0; m < 3; m++) {
            double best = HUGE_VAL;
            for (int j = 0; j < 3; j++)
                best = fmin(best, ang_dist(phi[j], theta + 2.0 * PI * m / 3.0));
            SL_CHECK_NEAR(best, 0.0, 1e-12);
        }
        /* Covered at a centre and within half the width; not halfway between stripes. */
        double wu = 0.2;
        SL_CHECK(ribbons_ref_twist_covered(theta + 2.0 * PI / 3.0 + 0.099, phi, 3, wu));
        SL_CHECK(!ribbons_ref_twist_covered(theta + 0.101, phi, 3, wu));
        SL_CHECK(!ribbons_ref_twist_covered(theta + PI / 3.0, phi, 3, wu));
        SL_CHECK(ribbons_ref_twist_covered(theta - 2.0 * PI, phi, 3, wu));
    }
    SL_CHECK(ribbons_ref_twist_stripes(-7.0, 1.0, 1, phi) == 1 && fabs(phi[0] - (4.0 * PI - 7.0)) < 1e-14);
    SL_CHECK(ribbons_ref_twist_stripes(1.0, 1.0, 0, phi) == 0);
    /* Width correction: w_r / cos(atan(slope)) = w_r sqrt(1 + slope^2). */
    double worst = 0.0;
    for (int k = 0; k <= 100; k++) {
        double slope = 0.1 * k, w = ribbons_ref_twist_width(0.15, slope);
        worst = fmax(worst, fabs(w / (0.15 * sqrt(1.0 + slope * slope)) - 1.0));
        SL_CHECK_NEAR(ribbons_ref_twist_width(0.15, -slope), w, 1e-15);
    }
    printf("twist width against w_r sqrt(1 + slope^2): worst relative %.3g over slopes 0..10\n", worst);
    SL_CHECK_MSG(worst < 1e-14, "twist width off by %.3g relative", worst);
    SL_CHECK_NEAR(ribbons_ref_twist_width(0.15, 0.0), 0.15, 1e-16);
    /* 45 degrees: a tube of radius r with r f h = 1 has slope 1, width sqrt 2 w_r. */
    double r = 0.05, tf = 4.0, hh = 1.0 / (r * tf);
    double slope = ribbons_ref_twist_slope(r, tf, hh);
    SL_CHECK_NEAR(slope, 1.0, 1e-15);
    SL_CHECK_NEAR(ribbons_ref_twist_width(0.15, slope), 0.15 * sqrt(2.0), 1e-15);
}

int main(void)
{
    test_tangent_circle();
    test_tangent_ellipse();
    test_tangent_special();
    test_lambda();
    test_ray_axis_aligned();
    test_ray_rotated(3.0);
    test_ray_rotated(1e5);
    test_polygon_bound();
    test_twist();
    SL_TEST_END();
}
