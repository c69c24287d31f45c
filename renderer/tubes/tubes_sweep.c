/* tubes_sweep.c — tubes_sweep.h: the quadratic sphere sweep in double (sampling, golden
 * section, Newton), for the CPU execution of `tubes`. */
#include <math.h>

#include "tubes_sweep.h"

#define SWEEP_MAX_SAMPLES 512
#define GOLDEN_STEPS 48

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

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
    double ddc[3];
    for (int k = 0; k < 3; k++)
        ddc[k] = 2.0 * (s->b[2][k] - 2.0 * s->b[1][k] + s->b[0][k]);
    for (int i = 0; i <= 16; i++) {
        double t = i / 16.0, c[3], dc[3], r, dr;
        eval_d(s, t, c, dc, &r, &dr);
        double speed2 = dot3(dc, dc);
        if (!(speed2 >= 1.1025 * dr * dr) || speed2 <= 0.0)
            return 0;
        double x[3] = {dc[1] * ddc[2] - dc[2] * ddc[1], dc[2] * ddc[0] - dc[0] * ddc[2],
                       dc[0] * ddc[1] - dc[1] * ddc[0]};
        double curvature = sqrt(dot3(x, x)) / (speed2 * sqrt(speed2));
        if (!(r * curvature < 0.5))
            return 0;
    }
    return 1;
}

/* Golden-section minimum of l on [a, b] (misses count as +inf); 1 when some t hit. */
static int golden_min(const sl_tubes_sweep *s, const double o[3], const double d[3], double a, double b,
                      double *l_best, double *t_best)
{
    const double g = 0.6180339887498949;
    double x1 = b - g * (b - a), x2 = a + g * (b - a);
    int ok1, ok2;
    double f1 = entry_at(s, o, d, x1, &ok1), f2 = entry_at(s, o, d, x2, &ok2);
    if (!ok1)
        f1 = INFINITY;
    if (!ok2)
        f2 = INFINITY;
    for (int i = 0; i < GOLDEN_STEPS; i++) {
        if (f1 <= f2) {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = entry_at(s, o, d, x1, &ok1);
            if (!ok1)
                f1 = INFINITY;
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = entry_at(s, o, d, x2, &ok2);
            if (!ok2)
                f2 = INFINITY;
        }
    }
    double t = f1 <= f2 ? x1 : x2, f = f1 <= f2 ? f1 : f2;
    if (!isfinite(f))
        return 0;
    *l_best = f;
    *t_best = t;
    return 1;
}

static int sample_count(const sl_tubes_sweep *s)
{
    double len = 0.0, rmin = INFINITY;
    for (int k = 0; k < 2; k++) {
        double e[3] = {s->b[k + 1][0] - s->b[k][0], s->b[k + 1][1] - s->b[k][1], s->b[k + 1][2] - s->b[k][2]};
        len += sqrt(dot3(e, e));
    }
    for (int k = 0; k < 3; k++)
        rmin = fmin(rmin, fabs(s->r[k]));
    double rmax = fmax(fabs(s->r[0]), fmax(fabs(s->r[1]), fabs(s->r[2])));
    /* Consecutive spheres overlap when the step is below the radius; near a zero radius
     * the cap keeps the cost bounded (such pieces are specks). */
    double rr = fmax(rmin, 0.05 * rmax);
    if (!(rr > 0.0) || !isfinite(len))
        return SWEEP_MAX_SAMPLES;
    double n = 8.0 + 4.0 * len / rr;
    return n > SWEEP_MAX_SAMPLES ? SWEEP_MAX_SAMPLES : (int)n;
}

int sl_tubes_sweep_intersect(const sl_tubes_sweep *s, const double o[3], const double d[3], double l_min,
                             double l_max, double *l, double *t)
{
    int n = sample_count(s);
    double best = l_max, best_t = 0.0;
    int found = 0;
    double f[SWEEP_MAX_SAMPLES + 1];
    int hit[SWEEP_MAX_SAMPLES + 1];
    for (int i = 0; i <= n; i++) {
        f[i] = entry_at(s, o, d, (double)i / n, &hit[i]);
        if (!hit[i])
            f[i] = INFINITY;
    }
    for (int i = 0; i <= n; i++) {
        if (!hit[i])
            continue;
        double left = i > 0 ? f[i - 1] : INFINITY, right = i < n ? f[i + 1] : INFINITY;
        if (i == 0 || i == n) { /* an end sphere: an entry of its own */
            if (f[i] >= l_min && f[i] < best) {
                best = f[i];
                best_t = (double)i / n;
                found = 1;
            }
        }
        if (!(f[i] <= left && f[i] <= right))
            continue;
        double lo = (double)(i > 0 ? i - 1 : 0) / n, hi = (double)(i < n ? i + 1 : n) / n, lm, tm;
        if (golden_min(s, o, d, lo, hi, &lm, &tm) && lm >= l_min && lm < best) {
            best = lm;
            best_t = tm;
            found = 1;
        } else if (f[i] >= l_min && f[i] < best && i > 0 && i < n) {
            /* the search fell below l_min: keep the sampled minimum when it is beyond it */
            best = f[i];
            best_t = (double)i / n;
            found = 1;
        }
    }
    if (found) {
        *l = best;
        *t = best_t;
    }
    return found;
}

double sl_tubes_sweep_residual(const sl_tubes_sweep *s, const double o[3], const double d[3], double l, double t)
{
    double c[3], dc[3], r, dr;
    eval_d(s, t, c, dc, &r, &dr);
    double x[3] = {o[0] + l * d[0] - c[0], o[1] + l * d[1] - c[1], o[2] + l * d[2] - c[2]};
    double ar = fabs(r);
    if (!(ar > 0.0))
        return INFINITY;
    double radial = fabs(sqrt(dot3(x, x)) - ar);
    double speed = sqrt(dot3(dc, dc));
    double along = speed > 0.0 ? fabs(dot3(x, dc) + r * dr) / speed : INFINITY;
    /* along the tangent the sphere leaves the envelope to second order: 0.01 r of offset
     * is ~1e-4 r of depth, so weigh it by 1/100 against the radial residual */
    return fmax(radial, 0.01 * along) / ar;
}

int sl_tubes_sweep_refine(const sl_tubes_sweep *s, const double o[3], const double d[3], double l_min, double t0,
                          double *l, double *t)
{
    double tc = t0, lc = 0.0;
    int ok;
    const double h = 1e-6;
    for (int i = 0; i < 6; i++) {
        double g = entry_slope(s, o, d, tc, &lc, &ok);
        if (!ok)
            return 0;
        double lp, lm;
        int okp, okm;
        double gp = entry_slope(s, o, d, fmin(tc + h, 1.0), &lp, &okp);
        double gm = entry_slope(s, o, d, fmax(tc - h, 0.0), &lm, &okm);
        double span = fmin(tc + h, 1.0) - fmax(tc - h, 0.0);
        if (!okp || !okm || !(span > 0.0))
            return 0;
        double curv = (gp - gm) / span;
        double step;
        if (curv > 0.0)
            step = -g / curv;
        else
            return 0;
        double tn = fmin(fmax(tc + step, 0.0), 1.0);
        if (fabs(tn - tc) < 1e-12) {
            tc = tn;
            break;
        }
        tc = tn;
    }
    lc = entry_at(s, o, d, tc, &ok);
    if (!ok || !(lc >= l_min))
        return 0;
    *l = lc;
    *t = tc;
    return 1;
}
