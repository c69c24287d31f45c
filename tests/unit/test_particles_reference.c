/* test_particles_reference.c — the particle references of tests/support/particles_reference.c.
 *
 * B-spline: the recursion's weights against the closed cubic polynomials of the plan
 * (§1.5), partition of unity, derivative weights summing to 0, linear fields exact, and
 * for a quadratic q(u) = uᵀAu + bᵀu + c sampled at the voxels ∇f, H exact and
 * f = q + tr(A)/3 exactly (measured: |f − q − tr(A)/3| ≤ 1e-12·|q|; the cubic B-spline's
 * variance is 1/3 per axis, the approximating filter's bias). Trilinear: a trilinear
 * polynomial exact with its gradient, clamping, integer types, NaN. Curvature: sphere,
 * cylinder, saddle (also rotated) to 1e-12 with e1; the 3×3 Jacobi against the plan's 2×2
 * tangent form; ellipsoid closed forms at 1000 points (1e-10 relative); torus against a
 * differentiated signed distance; shape index and reliability limits. Nearest point on an
 * ellipsoid (residual, orthogonality, brute force, degenerate points), areas against the
 * spheroid closed forms, NN statistics (hexagonal patch, grid = brute force), placement
 * counts on hand-made volumes, the CSV reader's round trip and each error, and the references
 * on gen_ellipsoid's f32/u16 data (seed count, isovalue in data units, curvature). CPU only.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "data/sl_generate.h"
#include "particles_reference.h"
#include "sl_test.h"

#define PI 3.14159265358979323846

/* A deterministic uniform number in [0, 1) (splitmix64), independent of the renderer's PRNG. */
static double uniform(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) / 9007199254740992.0;
}

/* An f32 volume of the given dims, values from fn(i, j, k). */
typedef double (*voxel_fn)(int i, int j, int k);

static sl_volume make_volume(int nx, int ny, int nz, voxel_fn fn)
{
    sl_volume v;
    memset(&v, 0, sizeof v);
    v.dims[0] = nx;
    v.dims[1] = ny;
    v.dims[2] = nz;
    v.components = 1;
    v.type = SL_VOXEL_F32;
    v.spacing[0] = v.spacing[1] = v.spacing[2] = 1.0;
    float *data = malloc((size_t)nx * ny * nz * sizeof *data);
    size_t n = 0;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++)
                data[n++] = (float)fn(i, j, k);
    v.data = data;
    return v;
}

static double max_abs_diff(const double *a, const double *b, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

/* ---- B-spline ---- */

static void test_bspline_weights(void)
{
    double worst_closed = 0.0, worst_sum = 0.0;
    for (int s = 0; s <= 1000; s++) {
        double t = s / 1000.0 * 0.999999999, w[4], d1[4], d2[4];
        pref_bspline_weights(t, w, d1, d2);
        /* Plan §1.5's closed polynomials, which the shader uses: the recursion must agree. */
        const double cw[4] = {(1 - t) * (1 - t) * (1 - t) / 6, (3 * t * t * t - 6 * t * t + 4) / 6,
                              (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6, t * t * t / 6};
        const double c1[4] = {-(1 - t) * (1 - t) / 2, (3 * t * t - 4 * t) / 2, (-3 * t * t + 2 * t + 1) / 2, t * t / 2};
        const double c2[4] = {1 - t, 3 * t - 2, -3 * t + 1, t};
        worst_closed = fmax(worst_closed, max_abs_diff(w, cw, 4));
        worst_closed = fmax(worst_closed, max_abs_diff(d1, c1, 4));
        worst_closed = fmax(worst_closed, max_abs_diff(d2, c2, 4));
        worst_sum = fmax(worst_sum, fabs(w[0] + w[1] + w[2] + w[3] - 1.0));
        worst_sum = fmax(worst_sum, fabs(d1[0] + d1[1] + d1[2] + d1[3]));
        worst_sum = fmax(worst_sum, fabs(d2[0] + d2[1] + d2[2] + d2[3]));
        for (int i = 0; i < 4; i++)
            SL_CHECK(w[i] >= 0.0);
    }
    SL_CHECK_NEAR(worst_closed, 0.0, 1e-15);
    SL_CHECK_NEAR(worst_sum, 0.0, 1e-15);
    double w[4], d1[4], d2[4];
    pref_bspline_weights(0.0, w, d1, d2);
    SL_CHECK(w[0] == 1.0 / 6.0 && w[1] == 4.0 / 6.0 && w[2] == 1.0 / 6.0 && w[3] == 0.0);
    SL_CHECK(d1[0] == -0.5 && d1[1] == 0.0 && d1[2] == 0.5 && d1[3] == 0.0);
    SL_CHECK(d2[0] == 1.0 && d2[1] == -2.0 && d2[2] == 1.0 && d2[3] == 0.0);
}

static double linear_field(int i, int j, int k)
{
    return 1.5 + 0.25 * i - 0.5 * j + 0.125 * k;
}

/* q(u) = uᵀAu + bᵀu + c with integer A, b, c: integers at the voxels (exact in float). */
static const double QA[9] = {2, 1, -1, 1, 3, 2, -1, 2, 1}; /* tr = 6: a bias of 2 */
static const double QB[3] = {3, -2, 5};
static const double QC = 7;

static double quadratic(const double u[3])
{
    double s = QC;
    for (int a = 0; a < 3; a++) {
        s += QB[a] * u[a];
        for (int b = 0; b < 3; b++)
            s += u[a] * QA[3 * a + b] * u[b];
    }
    return s;
}

static double quadratic_field(int i, int j, int k)
{
    const double u[3] = {i, j, k};
    return quadratic(u);
}

static void test_bspline_fields(void)
{
    uint64_t rng = 1;
    sl_volume lin = make_volume(12, 11, 10, linear_field);
    double worst_f = 0.0, worst_g = 0.0, worst_h = 0.0;
    for (int s = 0; s < 500; s++) {
        double u[3] = {2 + 7 * uniform(&rng), 2 + 6 * uniform(&rng), 2 + 5 * uniform(&rng)}, f, g[3], H[9];
        SL_CHECK(pref_bspline(&lin, u, &f, g, H) == 0);
        worst_f = fmax(worst_f, fabs(f - (1.5 + 0.25 * u[0] - 0.5 * u[1] + 0.125 * u[2])));
        const double want[3] = {0.25, -0.5, 0.125}, zero[9] = {0};
        worst_g = fmax(worst_g, max_abs_diff(g, want, 3));
        worst_h = fmax(worst_h, max_abs_diff(H, zero, 9));
    }
    SL_CHECK_NEAR(worst_f, 0.0, 1e-13);
    SL_CHECK_NEAR(worst_g, 0.0, 1e-13);
    SL_CHECK_NEAR(worst_h, 0.0, 1e-13);
    /* Clamp to edge: a linear field is flattened beyond the border, so not reproduced there. */
    double f, g[3], H[9];
    const double corner[3] = {0.0, 0.0, 0.0};
    SL_CHECK(pref_bspline(&lin, corner, &f, g, H) == 0);
    SL_CHECK(fabs(f - 1.5) > 1e-3 && fabs(g[0] - 0.25) > 1e-3);
    free(lin.data);

    sl_volume quad = make_volume(14, 13, 12, quadratic_field);
    double bias = (QA[0] + QA[4] + QA[8]) / 3.0, worst_rel = 0.0;
    worst_g = worst_h = 0.0;
    for (int s = 0; s < 500; s++) {
        double u[3] = {2 + 9 * uniform(&rng), 2 + 8 * uniform(&rng), 2 + 7 * uniform(&rng)};
        SL_CHECK(pref_bspline(&quad, u, &f, g, H) == 0);
        double q = quadratic(u);
        worst_rel = fmax(worst_rel, fabs(f - (q + bias)) / fmax(1.0, fabs(q)));
        double want_g[3], want_h[9];
        for (int a = 0; a < 3; a++) {
            want_g[a] = QB[a];
            for (int b = 0; b < 3; b++) {
                want_g[a] += (QA[3 * a + b] + QA[3 * b + a]) * u[b];
                want_h[3 * a + b] = QA[3 * a + b] + QA[3 * b + a];
            }
        }
        worst_g = fmax(worst_g, max_abs_diff(g, want_g, 3) / fmax(1.0, fabs(want_g[0]) + fabs(want_g[1]) + fabs(want_g[2])));
        worst_h = fmax(worst_h, max_abs_diff(H, want_h, 9));
        SL_CHECK(H[1] == H[3] && H[2] == H[6] && H[5] == H[7]);
    }
    printf("B-spline on a quadratic: |f - q - tr(A)/3| <= %.2g |q|, grad %.2g, H %.2g\n", worst_rel, worst_g, worst_h);
    SL_CHECK_NEAR(worst_rel, 0.0, 1e-12);
    SL_CHECK_NEAR(worst_g, 0.0, 1e-12);
    SL_CHECK_NEAR(worst_h, 0.0, 1e-12);
    SL_CHECK(fabs(bias) > 0.1); /* the bias is visible: q alone would fail */
    ((float *)quad.data)[5 + 14 * (5 + 13 * 5)] = NAN;
    const double near_nan[3] = {5.5, 4.2, 6.9};
    SL_CHECK(pref_bspline(&quad, near_nan, &f, g, H) == -1 && isnan(f) && isnan(g[1]) && isnan(H[8]));
    const double far_nan[3] = {10.5, 10.2, 9.9};
    SL_CHECK(pref_bspline(&quad, far_nan, &f, NULL, NULL) == 0 && isfinite(f));
    free(quad.data);
}

/* ---- trilinear ---- */

static double trilinear_poly(double x, double y, double z)
{
    return 2 - x + 0.5 * y + 3 * z + 0.25 * x * y - 0.5 * x * z + y * z - 0.125 * x * y * z;
}

static double trilinear_field(int i, int j, int k)
{
    return trilinear_poly(i, j, k);
}

static void test_trilinear(void)
{
    sl_volume v = make_volume(5, 4, 3, trilinear_field);
    uint64_t rng = 7;
    double worst_f = 0.0, worst_g = 0.0;
    for (int s = 0; s < 500; s++) {
        /* Inside one cell the trilinear interpolant of a trilinear polynomial is the polynomial. */
        double u[3] = {4 * uniform(&rng), 3 * uniform(&rng), 2 * uniform(&rng)}, f, g[3];
        SL_CHECK(pref_trilinear(&v, u, &f, g) == 0);
        double x = u[0], y = u[1], z = u[2];
        worst_f = fmax(worst_f, fabs(f - trilinear_poly(x, y, z)));
        const double want[3] = {-1 + 0.25 * y - 0.5 * z - 0.125 * y * z, 0.5 + 0.25 * x + z - 0.125 * x * z,
                                3 - 0.5 * x + y - 0.125 * x * y};
        worst_g = fmax(worst_g, max_abs_diff(g, want, 3));
    }
    SL_CHECK_NEAR(worst_f, 0.0, 1e-13);
    SL_CHECK_NEAR(worst_g, 0.0, 1e-13);
    /* Voxel values at integer u, the last voxel included; beyond the grid the edge value, gradient 0 there. */
    double f, g[3];
    const double last[3] = {4, 3, 2};
    SL_CHECK(pref_trilinear(&v, last, &f, g) == 0 && f == trilinear_poly(4, 3, 2));
    const double out[3] = {-3, 1.5, 7};
    SL_CHECK(pref_trilinear(&v, out, &f, g) == 0);
    SL_CHECK_NEAR(f, trilinear_poly(0, 1.5, 2), 1e-13);
    SL_CHECK(g[0] == 0.0 && g[2] == 0.0 && fabs(g[1] - (0.5 + 2 - 0)) < 1e-13);
    /* A voxel of zero weight does not poison f; one of non-zero weight does. */
    ((float *)v.data)[1] = NAN; /* voxel (1, 0, 0) */
    const double at0[3] = {0, 0, 0}, mid[3] = {0.5, 0.25, 0.5};
    SL_CHECK(pref_trilinear(&v, at0, &f, g) == 0 && f == 2.0 && isnan(g[0]));
    SL_CHECK(pref_trilinear(&v, mid, &f, g) == -1 && isnan(f) && isnan(g[2]));
    free(v.data);

    /* Integer types are their raw values; a one-voxel axis has gradient 0. */
    uint16_t u16[4] = {0, 65535, 1000, 3000};
    int16_t s16[4] = {-32768, 32767, -2, 2};
    uint8_t u8[4] = {0, 255, 10, 30};
    sl_volume iv;
    memset(&iv, 0, sizeof iv);
    iv.dims[0] = 2;
    iv.dims[1] = 2;
    iv.dims[2] = 1;
    iv.components = 1;
    const double q[3] = {0.5, 0.5, 0.0};
    iv.type = SL_VOXEL_U16;
    iv.data = u16;
    SL_CHECK(pref_trilinear(&iv, q, &f, g) == 0 && f == (0 + 65535 + 1000 + 3000) / 4.0 && g[2] == 0.0);
    SL_CHECK_NEAR(g[0], (65535 - 0 + 3000 - 1000) / 2.0, 1e-9);
    iv.type = SL_VOXEL_S16;
    iv.data = s16;
    SL_CHECK(pref_trilinear(&iv, q, &f, g) == 0 && f == (-32768 + 32767 - 2 + 2) / 4.0);
    iv.type = SL_VOXEL_U8;
    iv.data = u8;
    SL_CHECK(pref_trilinear(&iv, q, &f, g) == 0 && f == (0 + 255 + 10 + 30) / 4.0);
    SL_CHECK_NEAR(g[1], (10 - 0 + 30 - 255) / 2.0, 1e-12);
}

static void test_voxel_to_world(void)
{
    const double sp[3] = {0.5, 2.0, 4.0}, g_u[3] = {1, 2, 4};
    double H_u[9], g_x[3], H_x[9];
    for (int i = 0; i < 9; i++)
        H_u[i] = i + 1;
    pref_voxel_to_world(sp, g_u, H_u, g_x, H_x);
    SL_CHECK(g_x[0] == 2.0 && g_x[1] == 1.0 && g_x[2] == 1.0);
    SL_CHECK(H_x[0] == 4.0 && H_x[1] == 2.0 / 1.0 && H_x[5] == 6.0 / 8.0 && H_x[8] == 9.0 / 16.0);
}

/* ---- curvature ---- */

static void rotate_vec(const double R[9], const double v[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
    memcpy(out, r, sizeof r);
}

/* H' = R H Rᵀ. */
static void rotate_mat(const double R[9], const double H[9], double out[9])
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    s += R[3 * i + a] * H[3 * a + b] * R[3 * j + b];
            r[3 * i + j] = s;
        }
    memcpy(out, r, sizeof r);
}

/* A random rotation (from a random unit quaternion). */
static void random_rotation(uint64_t *rng, double R[9])
{
    double q[4], n = 0.0;
    for (int i = 0; i < 4; i++) {
        q[i] = uniform(rng) - 0.5;
        n += q[i] * q[i];
    }
    n = sqrt(n);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    const double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                         2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    memcpy(R, m, sizeof m);
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The plan's 2×2 tangent-plane form (the shader's), written here to cross-check the Jacobi path. */
static void curvature_2x2(const double g[3], const double H[9], double *k1, double *k2)
{
    double len = sqrt(dot3(g, g)), n[3] = {-g[0] / len, -g[1] / len, -g[2] / len};
    double sign = n[2] >= 0.0 ? 1.0 : -1.0, a = -1.0 / (sign + n[2]), b = n[0] * n[1] * a;
    double t1[3] = {1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]};
    double t2[3] = {b, sign + n[1] * n[1] * a, -n[1]};
    double Ht1[3], Ht2[3];
    rotate_vec(H, t1, Ht1);
    rotate_vec(H, t2, Ht2);
    double m11 = -dot3(t1, Ht1) / len, m12 = -dot3(t1, Ht2) / len, m22 = -dot3(t2, Ht2) / len;
    double mid = 0.5 * (m11 + m22), r = sqrt(0.25 * (m11 - m22) * (m11 - m22) + m12 * m12);
    *k1 = mid + r;
    *k2 = mid - r;
}

static void test_curvature_analytic(void)
{
    uint64_t rng = 3;
    double k1, k2, e1[3];
    /* Bright ball f = R − |x| at x = ρ x̂: g = −x̂, H = −(I − x̂x̂ᵀ)/ρ → κ1 = κ2 = 1/ρ. */
    double worst = 0.0;
    for (int s = 0; s < 200; s++) {
        double x[3] = {uniform(&rng) - 0.5, uniform(&rng) - 0.5, uniform(&rng) - 0.5};
        double rho = sqrt(dot3(x, x)), xh[3] = {x[0] / rho, x[1] / rho, x[2] / rho};
        double g[3] = {-xh[0], -xh[1], -xh[2]}, H[9];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                H[3 * i + j] = -((i == j) - xh[i] * xh[j]) / rho;
        SL_CHECK(pref_curvature(g, H, &k1, &k2, e1) == 0);
        worst = fmax(worst, fmax(fabs(k1 * rho - 1.0), fabs(k2 * rho - 1.0)));
        SL_CHECK(fabs(dot3(e1, xh)) < 1e-12 && fabs(dot3(e1, e1) - 1.0) < 1e-12);
    }
    SL_CHECK_NEAR(worst, 0.0, 1e-12);

    /* Bright cylinder f = R − sqrt(x² + y²) (axis z): κ1 = 1/ρ around, κ2 = 0, e1 azimuthal. */
    worst = 0.0;
    double worst_dir = 0.0;
    for (int s = 0; s < 200; s++) {
        double x = uniform(&rng) - 0.5, y = uniform(&rng) - 0.5, rho = hypot(x, y);
        double rh[3] = {x / rho, y / rho, 0}, g[3] = {-rh[0], -rh[1], 0}, H[9] = {0};
        for (int i = 0; i < 2; i++)
            for (int j = 0; j < 2; j++)
                H[3 * i + j] = -((i == j) - rh[i] * rh[j]) / rho;
        double R[9];
        random_rotation(&rng, R);
        const double azim[3] = {-rh[1], rh[0], 0};
        double az[3];
        rotate_vec(R, g, g);
        rotate_mat(R, H, H);
        rotate_vec(R, azim, az);
        SL_CHECK(pref_curvature(g, H, &k1, &k2, e1) == 0);
        worst = fmax(worst, fmax(fabs(k1 * rho - 1.0), fabs(k2 * rho)));
        worst_dir = fmax(worst_dir, 1.0 - fabs(dot3(e1, az)));
    }
    SL_CHECK_NEAR(worst, 0.0, 1e-12);
    SL_CHECK_NEAR(worst_dir, 0.0, 1e-12);

    /* Dark cylinder f = sqrt(x² + y²) − R (seen from inside): κ1 = 0 along the axis, κ2 = −1/ρ. κ1 shares
     * n's eigenvalue 0, so e1 must still be the axis, not a mix with n. */
    worst = worst_dir = 0.0;
    for (int s = 0; s < 200; s++) {
        double x = uniform(&rng) - 0.5, y = uniform(&rng) - 0.5, rho = hypot(x, y);
        double rh[3] = {x / rho, y / rho, 0}, g[3] = {rh[0], rh[1], 0}, H[9] = {0}, axis[3] = {0, 0, 1}, R[9];
        for (int i = 0; i < 2; i++)
            for (int j = 0; j < 2; j++)
                H[3 * i + j] = ((i == j) - rh[i] * rh[j]) / rho;
        random_rotation(&rng, R);
        rotate_vec(R, g, g);
        rotate_mat(R, H, H);
        rotate_vec(R, axis, axis);
        SL_CHECK(pref_curvature(g, H, &k1, &k2, e1) == 0);
        worst = fmax(worst, fmax(fabs(k1), fabs(k2 * rho + 1.0)));
        worst_dir = fmax(worst_dir, 1.0 - fabs(dot3(e1, axis)));
    }
    SL_CHECK_NEAR(worst, 0.0, 1e-12);
    SL_CHECK_NEAR(worst_dir, 0.0, 1e-12);

    /* Saddle f = z − (α x² − β y²)/2 at 0: n = −z, κ1 = α along x, κ2 = −β; rotated at random. */
    worst = worst_dir = 0.0;
    for (int s = 0; s < 200; s++) {
        double alpha = 0.1 + uniform(&rng), beta = 0.1 + uniform(&rng);
        double g[3] = {0, 0, 1}, H[9] = {-alpha, 0, 0, 0, beta, 0, 0, 0, 0}, ex[3] = {1, 0, 0}, R[9];
        random_rotation(&rng, R);
        rotate_vec(R, g, g);
        rotate_mat(R, H, H);
        rotate_vec(R, ex, ex);
        SL_CHECK(pref_curvature(g, H, &k1, &k2, e1) == 0);
        worst = fmax(worst, fmax(fabs(k1 - alpha), fabs(k2 + beta)));
        worst_dir = fmax(worst_dir, 1.0 - fabs(dot3(e1, ex)));
        /* e1's sign rule: its largest |component| is positive. */
        int big = fabs(e1[1]) > fabs(e1[0]) ? 1 : 0;
        big = fabs(e1[2]) > fabs(e1[big]) ? 2 : big;
        SL_CHECK(e1[big] > 0.0);
    }
    SL_CHECK_NEAR(worst, 0.0, 1e-12);
    SL_CHECK_NEAR(worst_dir, 0.0, 1e-12);

    /* Random gradients and Hessians: the 3×3 Jacobi path equals the 2×2 tangent form; scale-free. */
    worst = 0.0;
    for (int s = 0; s < 1000; s++) {
        double g[3], H[9], c1, c2;
        for (int i = 0; i < 3; i++)
            g[i] = uniform(&rng) - 0.5;
        for (int i = 0; i < 3; i++)
            for (int j = i; j < 3; j++)
                H[3 * i + j] = H[3 * j + i] = uniform(&rng) - 0.5;
        SL_CHECK(pref_curvature(g, H, &k1, &k2, NULL) == 0);
        curvature_2x2(g, H, &c1, &c2);
        double scale = fabs(c1) + fabs(c2) + 1e-300;
        worst = fmax(worst, (fabs(k1 - c1) + fabs(k2 - c2)) / scale);
        for (int i = 0; i < 9; i++)
            H[i] *= 1e-9; /* tiny curvatures keep their relative precision */
        double t1, t2;
        SL_CHECK(pref_curvature(g, H, &t1, &t2, NULL) == 0);
        worst = fmax(worst, (fabs(t1 * 1e9 - c1) + fabs(t2 * 1e9 - c2)) / scale);
    }
    SL_CHECK_NEAR(worst, 0.0, 1e-12);
    const double zero[3] = {0, 0, 0}, Hz[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, gn[3] = {NAN, 0, 1};
    SL_CHECK(pref_curvature(zero, Hz, &k1, &k2, e1) == -1 && k1 == 0.0 && k2 == 0.0);
    SL_CHECK(pref_curvature(gn, Hz, &k1, &k2, e1) == -1);
    /* A plane: both 0, still succeeds. */
    const double gz[3] = {0, 0, -2}, H0[9] = {0};
    SL_CHECK(pref_curvature(gz, H0, &k1, &k2, e1) == 0 && k1 == 0.0 && k2 == 0.0);
}

static void test_ellipsoid_curvature(void)
{
    uint64_t rng = 11;
    double k1, k2, e1[3];
    /* At (a, 0, 0): a/b² (along y) and a/c² (along z); here b < c so e1 = y. */
    const double axes[3] = {0.7, 0.3, 0.5}, px[3] = {0.7, 0, 0};
    SL_CHECK(pref_ellipsoid_curvature(axes, px, &k1, &k2, e1) == 0);
    SL_CHECK_NEAR(k1, 0.7 / 0.09, 1e-12);
    SL_CHECK_NEAR(k2, 0.7 / 0.25, 1e-12);
    SL_CHECK_NEAR(fabs(e1[1]), 1.0, 1e-12);
    /* Closed forms: K = 1/(a²b²c²h⁴), |mean| = |x²+y²+z²−a²−b²−c²|/(2a²b²c²h³), h² = Σ x_i²/a_i⁴. */
    double worst_k = 0.0, worst_h = 0.0;
    for (int s = 0; s < 1000; s++) {
        double ax[3] = {0.1 + uniform(&rng), 0.1 + uniform(&rng), 0.1 + uniform(&rng)};
        double th = PI * uniform(&rng), ph = 2 * PI * uniform(&rng);
        double p[3] = {ax[0] * sin(th) * cos(ph), ax[1] * sin(th) * sin(ph), ax[2] * cos(th)};
        SL_CHECK(pref_ellipsoid_curvature(ax, p, &k1, &k2, e1) == 0);
        double a2 = ax[0] * ax[0], b2 = ax[1] * ax[1], c2 = ax[2] * ax[2];
        double h2 = p[0] * p[0] / (a2 * a2) + p[1] * p[1] / (b2 * b2) + p[2] * p[2] / (c2 * c2);
        double K = 1.0 / (a2 * b2 * c2 * h2 * h2);
        double M = fabs(dot3(p, p) - a2 - b2 - c2) / (2 * a2 * b2 * c2 * h2 * sqrt(h2));
        worst_k = fmax(worst_k, fabs(k1 * k2 - K) / K);
        worst_h = fmax(worst_h, fabs(0.5 * (k1 + k2) - M) / M);
        SL_CHECK(k1 >= k2 && k2 > 0.0); /* convex, outward normal: positive */
    }
    printf("ellipsoid closed forms: Gaussian rel %.2g, mean rel %.2g at 1000 points\n", worst_k, worst_h);
    SL_CHECK_NEAR(worst_k, 0.0, 1e-10);
    SL_CHECK_NEAR(worst_h, 0.0, 1e-10);
}

/* Gradient of a bright torus f = r − sqrt((ρ − R0)² + z²). */
static void torus_gradient(double R0, const double p[3], double g[3])
{
    double rho = hypot(p[0], p[1]), d = hypot(rho - R0, p[2]);
    g[0] = -(rho - R0) / d * p[0] / rho;
    g[1] = -(rho - R0) / d * p[1] / rho;
    g[2] = -p[2] / d;
}

static void test_torus(void)
{
    const double R0 = 0.55, r = 0.2;
    double k1, k2, e1[3], main_dir[3], q[3];
    const double outer[3] = {R0 + r, 0, 0}, inner[3] = {R0 - r, 0, 0}, top[3] = {R0, 0, r};
    SL_CHECK(pref_torus_curvature(R0, r, outer, &k1, &k2, e1, main_dir) == 0);
    SL_CHECK_NEAR(k1, 1 / r, 1e-12);
    SL_CHECK_NEAR(k2, 1 / (R0 + r), 1e-12);
    SL_CHECK_NEAR(fabs(e1[2]), 1.0, 1e-12);
    SL_CHECK(pref_torus_curvature(R0, r, inner, &k1, &k2, e1, main_dir) == 0);
    SL_CHECK_NEAR(k2, -1 / (R0 - r), 1e-12);
    SL_CHECK_NEAR(fabs(main_dir[2]), 1.0, 1e-12); /* 1/r = 5 > 1/(R0 − r) = 2.86: the meridian */
    SL_CHECK(pref_torus_curvature(R0, r, top, &k1, &k2, e1, main_dir) == 0);
    SL_CHECK_NEAR(k2, 0.0, 1e-12);
    /* A fat torus (r > R0/2): the parallel dominates at the inner equator. */
    const double inner_fat[3] = {0.55 - 0.4, 0, 0};
    SL_CHECK(pref_torus_curvature(0.55, 0.4, inner_fat, &k1, &k2, e1, main_dir) == 0);
    SL_CHECK(fabs(k2) > fabs(k1) && fabs(main_dir[1]) > 0.999999);
    /* Against pref_curvature on the differentiated bright torus (Hessian by central differences of
     * the analytic gradient, error O(h²) ≈ 1e-9). */
    uint64_t rng = 5;
    double worst = 0.0, worst_near = 0.0;
    for (int s = 0; s < 200; s++) {
        double u = 2 * PI * uniform(&rng), v = 2 * PI * uniform(&rng);
        double p[3] = {(R0 + r * cos(v)) * cos(u), (R0 + r * cos(v)) * sin(u), r * sin(v)}, g[3], H[9];
        torus_gradient(R0, p, g);
        const double h = 1e-5;
        for (int b = 0; b < 3; b++) {
            double pp[3] = {p[0], p[1], p[2]}, pm[3] = {p[0], p[1], p[2]}, gp[3], gm[3];
            pp[b] += h;
            pm[b] -= h;
            torus_gradient(R0, pp, gp);
            torus_gradient(R0, pm, gm);
            for (int a = 0; a < 3; a++)
                H[3 * a + b] = (gp[a] - gm[a]) / (2 * h);
        }
        for (int a = 0; a < 3; a++)
            for (int b = a + 1; b < 3; b++)
                H[3 * a + b] = H[3 * b + a] = 0.5 * (H[3 * a + b] + H[3 * b + a]);
        double c1, c2;
        SL_CHECK(pref_curvature(g, H, &c1, &c2, NULL) == 0);
        SL_CHECK(pref_torus_curvature(R0, r, p, &k1, &k2, e1, NULL) == 0);
        worst = fmax(worst, fmax(fabs(c1 - k1), fabs(c2 - k2)));
        /* The nearest point of a point off the surface along the normal comes back. */
        double off[3] = {p[0] + 0.05 * (p[0] - R0 * cos(u)) / r, p[1] + 0.05 * (p[1] - R0 * sin(u)) / r,
                         p[2] + 0.05 * p[2] / r};
        double d = pref_torus_nearest(R0, r, off, q);
        worst_near = fmax(worst_near, fmax(fabs(d - 0.05), sqrt((q[0] - p[0]) * (q[0] - p[0]) +
                                                                 (q[1] - p[1]) * (q[1] - p[1]) + (q[2] - p[2]) * (q[2] - p[2]))));
    }
    SL_CHECK_NEAR(worst, 0.0, 1e-6);
    SL_CHECK_NEAR(worst_near, 0.0, 1e-12);
    const double axis[3] = {0, 0, 0.3};
    SL_CHECK(pref_torus_curvature(R0, r, axis, &k1, &k2, e1, main_dir) == -1);
}

static void test_shape_index(void)
{
    SL_CHECK_NEAR(pref_shape_index(2, 2), -1.0, 0.0);    /* sphere (convex) */
    SL_CHECK_NEAR(pref_shape_index(-2, -2), 1.0, 0.0);   /* cup */
    SL_CHECK_NEAR(pref_shape_index(2, 0), -0.5, 1e-15);  /* ridge */
    SL_CHECK_NEAR(pref_shape_index(0, -2), 0.5, 1e-15);  /* valley */
    SL_CHECK_NEAR(pref_shape_index(1.5, -1.5), 0.0, 0.0); /* symmetric saddle */
    SL_CHECK_NEAR(pref_shape_index(0, 2), -0.5, 1e-15);  /* given in the wrong order */
    SL_CHECK(isnan(pref_shape_index(0, 0)));
    /* Continuity into the umbilic limit. */
    SL_CHECK_NEAR(pref_shape_index(1.0 + 1e-9, 1.0), -1.0, 1e-6);
    SL_CHECK(pref_shape_index(1.0, 0.5) < -0.5 && pref_shape_index(1.0, 0.5) > -1.0);
    const double eps = 0.01;
    SL_CHECK_NEAR(pref_reliability(0.3, 0.3, eps), 0.0, 0.0);
    SL_CHECK_NEAR(pref_reliability(-0.3, -0.3, eps), 0.0, 0.0);
    SL_CHECK_NEAR(pref_reliability(0.3, 0.0, eps), 1.0, 1e-15);
    SL_CHECK_NEAR(pref_reliability(0.0, -0.3, eps), 1.0, 1e-15);
    SL_CHECK_NEAR(pref_reliability(0.3, -0.3, eps), 0.0, 1e-15);
    SL_CHECK_NEAR(pref_reliability(0.0, 0.0, eps), 0.0, 0.0);
    SL_CHECK_NEAR(pref_reliability(eps / 2, eps / 2, eps), 0.0, 0.0);
    SL_CHECK_NEAR(pref_reliability(eps / 2, 0.0, eps), 0.0, 0.0); /* flat: not "cylinder-like" */
    SL_CHECK_NEAR(pref_reliability(eps, 0.0, eps), 1.0, 1e-15);   /* |κ| = ε is not flat */
    SL_CHECK(pref_reliability(1.0, 0.5, eps) > 0.0 && pref_reliability(1.0, 0.5, eps) < 1.0);
}

/* ---- nearest point, areas ---- */

static void test_ellipsoid_nearest(void)
{
    uint64_t rng = 21;
    double worst_res = 0.0, worst_orth = 0.0, worst_brute = 0.0;
    for (int s = 0; s < 300; s++) {
        double ax[3] = {0.2 + uniform(&rng), 0.2 + uniform(&rng), 0.2 + uniform(&rng)};
        double p[3] = {2.4 * (uniform(&rng) - 0.5), 2.4 * (uniform(&rng) - 0.5), 2.4 * (uniform(&rng) - 0.5)}, q[3];
        double d = pref_ellipsoid_nearest(ax, p, q);
        double res = q[0] * q[0] / (ax[0] * ax[0]) + q[1] * q[1] / (ax[1] * ax[1]) + q[2] * q[2] / (ax[2] * ax[2]) - 1;
        worst_res = fmax(worst_res, fabs(res));
        /* p − q is along the surface normal ∇F(q). */
        double nq[3] = {q[0] / (ax[0] * ax[0]), q[1] / (ax[1] * ax[1]), q[2] / (ax[2] * ax[2])}, dq[3];
        double nl = sqrt(dot3(nq, nq));
        for (int i = 0; i < 3; i++) {
            nq[i] /= nl;
            dq[i] = p[i] - q[i];
        }
        double cr[3] = {dq[1] * nq[2] - dq[2] * nq[1], dq[2] * nq[0] - dq[0] * nq[2], dq[0] * nq[1] - dq[1] * nq[0]};
        worst_orth = fmax(worst_orth, sqrt(dot3(cr, cr)));
        SL_CHECK_NEAR(d, sqrt(dot3(dq, dq)), 1e-15);
        /* No sampled surface point is nearer (the global minimum, not only a stationary point). */
        if (s < 30) {
            double best = INFINITY;
            for (int i = 0; i <= 300; i++)
                for (int j = 0; j < 600; j++) {
                    double th = PI * i / 300.0, ph = 2 * PI * j / 600.0;
                    double e[3] = {ax[0] * sin(th) * cos(ph) - p[0], ax[1] * sin(th) * sin(ph) - p[1], ax[2] * cos(th) - p[2]};
                    best = fmin(best, sqrt(dot3(e, e)));
                }
            worst_brute = fmax(worst_brute, d - best);
        }
    }
    SL_CHECK_NEAR(worst_res, 0.0, 1e-12);
    SL_CHECK_NEAR(worst_orth, 0.0, 1e-12);
    SL_CHECK(worst_brute <= 1e-12);
    /* Degenerate points: the centre (nearest = the smallest axis), and a point in the plane of the
     * smallest axis near the centre (the nearest point leaves that plane). */
    const double ax[3] = {1.0, 0.8, 0.5}, centre[3] = {0, 0, 0}, flat[3] = {0.1, 0.05, 0.0};
    double q[3];
    SL_CHECK_NEAR(pref_ellipsoid_nearest(ax, centre, q), 0.5, 1e-15);
    SL_CHECK_NEAR(fabs(q[2]), 0.5, 1e-15);
    double d = pref_ellipsoid_nearest(ax, flat, q);
    SL_CHECK(fabs(q[2]) > 0.4 && d < 0.5);
    SL_CHECK_NEAR(q[0], 0.1 / (1 - 0.25), 1e-14); /* a² p/(a² − c²) */
    SL_CHECK_NEAR(q[1], 0.64 * 0.05 / (0.64 - 0.25), 1e-14);
    const double on_axis[3] = {2.0, 0, 0};
    SL_CHECK_NEAR(pref_ellipsoid_nearest(ax, on_axis, q), 1.0, 1e-15);
}

static void test_areas(void)
{
    SL_CHECK_NEAR(pref_sphere_area(0.5), PI, 1e-15);
    SL_CHECK_NEAR(pref_torus_area(0.55, 0.2), 4 * PI * PI * 0.11, 1e-15);
    const double sphere[3] = {0.6, 0.6, 0.6};
    SL_CHECK_NEAR(pref_ellipsoid_area(sphere) / pref_sphere_area(0.6), 1.0, 1e-13);
    /* Prolate (a = b < c): 2πa²(1 + c/(a e) asin e), e² = 1 − a²/c². */
    double a = 0.3, c = 0.9, e = sqrt(1 - a * a / (c * c));
    const double prolate[3] = {a, a, c};
    double want = 2 * PI * a * a * (1 + c / (a * e) * asin(e));
    SL_CHECK_NEAR(pref_ellipsoid_area(prolate) / want, 1.0, 1e-12);
    /* Oblate (a = b > c): 2πa²(1 + (1 − e²)/e atanh e), e² = 1 − c²/a². */
    a = 0.9;
    c = 0.2;
    e = sqrt(1 - c * c / (a * a));
    const double oblate[3] = {a, c, a}; /* the short axis along y: the formula is symmetric */
    want = 2 * PI * a * a * (1 + (1 - e * e) / e * atanh(e));
    SL_CHECK_NEAR(pref_ellipsoid_area(oblate) / want, 1.0, 1e-12);
    /* The generator's extreme ratio 19, both ways, and the axis order does not matter. */
    a = 0.05;
    c = 0.95;
    e = sqrt(1 - a * a / (c * c));
    const double needle[3] = {c, a, a};
    SL_CHECK_NEAR(pref_ellipsoid_area(needle) / (2 * PI * a * a * (1 + c / (a * e) * asin(e))), 1.0, 1e-12);
    e = sqrt(1 - a * a / (c * c));
    const double disk[3] = {c, c, a}, disk2[3] = {a, c, c};
    want = 2 * PI * c * c * (1 + (1 - e * e) / e * atanh(e));
    SL_CHECK_NEAR(pref_ellipsoid_area(disk) / want, 1.0, 1e-12);
    SL_CHECK(pref_ellipsoid_area(disk2) == pref_ellipsoid_area(disk));
    /* Triaxial lies between the spheroids through its extreme axes. */
    const double tri[3] = {0.5, 0.4, 0.3}, lo[3] = {0.3, 0.3, 0.3}, hi[3] = {0.5, 0.5, 0.5};
    SL_CHECK(pref_ellipsoid_area(tri) > pref_ellipsoid_area(lo) && pref_ellipsoid_area(tri) < pref_ellipsoid_area(hi));
}

/* ---- nearest neighbours ---- */

static void test_nn(void)
{
    /* A hexagonal patch of spacing d, tilted in 3D: every point's nearest neighbour is at d. */
    enum { ROWS = 30, COLS = 40 };
    const double d = 0.013;
    double *hex = malloc(3 * ROWS * COLS * sizeof *hex);
    size_t n = 0;
    for (int r = 0; r < ROWS; r++)
        for (int c = 0; c < COLS; c++) {
            double x = d * (c + 0.5 * (r & 1)), y = d * r * sqrt(3.0) / 2;
            hex[3 * n] = 0.3 + 0.8 * x;
            hex[3 * n + 1] = -0.2 + y;
            hex[3 * n + 2] = 0.1 + 0.6 * x;
            n++;
        }
    double mean, cv;
    SL_CHECK(pref_nn(hex, n, PREF_NN_BRUTE, &mean, &cv, NULL) == 0);
    SL_CHECK_NEAR(mean, d, 1e-15);
    SL_CHECK_NEAR(cv, 0.0, 1e-12);
    double ratio = pref_packing_ratio(n, mean, (double)n * sqrt(3.0) / 2 * d * d);
    SL_CHECK_NEAR(ratio, PI / (2 * sqrt(3.0)), 1e-12);
    SL_CHECK_NEAR(ratio, 0.9069, 1e-4);
    SL_CHECK(pref_nn(hex, n, PREF_NN_GRID, &mean, &cv, NULL) == 0);
    SL_CHECK_NEAR(mean, d, 1e-15);
    /* Moving one point off the lattice makes cv non-zero. */
    hex[3 * 500] += 0.3 * d;
    SL_CHECK(pref_nn(hex, n, PREF_NN_AUTO, &mean, &cv, NULL) == 0 && cv > 1e-3);
    free(hex);

    /* Random points on a sphere, a plane (flat z) and a few duplicates: grid == brute force exactly. */
    uint64_t rng = 9;
    enum { M = 3000 };
    double *pts = malloc(3 * M * sizeof *pts), *db = malloc(M * sizeof *db), *dg = malloc(M * sizeof *dg);
    for (int set = 0; set < 2; set++) {
        for (int i = 0; i < M; i++) {
            double z = 2 * uniform(&rng) - 1, ph = 2 * PI * uniform(&rng), s = sqrt(1 - z * z);
            if (set == 0) {
                pts[3 * i] = 0.7 * s * cos(ph);
                pts[3 * i + 1] = 0.7 * s * sin(ph);
                pts[3 * i + 2] = 0.7 * z;
            } else {
                pts[3 * i] = uniform(&rng);
                pts[3 * i + 1] = 3 * uniform(&rng);
                pts[3 * i + 2] = 0.25;
            }
        }
        memcpy(pts + 3 * 17, pts + 3 * 1000, 3 * sizeof *pts); /* a duplicate: distance 0 */
        for (int a = 0; a < 3; a++)
            pts[3 * (M - 1) + a] = 1.5; /* an outlier many cells from everything: the ring search must go on */
        double mb, cb, mg, cg;
        SL_CHECK(pref_nn(pts, M, PREF_NN_BRUTE, &mb, &cb, db) == 0);
        SL_CHECK(pref_nn(pts, M, PREF_NN_GRID, &mg, &cg, dg) == 0);
        SL_CHECK_MSG(memcmp(db, dg, M * sizeof *db) == 0, "set %d: grid and brute force differ", set);
        SL_CHECK(mb == mg && cb == cg && db[17] == 0.0 && db[1000] == 0.0);
        SL_CHECK(mb > 0.0 && cb > 0.1 && db[M - 1] > 0.5);
        double ma, ca;
        SL_CHECK(pref_nn(pts, M, PREF_NN_AUTO, &ma, &ca, NULL) == 0 && ma == mg);
    }
    free(pts);
    free(db);
    free(dg);
    const double one[3] = {0, 0, 0}, bad[6] = {0, 0, 0, NAN, 0, 0};
    SL_CHECK(pref_nn(one, 1, PREF_NN_AUTO, &mean, &cv, NULL) == -1);
    SL_CHECK(pref_nn(bad, 2, PREF_NN_AUTO, &mean, &cv, NULL) == -1);
}

/* ---- placement count ---- */

static double centre_spike(int i, int j, int k)
{
    return i == 1 && j == 1 && k == 1 ? 1.0 : 0.0;
}

static double plane_spike(int i, int j, int k)
{
    (void)k;
    return i == 1 && j == 1 ? 1.0 : 0.0;
}

static double x_ramp(int i, int j, int k)
{
    (void)j;
    (void)k;
    return (double)i;
}

static void test_placement_count(void)
{
    sl_volume v = make_volume(3, 3, 3, centre_spike);
    /* s = 1: the 6 edges from the centre voxel. */
    SL_CHECK(pref_placement_count(&v, 0.5, 1.0) == 6);
    /* s = 2: only the corners, all 0. */
    SL_CHECK(pref_placement_count(&v, 0.5, 2.0) == 0);
    /* s = 0.5: f = Π(1 − |d|) ≥ 0.5 at the centre and the 6 points 0.5 away on the axes (f = iso counts
     * as above); each of those 6 has 5 lattice neighbours below: 30. */
    SL_CHECK(pref_placement_count(&v, 0.5, 0.5) == 30);
    /* Half-open rule: at iso 1 only the centre is "above", its 6 edges cross; at iso 1 + tiny none. */
    SL_CHECK(pref_placement_count(&v, 1.0, 1.0) == 6);
    SL_CHECK(pref_placement_count(&v, 1.0 + 1e-9, 1.0) == 0);
    /* A NaN voxel drops exactly its own edges (a zero-weight NaN tap does not spread). */
    ((float *)v.data)[0 + 3 * (1 + 3 * 1)] = NAN; /* voxel (0, 1, 1), a neighbour of the centre */
    SL_CHECK(pref_placement_count(&v, 0.5, 1.0) == 5);
    free(v.data);
    v = make_volume(3, 3, 3, centre_spike);
    ((float *)v.data)[2 + 3 * (2 + 3 * 2)] = NAN; /* voxel (2, 2, 2): weight 0 in the centre's cell */
    SL_CHECK(pref_placement_count(&v, 0.5, 1.0) == 6);
    free(v.data);

    /* A ramp along x over 7×4×5 voxels at s = 1.5: lattice x = 0, 1.5, 3, 4.5 (n_x = 4, the next at 6
     * is the last voxel: included), y = 0, 1.5, 3 (n_y = 2), z = 0, 1.5, 3 (n_z = 2). iso 2.2: one x edge
     * per (y, z) line crosses: 3·3 = 9, no y or z edge. */
    sl_volume ramp = make_volume(7, 4, 5, x_ramp);
    SL_CHECK(pref_placement_count(&ramp, 2.2, 1.5) == 9);
    SL_CHECK(pref_placement_count(&ramp, 5.9, 1.5) == 9);  /* between 4.5 and 6 */
    SL_CHECK(pref_placement_count(&ramp, 6.0, 1.5) == 9);  /* f = iso is "above": the edge 4.5 -> 6 still crosses */
    SL_CHECK(pref_placement_count(&ramp, 6.0 + 1e-9, 1.5) == 0);
    SL_CHECK(pref_placement_count(&ramp, 2.2, 7.0) == 0);  /* one lattice point per axis */
    free(ramp.data);

    /* One slice in z: no z edges. */
    sl_volume flat = make_volume(3, 3, 1, plane_spike);
    SL_CHECK(pref_placement_count(&flat, 0.5, 1.0) == 4);
    sl_volume slab = make_volume(3, 3, 1, x_ramp);
    SL_CHECK(pref_placement_count(&slab, 0.5, 1.0) == 3);
    free(flat.data);
    free(slab.data);
}

/* ---- CSV ---- */

static char csv_path[64];

static void write_text(const char *text)
{
    FILE *fp = fopen(csv_path, "wb");
    SL_CHECK(fp != NULL);
    if (fp) {
        fputs(text, fp);
        fclose(fp);
    }
}

static void expect_csv_error(const char *text, const char *needle1, const char *needle2)
{
    write_text(text);
    pref_csv_row *rows = (pref_csv_row *)&rows;
    size_t count = 99;
    char err[256] = "";
    int rc = pref_csv_read(csv_path, &rows, &count, err, sizeof err);
    SL_CHECK_MSG(rc == -1 && rows == NULL && count == 0, "accepted: %s", text);
    SL_CHECK_MSG(strstr(err, needle1) != NULL, "message '%s' lacks '%s'", err, needle1);
    SL_CHECK_MSG(!needle2 || strstr(err, needle2) != NULL, "message '%s' lacks '%s'", err, needle2);
    if (rows != (pref_csv_row *)&rows)
        free(rows);
}

static void test_csv(void)
{
    snprintf(csv_path, sizeof csv_path, "/tmp/test_particles_reference_%ld.csv", (long)getpid());
    /* Round trip: rows written with %.17g come back bit-identical. */
    uint64_t rng = 2;
    enum { N = 50 };
    pref_csv_row want[N];
    FILE *fp = fopen(csv_path, "wb");
    SL_CHECK(fp != NULL);
    if (!fp)
        return;
    fprintf(fp, "%s\n", PREF_CSV_HEADER);
    for (int i = 0; i < N; i++) {
        want[i].set = i % 4;
        for (int a = 0; a < 3; a++) {
            want[i].p[a] = uniform(&rng) * 100 - 50;
            want[i].n[a] = uniform(&rng) * 2 - 1;
        }
        want[i].k1 = uniform(&rng) * 10;
        want[i].k2 = -uniform(&rng) * 1e-5;
        want[i].reliability = uniform(&rng);
        fprintf(fp, "%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g%s", want[i].set, want[i].p[0],
                want[i].p[1], want[i].p[2], want[i].n[0], want[i].n[1], want[i].n[2], want[i].k1, want[i].k2,
                want[i].reliability, i == 7 ? "\r\n" : (i == N - 1 ? "" : "\n")); /* a CRLF line, no final newline */
    }
    fclose(fp);
    pref_csv_row *rows = NULL;
    size_t count = 0;
    char err[256] = "";
    SL_CHECK_MSG(pref_csv_read(csv_path, &rows, &count, err, sizeof err) == 0, "%s", err);
    SL_CHECK(count == N && rows != NULL);
    int same = 1;
    for (size_t i = 0; rows && i < count && i < N; i++)
        same &= rows[i].set == want[i].set && memcmp(rows[i].p, want[i].p, sizeof want[i].p) == 0 &&
                memcmp(rows[i].n, want[i].n, sizeof want[i].n) == 0 && rows[i].k1 == want[i].k1 &&
                rows[i].k2 == want[i].k2 && rows[i].reliability == want[i].reliability;
    SL_CHECK(same);
    free(rows);
    /* Header only: 0 rows. */
    write_text(PREF_CSV_HEADER "\n");
    rows = (pref_csv_row *)&rows;
    SL_CHECK(pref_csv_read(csv_path, &rows, &count, err, sizeof err) == 0 && count == 0 && rows == NULL);

    expect_csv_error("", "line 1", "header");
    expect_csv_error("set,x,y,z,nx,ny,nz,k1,k2\n", "line 1", "header");
    expect_csv_error("set,x,y,z,nx,ny,nz,k1,k2,reliability,extra\n", "line 1", "header");
    expect_csv_error(PREF_CSV_HEADER "\n1,0.5,0.25,-3,0,0,1,0.1,-0.2\n", "line 2", "9 columns, want 10");
    expect_csv_error(PREF_CSV_HEADER "\n1,0.5,0.25,-3,0,0,1,0.1,-0.2,0.9,7\n", "line 2", "11 columns, want 10");
    expect_csv_error(PREF_CSV_HEADER "\n1,0.5,0.25,-3,0,0,1,0.1,-0.2,0.9\n2,nan,0,0,0,0,1,0,0,0\n", "line 3",
                     "not finite");
    expect_csv_error(PREF_CSV_HEADER "\n0,0,0,0,0,0,1,inf,0,0\n", "line 2", "column 8");
    expect_csv_error(PREF_CSV_HEADER "\n0,0,0,0,0,0,1,1e999,0,0\n", "line 2", "not finite");
    expect_csv_error(PREF_CSV_HEADER "\n4,0,0,0,0,0,1,0,0,0\n", "line 2", "0..3");
    expect_csv_error(PREF_CSV_HEADER "\n1.5,0,0,0,0,0,1,0,0,0\n", "line 2", "0..3");
    expect_csv_error(PREF_CSV_HEADER "\n-1,0,0,0,0,0,1,0,0,0\n", "line 2", "0..3");
    expect_csv_error(PREF_CSV_HEADER "\n0,abc,0,0,0,0,1,0,0,0\n", "line 2", "not a number");
    expect_csv_error(PREF_CSV_HEADER "\n0,1x,0,0,0,0,1,0,0,0\n", "line 2", "not a number");
    expect_csv_error(PREF_CSV_HEADER "\n0,,0,0,0,0,1,0,0,0\n", "line 2", "not a number");
    expect_csv_error(PREF_CSV_HEADER "\n0,0,0,0,0,0,1,0,0,0\n\n0,0,0,0,0,0,1,0,0,0\n", "line 3", "blank");
    unlink(csv_path);
    rows = (pref_csv_row *)&rows;
    SL_CHECK(pref_csv_read(csv_path, &rows, &count, err, sizeof err) == -1 && rows == NULL && strstr(err, "cannot open"));
}

/* ---- with the ellipsoid generator ---- */

static sl_dataset *generate(const char *json)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    SL_CHECK_MSG(sl_generate_json(json, &ds, &err) == SL_OK, "%s: %s", json, err.message);
    return ds;
}

/* The references on gen_ellipsoid's data: the seed count against 1.5·A/h² for a sphere, the u16
 * isovalue mapping of the generator's header, and B-spline curvature (voxel → world) against the
 * analytic ellipsoid on an anisotropic grid. */
static void test_on_generated(void)
{
    sl_dataset *f32 = generate("{\"generator\":\"ellipsoid\",\"size\":65}");
    sl_dataset *u16 = generate("{\"generator\":\"ellipsoid\",\"size\":65,\"voxel_type\":\"u16\"}");
    if (f32 && u16) {
        /* iso 0.5: a sphere of radius (1 − 0.5)·0.6 = 0.3, h = 1/32 world. */
        uint64_t n_f = pref_placement_count(&f32->volume, 0.5, 1.0);
        uint64_t n_u = pref_placement_count(&u16->volume, (0.5 + 1.5) / 2.5 * 65535.0, 1.0);
        double expect = 1.5 * pref_sphere_area(0.3) * 32.0 * 32.0;
        printf("ellipsoid sphere r 0.3 at 65^3: %llu seeds f32, %llu u16, 1.5 A/h^2 = %.0f\n", (unsigned long long)n_f,
               (unsigned long long)n_u, expect);
        SL_CHECK(fabs((double)n_f - expect) < 0.03 * expect);
        SL_CHECK(llabs((long long)n_f - (long long)n_u) <= 5);
        SL_CHECK(pref_placement_count(&f32->volume, 0.25, 2.0) > 0);
    }
    sl_dataset_destroy(f32);
    sl_dataset_destroy(u16);

    sl_dataset *ds = generate("{\"generator\":\"ellipsoid\",\"size\":97,\"a\":0.8,\"b\":0.6,\"c\":0.5,\"anisotropy\":2}");
    if (ds) {
        const double axes[3] = {0.8 * 0.75, 0.6 * 0.75, 0.5 * 0.75}; /* iso 0.25 */
        const double org[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
        uint64_t rng = 4;
        double worst = 0.0, worst_f = 0.0;
        for (int s = 0; s < 200; s++) {
            double th = 0.2 + 2.7 * uniform(&rng), ph = 2 * PI * uniform(&rng);
            double p[3] = {axes[0] * sin(th) * cos(ph), axes[1] * sin(th) * sin(ph), axes[2] * cos(th)}, u[3];
            for (int a = 0; a < 3; a++)
                u[a] = (p[a] - org[a]) / ds->volume.spacing[a];
            double f, g[3], H[9], k1, k2, r1, r2, ft;
            SL_CHECK(pref_bspline(&ds->volume, u, &f, g, H) == 0);
            SL_CHECK(pref_trilinear(&ds->volume, u, &ft, NULL) == 0);
            worst_f = fmax(worst_f, fabs(ft - 0.25));
            pref_voxel_to_world(ds->volume.spacing, g, H, g, H);
            SL_CHECK(pref_curvature(g, H, &k1, &k2, NULL) == 0);
            SL_CHECK(pref_ellipsoid_curvature(axes, p, &r1, &r2, NULL) == 0);
            worst = fmax(worst, fmax(fabs(k1 - r1) / r1, fabs(k2 - r2) / r2));
        }
        printf("B-spline curvature on a 97x97x49 ellipsoid (iso 0.25): worst rel %.3g; trilinear |f - iso| %.3g\n",
               worst, worst_f);
        SL_CHECK(worst < 0.02);   /* measured 0.5 % */
        SL_CHECK(worst_f < 0.005); /* measured 0.0013 */
    }
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_bspline_weights();
    test_bspline_fields();
    test_trilinear();
    test_voxel_to_world();
    test_curvature_analytic();
    test_ellipsoid_curvature();
    test_torus();
    test_shape_index();
    test_ellipsoid_nearest();
    test_areas();
    test_nn();
    test_placement_count();
    test_csv();
    test_on_generated();
    SL_TEST_END();
}
