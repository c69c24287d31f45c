/* tubes_sweep.c — tubes_sweep.h: the quadratic sphere sweep in double (sampling, golden
 * section, Newton), for the CPU execution of `tubes`. */
#include <math.h>

#include "tubes_sweep.h"

/* Largest radius x curvature handed to Embree's round curves: at 0.37 its intersector lost
 * hits in the middle of a bend (random set seed 1, 0.9 world units of depth); 0.2 lost none
 * in any test scene. Bends beyond it are exact user primitives. */
#define SL_TUBES_SWEEP_MAX_BEND 0.2

#define GOLDEN_STEPS 48
#define GOLDEN_COARSE 12 /* golden steps before Newton takes over */
#define GOLDEN_WIDTH 1e-9 /* in t: l is flat at its minimum, so its error is far below that */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
/* min / max of numbers known not to be NaN, inline (libm's fmin / fmax are calls on x86-64) */
static double min2(double a, double b) { return a < b ? a : b; }
static double max2(double a, double b) { return a > b ? a : b; }
static double clamp01(double t) { return t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t; }

void sl_tubes_sweep_eval(const sl_tubes_sweep *s, double t, double c[3], double *r)
{
    double u = 1.0 - t, w0 = u * u, w1 = 2.0 * u * t, w2 = t * t;
    for (int k = 0; k < 3; k++)
        c[k] = w0 * s->b[0][k] + w1 * s->b[1][k] + w2 * s->b[2][k];
    *r = fabs(w0 * s->r[0] + w1 * s->r[1] + w2 * s->r[2]);
}

/* Centre, radius and their derivatives at t (signed radius). */
static void eval_d(const sl_tubes_sweep *s, double t, double c[3], double dc[3], double *r, double *dr)
{
    double u = 1.0 - t;
    for (int k = 0; k < 3; k++) {
        c[k] = u * u * s->b[0][k] + 2.0 * u * t * s->b[1][k] + t * t * s->b[2][k];
        dc[k] = 2.0 * (u * (s->b[1][k] - s->b[0][k]) + t * (s->b[2][k] - s->b[1][k]));
    }
    *r = u * u * s->r[0] + 2.0 * u * t * s->r[1] + t * t * s->r[2];
    *dr = 2.0 * (u * (s->r[1] - s->r[0]) + t * (s->r[2] - s->r[1]));
}

/* Entry distance into the sphere of parameter t; 0 when the ray misses it (*ok = 0). */
static double entry_at(const sl_tubes_sweep *s, const double o[3], const double d[3], double t, int *ok)
{
    double c[3], r;
    sl_tubes_sweep_eval(s, t, c, &r);
    double q[3] = {c[0] - o[0], c[1] - o[1], c[2] - o[2]};
    double a = dot3(d, q);
    double disc = r * r - (dot3(q, q) - a * a);
    *ok = disc >= 0.0;
    return *ok ? a - sqrt(disc) : 0.0;
}

/* l'(t) where the sphere of t is hit; *ok = 0 where it is not (or tangent). */
static double entry_slope(const sl_tubes_sweep *s, const double o[3], const double d[3], double t, double *l,
                          int *ok)
{
    double c[3], dc[3], r, dr;
    eval_d(s, t, c, dc, &r, &dr);
    double q[3] = {c[0] - o[0], c[1] - o[1], c[2] - o[2]};
    double a = dot3(d, q), da = dot3(d, dc);
    double disc = r * r - (dot3(q, q) - a * a);
    *ok = disc > 0.0;
    if (!*ok)
        return 0.0;
    double root = sqrt(disc);
    double ddisc = 2.0 * r * dr - (2.0 * dot3(q, dc) - 2.0 * a * da);
    *l = a - root;
    return da - ddisc / (2.0 * root);
}

int sl_tubes_sweep_regular(const sl_tubes_sweep *s)
{
    if (!(s->r[0] > 0.0 && s->r[1] > 0.0 && s->r[2] > 0.0))
        return 0;
    /* c'(t) = A + t B, r'(t) = alpha + t beta (linear); c'' = B, so c' x c'' = A x B. */
    double A[3], B[3];
    for (int k = 0; k < 3; k++) {
        A[k] = 2.0 * (s->b[1][k] - s->b[0][k]);
        B[k] = 2.0 * (s->b[2][k] - 2.0 * s->b[1][k] + s->b[0][k]);
    }
    double alpha = 2.0 * (s->r[1] - s->r[0]), beta = 2.0 * (s->r[2] - 2.0 * s->r[1] + s->r[0]);
    /* |c'|^2 - 1.1025 r'^2 = a t^2 + b t + c: its minimum on [0, 1] must be > 0 */
    double qa = dot3(B, B) - 1.1025 * beta * beta, qb = 2.0 * (dot3(A, B) - 1.1025 * alpha * beta),
           qc = dot3(A, A) - 1.1025 * alpha * alpha;
    double cand[3] = {0.0, 1.0, qa != 0.0 ? -qb / (2.0 * qa) : 0.0};
    for (int i = 0; i < 3; i++) {
        double t = cand[i];
        if (t < 0.0 || t > 1.0)
            continue;
        if (!((qa * t + qb) * t + qc > 0.0))
            return 0;
    }
    /* the smallest speed (where the curvature |A x B| / |c'|^3 is largest) */
    double bb = dot3(B, B), ts = bb > 0.0 ? fmin(fmax(-dot3(A, B) / bb, 0.0), 1.0) : 0.0;
    double v[3] = {A[0] + ts * B[0], A[1] + ts * B[1], A[2] + ts * B[2]};
    double speed2 = dot3(v, v);
    double x[3] = {A[1] * B[2] - A[2] * B[1], A[2] * B[0] - A[0] * B[2], A[0] * B[1] - A[1] * B[0]};
    double rmax = fmax(s->r[0], fmax(s->r[1], s->r[2]));
    if (!(speed2 > 0.0))
        return 0;
    double curvature = sqrt(dot3(x, x)) / (speed2 * sqrt(speed2));
    return rmax * curvature < SL_TUBES_SWEEP_MAX_BEND;
}

/* Polynomials in t in the power basis, coefficient k of t^k. */
static double poly_eval(const double *c, int degree, double t)
{
    double v = c[degree];
    for (int k = degree - 1; k >= 0; k--)
        v = v * t + c[k];
    return v;
}

/* The entry l(t) = a(t) - sqrt(D(t)) from a's and D's power-basis coefficients; *ok = 0 where
 * D < 0 (the sphere of t is missed). */
static double entry_poly(const double A[3], const double D[5], double t, int *ok)
{
    double g = poly_eval(D, 4, t);
    *ok = g >= 0.0;
    return *ok ? poly_eval(A, 2, t) - sqrt(g) : INFINITY;
}

/* Newton on l'(t) = 0 from t0 inside [a, b], l' and l'' from the polynomials:
 *   l' = A' - D' / (2 sqrt D),   l'' = A'' - D'' / (2 sqrt D) + D'^2 / (4 D sqrt D).
 * 1 with the minimum when it converged inside (a, b) to a value no higher than l(t0); 0 when
 * it left the bracket, met a miss or l'' <= 0 (the caller falls back to golden section). */
static int newton_min(const double A[3], const double D[5], double a, double b, double t0, double l0,
                      double *l_best, double *t_best)
{
    double t = t0;
    for (int i = 0; i < 12; i++) {
        double g = D[4], g1 = 0.0, g2 = 0.0;
        for (int k = 3; k >= 0; k--) {
            g2 = g2 * t + g1;
            g1 = g1 * t + g;
            g = g * t + D[k];
        }
        g2 *= 2.0;
        if (!(g > 0.0))
            return 0;
        double root = sqrt(g), a1 = A[1] + 2.0 * A[2] * t, a2 = 2.0 * A[2];
        double d1 = a1 - g1 / (2.0 * root), d2 = a2 - g2 / (2.0 * root) + g1 * g1 / (4.0 * g * root);
        if (!(d2 > 0.0))
            return 0;
        double next = t - d1 / d2;
        if (!(next > a && next < b))
            return 0;
        int done = fabs(next - t) <= 1e-12;
        t = next;
        if (done) {
            int ok;
            double l = entry_poly(A, D, t, &ok);
            if (!ok || !(l <= l0))
                return 0;
            *l_best = l;
            *t_best = t;
            return 1;
        }
    }
    return 0;
}

/* Golden-section minimum of l on [a, b] (misses count as +inf) down to a bracket of
 * GOLDEN_WIDTH in t; 1 when some t hit. */
static int golden_min(const double A[3], const double D[5], double a, double b, double *l_best, double *t_best)
{
    const double g = 0.6180339887498949;
    double x1 = b - g * (b - a), x2 = a + g * (b - a);
    int ok;
    double f1 = entry_poly(A, D, x1, &ok), f2 = entry_poly(A, D, x2, &ok);
    for (int i = 0; i < GOLDEN_STEPS && b - a > GOLDEN_WIDTH; i++) {
        /* once the bracket holds one minimum (a grazing rim can put two in the first one),
         * Newton finishes it in a few steps */
        if (i == GOLDEN_COARSE && newton_min(A, D, a, b, f1 <= f2 ? x1 : x2, fmin(f1, f2), l_best, t_best))
            return 1;
        if (f1 <= f2) {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = entry_poly(A, D, x1, &ok);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = entry_poly(A, D, x2, &ok);
        }
    }
    double t = f1 <= f2 ? x1 : x2, f = f1 <= f2 ? f1 : f2;
    if (!isfinite(f))
        return 0;
    *l_best = f;
    *t_best = t;
    return 1;
}

/* A root of the polynomial in [a, b] where its values at the ends have opposite signs (or one
 * is zero): Newton inside the shrinking bracket, bisection where a step would leave it, until
 * the step or the bracket is below 1e-15 (t lies in [0, 1]). */
static double poly_root(const double *c, int degree, double a, double b)
{
    double fa = poly_eval(c, degree, a);
    if (fa == 0.0)
        return a;
    double x = 0.5 * (a + b);
    for (int i = 0; i < 100; i++) {
        double f = c[degree], df = 0.0;
        for (int k = degree - 1; k >= 0; k--) {
            df = df * x + f;
            f = f * x + c[k];
        }
        if (f == 0.0)
            return x;
        if ((f < 0.0) == (fa < 0.0)) {
            a = x;
            fa = f;
        } else {
            b = x;
        }
        double next = x - f / df;
        if (!(next > a && next < b))
            next = 0.5 * (a + b);
        if (fabs(next - x) <= 1e-15 || b - a <= 1e-15)
            return next;
        x = next;
    }
    return x;
}

/* Knots on [0, 1] between which the polynomial of `degree` (<= 4) is monotone: 0, the roots
 * of its derivative (recursively), 1. Returns the knot count (<= degree + 1). */
static int monotone_knots(const double *c, int degree, double knots[6])
{
    if (degree <= 1) {
        knots[0] = 0.0;
        knots[1] = 1.0;
        return 2;
    }
    if (degree == 2) { /* the derivative is linear: its root in closed form */
        int n = 0;
        knots[n++] = 0.0;
        double t = c[2] != 0.0 ? -c[1] / (2.0 * c[2]) : -1.0;
        if (t > 0.0 && t < 1.0)
            knots[n++] = t;
        knots[n++] = 1.0;
        return n;
    }
    double dc[4];
    for (int k = 1; k <= degree; k++)
        dc[k - 1] = k * c[k];
    double dk[6];
    int n = monotone_knots(dc, degree - 1, dk), out = 0;
    knots[out++] = 0.0;
    for (int i = 0; i + 1 < n; i++) {
        double fa = poly_eval(dc, degree - 1, dk[i]), fb = poly_eval(dc, degree - 1, dk[i + 1]);
        if ((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0))
            knots[out++] = poly_root(dc, degree - 1, dk[i], dk[i + 1]);
    }
    knots[out++] = 1.0;
    return out;
}

/* D(t) = r(t)^2 - |q(t)|^2 + (d.q(t))^2, q = c - o: the ray meets the sphere of t where D >= 0;
 * A(t) = d.q(t). Power basis. */
static void discriminant(const sl_tubes_sweep *s, const double o[3], const double d[3], double D[5], double A[3])
{
    double Q[3][3], R[3] = {s->r[0], 2.0 * (s->r[1] - s->r[0]), s->r[0] - 2.0 * s->r[1] + s->r[2]};
    for (int k = 0; k < 3; k++) {
        Q[0][k] = s->b[0][k] - o[k];
        Q[1][k] = 2.0 * (s->b[1][k] - s->b[0][k]);
        Q[2][k] = s->b[0][k] - 2.0 * s->b[1][k] + s->b[2][k];
    }
    for (int i = 0; i < 3; i++)
        A[i] = dot3(d, Q[i]);
    for (int k = 0; k < 5; k++)
        D[k] = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            D[i + j] += R[i] * R[j] - dot3(Q[i], Q[j]) + A[i] * A[j];
}

/* Squared distance from the origin to the segment [p, q] (3D points). */
static double segment_distance2(const double p[3], const double q[3])
{
    double e[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    double ee = dot3(e, e), s = ee > 0.0 ? clamp01(-dot3(p, e) / ee) : 0.0;
    double x[3] = {p[0] + s * e[0], p[1] + s * e[1], p[2] + s * e[2]};
    return dot3(x, x);
}

/* 0 when the ray surely misses every entry in [l_min, l_max): the centre curve lies in the
 * triangle of its controls and the radius below the largest |control|, so the sweep lies in
 * that triangle grown by r_max. Across the ray: the triangle projected on the plane normal to
 * d is farther than r_max from the ray (distance to its edges, the ray's point not inside it).
 * Along it: an entry l(t) = d.q - sqrt(...) is at most the largest d.q of the controls and at
 * least the smallest less r_max. Conservative by a relative 1e-9. */
static int sweep_may_hit(const sl_tubes_sweep *s, const double o[3], const double d[3], double l_min,
                         double l_max)
{
    double rmax = max2(fabs(s->r[0]), max2(fabs(s->r[1]), fabs(s->r[2]))), a[3], p[3][3];
    for (int i = 0; i < 3; i++) {
        double q[3] = {s->b[i][0] - o[0], s->b[i][1] - o[1], s->b[i][2] - o[2]};
        a[i] = dot3(d, q);
        for (int k = 0; k < 3; k++)
            p[i][k] = q[k] - a[i] * d[k];
    }
    double slack = 1e-9 * (rmax + max2(fabs(a[0]), max2(fabs(a[1]), fabs(a[2]))));
    if (!(max2(a[0], max2(a[1], a[2])) + slack >= l_min) || min2(a[0], min2(a[1], a[2])) - rmax - slack >= l_max)
        return 0;
    /* the ray's point inside the projected triangle: the three edge sides agree (a degenerate
     * triangle has zero sides and counts as inside) */
    double side[3];
    for (int i = 0; i < 3; i++) {
        const double *u = p[i], *v = p[(i + 1) % 3];
        double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        side[i] = dot3(x, d);
    }
    if ((side[0] >= 0.0 && side[1] >= 0.0 && side[2] >= 0.0) || (side[0] <= 0.0 && side[1] <= 0.0 && side[2] <= 0.0))
        return 1;
    double dist2 = min2(segment_distance2(p[0], p[1]), min2(segment_distance2(p[1], p[2]), segment_distance2(p[2], p[0])));
    double reach = rmax + slack;
    return dist2 <= reach * reach;
}

int sl_tubes_sweep_intersect(const sl_tubes_sweep *s, const double o[3], const double d[3], double l_min,
                             double l_max, double *l, double *t)
{
    if (!sweep_may_hit(s, o, d, l_min, l_max))
        return 0;
    /* about the ray's point level with the middle control: |q| is then of the piece's size,
     * not the eye's distance, and D = r^2 - |q|^2 + (d.q)^2 loses nothing to cancellation */
    double shift = d[0] * (s->b[1][0] - o[0]) + d[1] * (s->b[1][1] - o[1]) + d[2] * (s->b[1][2] - o[2]);
    double os[3] = {o[0] + shift * d[0], o[1] + shift * d[1], o[2] + shift * d[2]};
    double D[5], A[3], knots[6], ends[12];
    discriminant(s, os, d, D, A);
    int nk = monotone_knots(D, 4, knots), ne = 0;
    /* the roots of D split [0, 1] into intervals of one sign */
    ends[ne++] = 0.0;
    for (int i = 0; i + 1 < nk; i++) {
        double fa = poly_eval(D, 4, knots[i]), fb = poly_eval(D, 4, knots[i + 1]);
        if ((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0))
            ends[ne++] = poly_root(D, 4, knots[i], knots[i + 1]);
    }
    ends[ne++] = 1.0;
    double lo_l = l_min - shift, best = l_max - shift, best_t = 0.0;
    int found = 0;
    for (int iv = 0; iv + 1 < ne; iv++) {
        double ta = ends[iv], tb = ends[iv + 1];
        if (!(tb > ta) || !(poly_eval(D, 4, 0.5 * (ta + tb)) > 0.0))
            continue;
        /* l on [ta, tb]: the sampled minima, polished by golden section; the piece's ends are
         * entries of their own (its end spheres) */
        enum { M = 32 };
        double f[M + 1];
        int ok[M + 1];
        /* branch-free, so that the compiler can evaluate several samples at once */
        for (int i = 0; i <= M; i++) {
            double ts = ta + (tb - ta) * i / M;
            double g = (((D[4] * ts + D[3]) * ts + D[2]) * ts + D[1]) * ts + D[0];
            double e = (A[2] * ts + A[1]) * ts + A[0] - sqrt(g >= 0.0 ? g : 0.0);
            f[i] = g >= 0.0 ? e : INFINITY;
        }
        for (int i = 0; i <= M; i++)
            ok[i] = f[i] < INFINITY;
        for (int i = 0; i <= M; i++) {
            double ti = ta + (tb - ta) * i / M;
            if (!ok[i])
                continue;
            if ((i == 0 && ta == 0.0) || (i == M && tb == 1.0)) {
                if (f[i] >= lo_l && f[i] < best) {
                    best = f[i];
                    best_t = ti;
                    found = 1;
                }
            }
            double left = i > 0 ? f[i - 1] : INFINITY, right = i < M ? f[i + 1] : INFINITY;
            if (!(f[i] <= left && f[i] <= right))
                continue;
            double lo = ta + (tb - ta) * (i > 0 ? i - 1 : 0) / M, hi = ta + (tb - ta) * (i < M ? i + 1 : M) / M, lm, tm;
            if (golden_min(A, D, lo, hi, &lm, &tm) && lm >= lo_l && lm < best) {
                best = lm;
                best_t = tm;
                found = 1;
            } else if (f[i] >= lo_l && f[i] < best) {
                best = f[i];
                best_t = ti;
                found = 1;
            }
        }
    }
    if (found) {
        *l = best + shift;
        *t = best_t;
    }
    return found;
}

int sl_tubes_sweep_refine(const sl_tubes_sweep *s, const double o[3], const double d[3], double l_min, double t0,
                          double *l, double *t)
{
    double tc = fmin(fmax(t0, 0.0), 1.0), lc = 0.0;
    int ok, converged = 0;
    const double h = 1e-6;
    for (int i = 0; i < 16 && !converged; i++) {
        double g = entry_slope(s, o, d, tc, &lc, &ok);
        if (!ok)
            return 0;
        if ((tc <= 0.0 && g >= 0.0) || (tc >= 1.0 && g <= 0.0)) {
            converged = 1; /* a minimum at the piece's end */
            break;
        }
        double lp, lm, hi = fmin(tc + h, 1.0), lo = fmax(tc - h, 0.0);
        int okp, okm;
        double gp = entry_slope(s, o, d, hi, &lp, &okp), gm = entry_slope(s, o, d, lo, &lm, &okm);
        if (!okp || !okm)
            return 0;
        double curv = (gp - gm) / (hi - lo);
        /* Newton where l is convex, else a short step downhill; never more than 0.1 */
        double step = curv > 0.0 ? -g / curv : (g > 0.0 ? -0.02 : 0.02);
        step = fmin(fmax(step, -0.1), 0.1);
        double tn = fmin(fmax(tc + step, 0.0), 1.0);
        converged = fabs(tn - tc) < 1e-11;
        tc = tn;
    }
    if (!converged)
        return 0;
    lc = entry_at(s, o, d, tc, &ok);
    if (!ok || !(lc >= l_min))
        return 0;
    *l = lc;
    *t = tc;
    return 1;
}
