/* particles_reference.c — the particle references (see particles_reference.h).
 *
 * Voxels are decoded here from sl_volume's raw array (no renderer accessor). The B-spline
 * weights come from the Cox–de Boor recursion on the knots 0..4, not from the closed cubic
 * polynomials the shader uses; the eigenvectors from cyclic Jacobi on the full 3×3 G, not
 * the shader's 2×2 tangent form. Everything in double; no caching, no threads.
 */
#include "particles_reference.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PREF_PI 3.14159265358979323846

/* ---- voxels ---- */

static int clamp_index(long i, int n)
{
    return i < 0 ? 0 : (i >= n ? n - 1 : (int)i);
}

static double voxel(const sl_volume *vol, int x, int y, int z)
{
    size_t i = ((size_t)z * (size_t)vol->dims[1] + (size_t)y) * (size_t)vol->dims[0] + (size_t)x;
    switch (vol->type) {
    case SL_VOXEL_U8: return (double)((const uint8_t *)vol->data)[i];
    case SL_VOXEL_U16: return (double)((const uint16_t *)vol->data)[i];
    case SL_VOXEL_S16: return (double)((const int16_t *)vol->data)[i];
    case SL_VOXEL_F32: return (double)((const float *)vol->data)[i];
    }
    return NAN;
}

/* ---- trilinear ---- */

int pref_trilinear(const sl_volume *vol, const double u[3], double *f, double g[3])
{
    int lo[3], hi[3];
    double t[3], live[3]; /* live: 1 where the coordinate is inside the axis (gradient flows) */
    for (int a = 0; a < 3; a++) {
        int n = vol->dims[a];
        double c = u[a];
        live[a] = n > 1 && c >= 0.0 && c <= (double)(n - 1);
        if (c < 0.0)
            c = 0.0;
        if (c > (double)(n - 1))
            c = (double)(n - 1);
        if (n == 1) {
            lo[a] = hi[a] = 0;
            t[a] = 0.0;
            continue;
        }
        long cell = (long)floor(c);
        if (cell > n - 2)
            cell = n - 2; /* the last voxel belongs to the cell below */
        lo[a] = (int)cell;
        hi[a] = (int)cell + 1;
        t[a] = c - (double)cell;
    }
    double v[2][2][2];
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++)
                v[k][j][i] = voxel(vol, i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2]);
    /* f = Σ wx wy wz v with w(0) = 1 − t, w(1) = t, skipping zero weights (so a voxel value
     * is read alone at integer u); ∂/∂t_a replaces w_a by (−1, +1) and uses all 8 taps. */
    double sum = 0.0, grad[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++) {
                double wx = i ? t[0] : 1.0 - t[0], wy = j ? t[1] : 1.0 - t[1], wz = k ? t[2] : 1.0 - t[2];
                double dx = i ? 1.0 : -1.0, dy = j ? 1.0 : -1.0, dz = k ? 1.0 : -1.0;
                if (wx * wy * wz != 0.0)
                    sum += wx * wy * wz * v[k][j][i];
                grad[0] += dx * wy * wz * v[k][j][i];
                grad[1] += wx * dy * wz * v[k][j][i];
                grad[2] += wx * wy * dz * v[k][j][i];
            }
    if (isnan(sum)) {
        *f = NAN;
        if (g)
            g[0] = g[1] = g[2] = NAN;
        return -1;
    }
    *f = sum;
    if (g)
        for (int a = 0; a < 3; a++)
            g[a] = live[a] ? grad[a] : 0.0;
    return 0;
}

/* ---- B-spline ---- */

/* N_{0,p}(y) on the uniform knots 0, 1, …, p + 1 (Cox–de Boor). */
static double basis(int p, double y)
{
    if (p == 0)
        return y >= 0.0 && y < 1.0 ? 1.0 : 0.0;
    return (y * basis(p - 1, y) + ((double)p + 1.0 - y) * basis(p - 1, y - 1.0)) / (double)p;
}

void pref_bspline_weights(double t, double w[4], double d1[4], double d2[4])
{
    for (int i = 0; i < 4; i++) {
        double y = t + 1.0 - (double)i + 2.0; /* the centred B(x) is N_{0,3}(x + 2) */
        w[i] = basis(3, y);
        d1[i] = basis(2, y) - basis(2, y - 1.0);                          /* N' = N_{0,2}(y) − N_{0,2}(y − 1) */
        d2[i] = basis(1, y) - 2.0 * basis(1, y - 1.0) + basis(1, y - 2.0); /* applied twice */
    }
}

int pref_bspline(const sl_volume *vol, const double u[3], double *f, double g[3], double H[9])
{
    double w[3][3][4]; /* [axis][derivative order][tap] */
    long base[3];
    for (int a = 0; a < 3; a++) {
        double fl = floor(u[a]);
        base[a] = (long)fl - 1;
        pref_bspline_weights(u[a] - fl, w[a][0], w[a][1], w[a][2]);
    }
    double sum = 0.0, grad[3] = {0, 0, 0}, hess[9] = {0};
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                double v = voxel(vol, clamp_index(base[0] + i, vol->dims[0]), clamp_index(base[1] + j, vol->dims[1]),
                                 clamp_index(base[2] + k, vol->dims[2]));
                if (isnan(v)) {
                    *f = NAN;
                    for (int c = 0; g && c < 3; c++)
                        g[c] = NAN;
                    for (int c = 0; H && c < 9; c++)
                        H[c] = NAN;
                    return -1;
                }
                const int tap[3] = {i, j, k};
                sum += w[0][0][i] * w[1][0][j] * w[2][0][k] * v;
                for (int a = 0; a < 3; a++) {
                    double prod = v;
                    for (int c = 0; c < 3; c++)
                        prod *= w[c][c == a][tap[c]];
                    grad[a] += prod;
                    for (int b = 0; b < 3; b++) {
                        double ph = v;
                        for (int c = 0; c < 3; c++)
                            ph *= w[c][(c == a) + (c == b)][tap[c]];
                        hess[3 * a + b] += ph;
                    }
                }
            }
    *f = sum;
    if (g)
        memcpy(g, grad, sizeof grad);
    if (H)
        memcpy(H, hess, sizeof hess);
    return 0;
}

void pref_voxel_to_world(const double spacing[3], const double g_u[3], const double H_u[9], double g_x[3],
                         double H_x[9])
{
    double g[3], H[9];
    for (int a = 0; a < 3; a++) {
        g[a] = g_u ? g_u[a] / spacing[a] : 0.0;
        for (int b = 0; b < 3; b++)
            H[3 * a + b] = H_u ? H_u[3 * a + b] / (spacing[a] * spacing[b]) : 0.0;
    }
    if (g_x)
        memcpy(g_x, g, sizeof g);
    if (H_x)
        memcpy(H_x, H, sizeof H);
}

/* ---- curvature ---- */

/* C = Aᵀ B (transpose_a) or A B, 3×3 row-major. */
static void mat_mul(const double A[9], const double B[9], int transpose_a, double C[9])
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++)
                s += (transpose_a ? A[3 * k + i] : A[3 * i + k]) * B[3 * k + j];
            r[3 * i + j] = s;
        }
    memcpy(C, r, sizeof r);
}

/* Cyclic Jacobi: A (symmetric, destroyed) → eigenvalues lambda, eigenvectors the columns of V. */
static void jacobi3(double A[9], double lambda[3], double V[9])
{
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(V, identity, sizeof identity);
    for (int sweep = 0; sweep < 100; sweep++) {
        double off = A[1] * A[1] + A[2] * A[2] + A[5] * A[5];
        double diag = A[0] * A[0] + A[4] * A[4] + A[8] * A[8];
        if (off == 0.0 || off <= 1e-40 * diag)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                double apq = A[3 * p + q];
                if (apq == 0.0)
                    continue;
                double theta = (A[3 * q + q] - A[3 * p + p]) / (2.0 * apq);
                double t = fabs(theta) > 1e150 ? 0.5 / theta
                                                : (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                double J[9];
                memcpy(J, identity, sizeof J);
                J[3 * p + p] = c;
                J[3 * q + q] = c;
                J[3 * p + q] = s;
                J[3 * q + p] = -s;
                mat_mul(J, A, 1, A); /* Jᵀ A */
                mat_mul(A, J, 0, A); /* (Jᵀ A) J */
                A[3 * p + q] = A[3 * q + p] = 0.0;
                mat_mul(V, J, 0, V);
            }
    }
    for (int i = 0; i < 3; i++)
        lambda[i] = A[3 * i + i];
}

int pref_curvature(const double g[3], const double H[9], double *k1, double *k2, double e1[3])
{
    *k1 = *k2 = 0.0;
    if (e1)
        e1[0] = e1[1] = e1[2] = 0.0;
    for (int i = 0; i < 9; i++)
        if (!isfinite(H[i]) || (i < 3 && !isfinite(g[i])))
            return -1;
    double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(len > 0.0) || !isfinite(len))
        return -1;
    double n[3] = {-g[0] / len, -g[1] / len, -g[2] / len}, P[9], G[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            P[3 * i + j] = (i == j) - n[i] * n[j];
    mat_mul(P, H, 0, G);
    mat_mul(G, P, 0, G);
    double norm = 0.0;
    for (int i = 0; i < 9; i++) {
        G[i] *= -1.0 / len;
        norm += G[i] * G[i];
    }
    norm = sqrt(norm);
    double shift = norm > 0.0 ? 3.0 * norm : 1.0; /* n's eigenvalue 0 → shift, apart from |κ| ≤ norm */
    double A[9], lambda[3], V[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            A[3 * i + j] = 0.5 * (G[3 * i + j] + G[3 * j + i]) + shift * n[i] * n[j];
    jacobi3(A, lambda, V);
    int drop = 0;
    double best = -1.0;
    for (int c = 0; c < 3; c++) {
        double d = fabs(V[c] * n[0] + V[3 + c] * n[1] + V[6 + c] * n[2]);
        if (d > best) {
            best = d;
            drop = c;
        }
    }
    int a = (drop + 1) % 3, b = (drop + 2) % 3;
    if (lambda[b] > lambda[a]) {
        int s = a;
        a = b;
        b = s;
    }
    *k1 = lambda[a];
    *k2 = lambda[b];
    if (e1) {
        double v[3] = {V[a], V[3 + a], V[6 + a]};
        int big = 0;
        for (int i = 1; i < 3; i++)
            if (fabs(v[i]) > fabs(v[big]))
                big = i;
        double sign = v[big] < 0.0 ? -1.0 : 1.0;
        for (int i = 0; i < 3; i++)
            e1[i] = sign * v[i];
    }
    return 0;
}

double pref_shape_index(double k1, double k2)
{
    if (k1 < k2) {
        double s = k1;
        k1 = k2;
        k2 = s;
    }
    if (k1 == k2)
        return k1 == 0.0 ? NAN : (k1 > 0.0 ? -1.0 : 1.0);
    return 2.0 / PREF_PI * atan((k2 + k1) / (k2 - k1));
}

double pref_reliability(double k1, double k2, double eps)
{
    if (fabs(k1) < eps && fabs(k2) < eps)
        return 0.0;
    return 1.0 - fabs(2.0 * (fabs(pref_shape_index(k1, k2)) - 0.5));
}

/* ---- analytic surfaces ---- */

int pref_ellipsoid_curvature(const double axes[3], const double p[3], double *k1, double *k2, double e1[3])
{
    /* f = −F is bright inside: g = −∇F, H = −∇²F, so n = ∇F/|∇F| points outward. */
    double g[3], H[9] = {0};
    for (int a = 0; a < 3; a++) {
        double inv = 1.0 / (axes[a] * axes[a]);
        g[a] = -2.0 * p[a] * inv;
        H[4 * a] = -2.0 * inv;
    }
    return pref_curvature(g, H, k1, k2, e1);
}

/* Σ (a_i p_i/(a_i² + t))² − 1 over the axes in mask. */
static double lagrange_phi(const double axes[3], const double p[3], int mask, double t)
{
    double s = 0.0;
    for (int i = 0; i < 3; i++)
        if (mask & (1 << i)) {
            double r = axes[i] * p[i] / (axes[i] * axes[i] + t);
            s += r * r;
        }
    return s - 1.0;
}

double pref_ellipsoid_nearest(const double axes[3], const double p[3], double q[3])
{
    int mask = 0, smallest = 0;
    double lo = -INFINITY, amax = 0.0, plen = 0.0;
    for (int i = 0; i < 3; i++) {
        if (axes[i] < axes[smallest])
            smallest = i;
        amax = fmax(amax, axes[i]);
        plen += p[i] * p[i];
        if (p[i] != 0.0) {
            mask |= 1 << i;
            lo = fmax(lo, -axes[i] * axes[i]);
        }
    }
    plen = sqrt(plen);
    double best = INFINITY, cand[3];
    if (mask) {
        /* φ decreases from +∞ at t = lo to −1: bisect until the bracket stops shrinking. */
        double hi = amax * plen;
        for (int it = 0; it < 4000; it++) {
            double mid = 0.5 * (lo + hi);
            if (mid <= lo || mid >= hi)
                break;
            if (lagrange_phi(axes, p, mask, mid) > 0.0)
                lo = mid;
            else
                hi = mid;
        }
        double t = 0.5 * (lo + hi), d2 = 0.0;
        for (int i = 0; i < 3; i++) {
            cand[i] = p[i] == 0.0 ? 0.0 : axes[i] * axes[i] * p[i] / (axes[i] * axes[i] + t);
            d2 += (cand[i] - p[i]) * (cand[i] - p[i]);
        }
        best = sqrt(d2);
        memcpy(q, cand, sizeof cand);
    }
    /* p in the plane of the smallest axis: t = −a_min² may give a nearer point off that plane. */
    if (p[smallest] == 0.0) {
        double am2 = axes[smallest] * axes[smallest], s = 0.0;
        int ok = 1;
        for (int i = 0; i < 3; i++) {
            if (i == smallest)
                continue;
            double den = axes[i] * axes[i] - am2;
            if (p[i] != 0.0 && den <= 0.0) {
                ok = 0;
                break;
            }
            cand[i] = p[i] == 0.0 ? 0.0 : axes[i] * axes[i] * p[i] / den;
            s += (cand[i] / axes[i]) * (cand[i] / axes[i]);
        }
        if (ok && s <= 1.0) {
            cand[smallest] = axes[smallest] * sqrt(1.0 - s);
            double d2 = 0.0;
            for (int i = 0; i < 3; i++)
                d2 += (cand[i] - p[i]) * (cand[i] - p[i]);
            if (sqrt(d2) < best) {
                best = sqrt(d2);
                memcpy(q, cand, sizeof cand);
            }
        }
    }
    return best;
}

/* Ring point nearest p, the unit radial and azimuthal directions; −1 on the axis or the ring. */
static int torus_frame(double R0, const double p[3], double ring[3], double radial[3], double azim[3], double *dist)
{
    double rho = hypot(p[0], p[1]);
    if (!(rho > 0.0))
        return -1;
    radial[0] = p[0] / rho;
    radial[1] = p[1] / rho;
    radial[2] = 0.0;
    azim[0] = -radial[1];
    azim[1] = radial[0];
    azim[2] = 0.0;
    for (int i = 0; i < 3; i++)
        ring[i] = R0 * radial[i];
    *dist = sqrt((p[0] - ring[0]) * (p[0] - ring[0]) + (p[1] - ring[1]) * (p[1] - ring[1]) + p[2] * p[2]);
    return *dist > 0.0 ? 0 : -1;
}

int pref_torus_curvature(double R0, double r, const double p[3], double *k1, double *k2, double e1[3],
                         double main_dir[3])
{
    double ring[3], radial[3], azim[3], d;
    *k1 = *k2 = 0.0;
    if (torus_frame(R0, p, ring, radial, azim, &d) != 0)
        return -1;
    double n[3];
    for (int i = 0; i < 3; i++)
        n[i] = (p[i] - ring[i]) / d;
    double cos_v = n[0] * radial[0] + n[1] * radial[1];
    *k1 = 1.0 / r;
    *k2 = cos_v / (R0 + r * cos_v);
    /* Meridian tangent: azim × n, in the plane of the z axis and p. */
    double mer[3] = {azim[1] * n[2] - azim[2] * n[1], azim[2] * n[0] - azim[0] * n[2], azim[0] * n[1] - azim[1] * n[0]};
    if (e1)
        memcpy(e1, mer, sizeof mer);
    if (main_dir)
        memcpy(main_dir, fabs(*k1) >= fabs(*k2) ? mer : azim, sizeof mer);
    return 0;
}

double pref_torus_nearest(double R0, double r, const double p[3], double q[3])
{
    double ring[3], radial[3], azim[3], d;
    if (torus_frame(R0, p, ring, radial, azim, &d) != 0)
        return NAN;
    for (int i = 0; i < 3; i++)
        q[i] = ring[i] + r * (p[i] - ring[i]) / d;
    return fabs(d - r);
}

double pref_sphere_area(double R)
{
    return 4.0 * PREF_PI * R * R;
}

double pref_torus_area(double R0, double r)
{
    return 4.0 * PREF_PI * PREF_PI * R0 * r;
}

/* Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n from the Chebyshev-like guess). */
static void gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(PREF_PI * ((double)i + 0.75) / ((double)n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; k++) {
                double pk = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / (double)k;
                p0 = p1;
                p1 = pk;
            }
            dp = (double)n * (z * p1 - p0) / (z * z - 1.0);
            double step = p1 / dp;
            z -= step;
            if (fabs(step) < 1e-16)
                break;
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
}

/* Breakpoints 0, ε, 4ε, 16ε, …, hi: panels that shrink toward 0 where the integrand has a
 * feature of width ε. Returns the number of panels (≤ 30). */
static int graded_panels(double eps, double hi, double *b)
{
    int n = 0;
    b[n++] = 0.0;
    for (double t = eps; t < hi && n < 30; t *= 4.0)
        b[n++] = t;
    b[n++] = hi;
    return n - 1;
}

double pref_ellipsoid_area(const double axes[3])
{
    enum { N = 64 };
    double x[N], w[N];
    gauss_legendre(N, x, w);
    double a = axes[0], b = axes[1], c = axes[2], t;
    /* Sorted a ≥ b ≥ c; the pole on the shortest axis. */
    if (a < b) { t = a; a = b; b = t; }
    if (b < c) { t = b; b = c; c = t; }
    if (a < b) { t = a; a = b; b = t; }
    /* One octant, s = cos θ ∈ [0, 1] (dA = sqrt(e) ds dφ), φ ∈ [0, π/2]:
     * e = c²(1 − s²)(b² cos²φ + a² sin²φ) + a²b²s², which varies fast near s = 0 over c/a (the rim)
     * and near φ = 0 over b/a: 64-point panels graded there. */
    double bs[32], bp[32], sum = 0.0;
    int ns = graded_panels(c / a, 1.0, bs), np = graded_panels(b / a, 0.5 * PREF_PI, bp);
    for (int I = 0; I < ns; I++)
        for (int i = 0; i < N; i++) {
            double hs = 0.5 * (bs[I + 1] - bs[I]), sv = bs[I] + hs * (x[i] + 1.0), ws = hs * w[i];
            for (int J = 0; J < np; J++)
                for (int j = 0; j < N; j++) {
                    double hp = 0.5 * (bp[J + 1] - bp[J]), ph = bp[J] + hp * (x[j] + 1.0);
                    double cp = cos(ph), sp = sin(ph);
                    double e = c * c * (1.0 - sv * sv) * (b * b * cp * cp + a * a * sp * sp) + a * a * b * b * sv * sv;
                    sum += ws * hp * w[j] * sqrt(e);
                }
        }
    return 8.0 * sum;
}

/* ---- placement count ---- */

uint64_t pref_placement_count(const sl_volume *vol, double iso, double s)
{
    long n[3];
    for (int a = 0; a < 3; a++)
        n[a] = (long)floor((double)(vol->dims[a] - 1) / s);
    uint64_t count = 0;
    for (long k = 0; k <= n[2]; k++)
        for (long j = 0; j <= n[1]; j++)
            for (long i = 0; i <= n[0]; i++) {
                const long idx[3] = {i, j, k};
                double r[3] = {s * (double)i, s * (double)j, s * (double)k}, f0;
                if (pref_trilinear(vol, r, &f0, NULL) != 0)
                    continue;
                for (int a = 0; a < 3; a++) {
                    if (idx[a] + 1 > n[a])
                        continue;
                    double r1[3] = {r[0], r[1], r[2]}, f1;
                    r1[a] = s * (double)(idx[a] + 1);
                    if (pref_trilinear(vol, r1, &f1, NULL) != 0)
                        continue;
                    count += (f0 < iso) != (f1 < iso);
                }
            }
    return count;
}

/* ---- nearest neighbours ---- */

static double dist2(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
}

static void nn_brute(const double *xyz, size_t n, double *d2)
{
    for (size_t i = 0; i < n; i++)
        d2[i] = INFINITY;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            double d = dist2(xyz + 3 * i, xyz + 3 * j);
            if (d < d2[i])
                d2[i] = d;
            if (d < d2[j])
                d2[j] = d;
        }
}

/* Uniform grid, points sorted by cell (counting sort); per point, rings of cells at Chebyshev
 * distance 0, 1, 2, … until the best distance is at most ring·h (no unvisited cell is nearer). */
static int nn_grid(const double *xyz, size_t n, double *d2)
{
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++)
        lo[a] = hi[a] = xyz[a];
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], xyz[3 * i + a]);
            hi[a] = fmax(hi[a], xyz[3 * i + a]);
        }
    double ext[3], area = 0.0;
    for (int a = 0; a < 3; a++)
        ext[a] = hi[a] - lo[a];
    area = 2.0 * (ext[0] * ext[1] + ext[1] * ext[2] + ext[2] * ext[0]);
    double h = sqrt(area / (double)n); /* points on a surface: a few per cell */
    double emax = fmax(ext[0], fmax(ext[1], ext[2]));
    if (!(h > 0.0))
        h = emax > 0.0 ? emax / cbrt((double)n) : 1.0;
    long cells[3];
    for (;;) {
        double total = 1.0;
        for (int a = 0; a < 3; a++) {
            cells[a] = (long)floor(ext[a] / h) + 1;
            total *= (double)cells[a];
        }
        if (total <= 8.0 * (double)n + 64.0)
            break;
        h *= 1.25;
    }
    size_t ncell = (size_t)(cells[0] * cells[1] * cells[2]);
    size_t *start = calloc(ncell + 1, sizeof *start), *order = malloc(n * sizeof *order),
           *cell_of = malloc(n * sizeof *cell_of);
    if (!start || !order || !cell_of) {
        free(start);
        free(order);
        free(cell_of);
        return -1;
    }
    long (*coord)[3] = malloc(n * sizeof *coord);
    if (!coord) {
        free(start);
        free(order);
        free(cell_of);
        return -1;
    }
    for (size_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) {
            long c = (long)floor((xyz[3 * i + a] - lo[a]) / h);
            coord[i][a] = c < 0 ? 0 : (c >= cells[a] ? cells[a] - 1 : c);
        }
        cell_of[i] = (size_t)((coord[i][2] * cells[1] + coord[i][1]) * cells[0] + coord[i][0]);
        start[cell_of[i] + 1]++;
    }
    for (size_t c = 0; c < ncell; c++)
        start[c + 1] += start[c];
    size_t *fill = malloc(ncell * sizeof *fill);
    if (!fill) {
        free(start);
        free(order);
        free(cell_of);
        free(coord);
        return -1;
    }
    memcpy(fill, start, ncell * sizeof *fill);
    for (size_t i = 0; i < n; i++)
        order[fill[cell_of[i]]++] = i;
    free(fill);
    long reach = cells[0] > cells[1] ? cells[0] : cells[1];
    if (cells[2] > reach)
        reach = cells[2];
    for (size_t i = 0; i < n; i++) {
        double best = INFINITY;
        for (long ring = 0; ring <= reach; ring++) {
            for (long dz = -ring; dz <= ring; dz++)
                for (long dy = -ring; dy <= ring; dy++)
                    for (long dx = -ring; dx <= ring; dx++) {
                        if (labs(dx) != ring && labs(dy) != ring && labs(dz) != ring)
                            continue; /* inner cells were visited in earlier rings */
                        long c[3] = {coord[i][0] + dx, coord[i][1] + dy, coord[i][2] + dz};
                        if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= cells[0] || c[1] >= cells[1] || c[2] >= cells[2])
                            continue;
                        size_t cell = (size_t)((c[2] * cells[1] + c[1]) * cells[0] + c[0]);
                        for (size_t m = start[cell]; m < start[cell + 1]; m++) {
                            size_t j = order[m];
                            if (j == i)
                                continue;
                            double d = dist2(xyz + 3 * i, xyz + 3 * j);
                            if (d < best)
                                best = d;
                        }
                    }
            double reach_dist = (double)ring * h;
            if (best <= reach_dist * reach_dist)
                break;
        }
        d2[i] = best;
    }
    free(start);
    free(order);
    free(cell_of);
    free(coord);
    return 0;
}

int pref_nn(const double *xyz, size_t n, pref_nn_method method, double *mean, double *cv, double *dist)
{
    if (n < 2 || !xyz)
        return -1;
    for (size_t i = 0; i < 3 * n; i++)
        if (!isfinite(xyz[i]))
            return -1;
    double *d2 = malloc(n * sizeof *d2);
    if (!d2)
        return -1;
    if (method == PREF_NN_BRUTE || (method == PREF_NN_AUTO && n < 2000))
        nn_brute(xyz, n, d2);
    else if (nn_grid(xyz, n, d2) != 0) {
        free(d2);
        return -1;
    }
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        d2[i] = sqrt(d2[i]);
        sum += d2[i];
    }
    double m = sum / (double)n, var = 0.0;
    for (size_t i = 0; i < n; i++)
        var += (d2[i] - m) * (d2[i] - m);
    var /= (double)n;
    if (mean)
        *mean = m;
    if (cv)
        *cv = m > 0.0 ? sqrt(var) / m : 0.0;
    if (dist)
        memcpy(dist, d2, n * sizeof *d2);
    free(d2);
    return 0;
}

double pref_packing_ratio(size_t n, double mean, double area)
{
    return (double)n * PREF_PI * 0.25 * mean * mean / area;
}

/* ---- CSV ---- */

static int csv_fail(char *err, size_t size, const char *fmt, ...)
{
    if (err && size) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, size, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* Parses line `line` (NUL-terminated, no line end) into row; fills err on a fault. */
static int csv_row_parse(char *line, size_t number, pref_csv_row *row, char *err, size_t size)
{
    char *fields[11];
    int nf = 0;
    for (char *p = line;;) {
        if (nf < 11)
            fields[nf] = p;
        nf++;
        char *comma = strchr(p, ',');
        if (!comma)
            break;
        *comma = '\0';
        p = comma + 1;
    }
    if (nf != 10)
        return csv_fail(err, size, "line %zu: %d columns, want 10", number, nf);
    double v[10];
    for (int c = 0; c < 10; c++) {
        char *end = NULL;
        errno = 0;
        v[c] = strtod(fields[c], &end);
        if (end == fields[c] || *end != '\0')
            return csv_fail(err, size, "line %zu: column %d \"%.32s\" is not a number", number, c + 1, fields[c]);
        if (!isfinite(v[c]))
            return csv_fail(err, size, "line %zu: column %d \"%.32s\" is not finite", number, c + 1, fields[c]);
    }
    if (v[0] != floor(v[0]) || v[0] < 0.0 || v[0] > 3.0)
        return csv_fail(err, size, "line %zu: set \"%.32s\" is not an integer 0..3", number, fields[0]);
    row->set = (int)v[0];
    for (int a = 0; a < 3; a++) {
        row->p[a] = v[1 + a];
        row->n[a] = v[4 + a];
    }
    row->k1 = v[7];
    row->k2 = v[8];
    row->reliability = v[9];
    return 0;
}

int pref_csv_read(const char *path, pref_csv_row **rows, size_t *count, char *err, size_t err_size)
{
    *rows = NULL;
    *count = 0;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return csv_fail(err, err_size, "%s: cannot open: %s", path, strerror(errno));
    size_t cap = 1 << 16, len = 0;
    char *text = malloc(cap + 1);
    for (size_t got; text && (got = fread(text + len, 1, cap - len, fp)) > 0;) {
        len += got;
        if (len == cap) {
            char *bigger = realloc(text, 2 * cap + 1);
            if (!bigger) {
                free(text);
                text = NULL;
                break;
            }
            text = bigger;
            cap *= 2;
        }
    }
    int read_error = ferror(fp);
    fclose(fp);
    if (!text)
        return csv_fail(err, err_size, "%s: out of memory", path);
    if (read_error) {
        free(text);
        return csv_fail(err, err_size, "%s: read error", path);
    }
    text[len] = '\0';
    if (memchr(text, '\0', len)) {
        free(text);
        return csv_fail(err, err_size, "%s: contains a NUL byte", path);
    }
    size_t lines = 0;
    for (size_t i = 0; i < len; i++)
        lines += text[i] == '\n';
    pref_csv_row *out = malloc((lines + 1) * sizeof *out);
    if (!out) {
        free(text);
        return csv_fail(err, err_size, "%s: out of memory", path);
    }
    size_t n = 0, number = 0;
    int status = 0;
    char *p = text, *stop = text + len;
    while (p < stop || number == 0) {
        number++;
        char *nl = memchr(p, '\n', (size_t)(stop - p));
        char *end = nl ? nl : stop;
        if (end > p && end[-1] == '\r')
            end--;
        *end = '\0';
        if (number == 1) {
            if (strcmp(p, PREF_CSV_HEADER) != 0) {
                status = csv_fail(err, err_size, "%s: line 1: header \"%.80s\", want \"%s\"", path, p, PREF_CSV_HEADER);
                break;
            }
        } else if (*p == '\0') {
            status = csv_fail(err, err_size, "%s: line %zu: blank line", path, number);
            break;
        } else {
            char msg[192];
            if (csv_row_parse(p, number, &out[n], msg, sizeof msg) != 0) {
                status = csv_fail(err, err_size, "%s: %s", path, msg);
                break;
            }
            n++;
        }
        if (!nl)
            break;
        p = nl + 1;
    }
    free(text);
    if (status != 0 || n == 0) {
        free(out);
        out = NULL;
    }
    if (status != 0)
        return status;
    *rows = out;
    *count = n;
    return 0;
}
