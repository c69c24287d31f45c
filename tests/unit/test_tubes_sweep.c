/* test_tubes_sweep.c — the CPU execution's exact sweep intersector (renderer/tubes/tubes_sweep.c)
 * against a brute-force reference that shares no code with it.
 *
 * The reference evaluates the quadratic Bézier centre and radius in long double at 20 001
 * parameters, takes the nearest sphere entry along the ray, and polishes it by ternary search
 * between the neighbouring samples. Sweeps: random, tight bends (radius x curvature up to ~5),
 * zero length (a sphere), collinear controls, radius 0 at an end, a radius growing faster than
 * the centre moves; rays aimed within 1.5 r of a random centre point from 3 to 3000 sizes away,
 * some with l_max before the entry. Held: every hit the reference finds away from grazing
 * (the deepest sphere penetration at least 1e-3 r^2) is found, at a distance within 2e-6 r (the
 * reference's own sampling bound); no hit where the reference's rays clear every sphere by
 * 1e-3 r; l_max is respected. Prints the worst error. Single thread.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "sl_test.h"
#include "tubes/tubes_sweep.h"

#define SAMPLES 20000

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double uniform(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}
static double between(double a, double b) { return a + (b - a) * uniform(); }

/* The entry distance into the sphere of t and the ray's penetration r^2 - distance^2. */
static long double ref_entry(const sl_tubes_sweep *s, const double o[3], const double d[3], long double t,
                             long double *penetration)
{
    long double u = 1.0L - t, w0 = u * u, w1 = 2.0L * u * t, w2 = t * t, q[3], a = 0.0L, qq = 0.0L;
    for (int k = 0; k < 3; k++) {
        q[k] = w0 * s->b[0][k] + w1 * s->b[1][k] + w2 * s->b[2][k] - o[k];
        a += q[k] * d[k];
        qq += q[k] * q[k];
    }
    long double r = fabsl(w0 * s->r[0] + w1 * s->r[1] + w2 * s->r[2]);
    *penetration = r * r - (qq - a * a);
    return *penetration >= 0.0L ? a - sqrtl(*penetration) : INFINITY;
}

/* The nearest entry (origin outside the sweep): 1 with *l; *deepest = the largest penetration. */
static int ref_intersect(const sl_tubes_sweep *s, const double o[3], const double d[3], long double *l,
                         long double *deepest)
{
    long double best = INFINITY, pen;
    int best_i = -1;
    *deepest = -INFINITY;
    for (int i = 0; i <= SAMPLES; i++) {
        long double e = ref_entry(s, o, d, (long double)i / SAMPLES, &pen);
        if (pen > *deepest)
            *deepest = pen;
        if (e < best) {
            best = e;
            best_i = i;
        }
    }
    if (best_i < 0)
        return 0;
    long double a = (best_i > 0 ? best_i - 1 : 0) / (long double)SAMPLES;
    long double b = (best_i < SAMPLES ? best_i + 1 : SAMPLES) / (long double)SAMPLES;
    for (int i = 0; i < 200; i++) {
        long double m1 = a + (b - a) / 3.0L, m2 = b - (b - a) / 3.0L;
        if (ref_entry(s, o, d, m1, &pen) <= ref_entry(s, o, d, m2, &pen))
            b = m2;
        else
            a = m1;
    }
    long double polished = ref_entry(s, o, d, 0.5L * (a + b), &pen);
    *l = polished < best ? polished : best;
    return 1;
}

static void random_sweep(sl_tubes_sweep *s, int kind, double *size)
{
    double scale = between(0.05, 2.0);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            s->b[i][k] = between(-scale, scale);
    double r = between(0.02, 0.4) * scale;
    for (int i = 0; i < 3; i++)
        s->r[i] = r * between(0.5, 1.5);
    switch (kind) {
    case 1: /* a tight bend: the middle control far out, the ends close */
        for (int k = 0; k < 3; k++) {
            s->b[2][k] = s->b[0][k] + between(-0.2, 0.2) * scale;
            s->b[1][k] = s->b[0][k] + between(-1.0, 1.0) * scale;
        }
        break;
    case 2: /* zero length: a sphere */
        for (int i = 1; i < 3; i++)
            for (int k = 0; k < 3; k++)
                s->b[i][k] = s->b[0][k];
        break;
    case 3: /* collinear controls, the middle one outside the ends (a fold back) */
        for (int k = 0; k < 3; k++) {
            double dir = s->b[2][k] - s->b[0][k];
            s->b[1][k] = s->b[0][k] + between(-0.5, 1.5) * dir;
        }
        break;
    case 4: /* radius 0 at an end */
        s->r[0] = 0.0;
        break;
    case 5: /* the radius grows faster than the centre moves */
        for (int k = 0; k < 3; k++)
            s->b[2][k] = s->b[0][k] + 0.1 * (s->b[2][k] - s->b[0][k]);
        s->r[2] = 4.0 * s->r[0];
        break;
    default:
        break;
    }
    *size = scale;
}

int main(void)
{
    int compared = 0, grazing = 0, misses = 0, lmax_checked = 0;
    double worst = 0.0;
    for (int c = 0; c < 1200; c++) {
        sl_tubes_sweep s;
        double size;
        random_sweep(&s, c % 6, &size);
        double rmax = fmax(fabs(s.r[0]), fmax(fabs(s.r[1]), fabs(s.r[2])));
        /* aim within 1.5 rmax of a centre point, from far enough to start outside */
        double t0 = uniform(), u = 1.0 - t0, target[3], d[3], len = 0.0;
        for (int k = 0; k < 3; k++) {
            target[k] = u * u * s.b[0][k] + 2.0 * u * t0 * s.b[1][k] + t0 * t0 * s.b[2][k] +
                        between(-1.5, 1.5) * rmax;
            d[k] = between(-1.0, 1.0);
            len += d[k] * d[k];
        }
        len = sqrt(len);
        for (int k = 0; k < 3; k++)
            d[k] /= len;
        double distance = (c % 3 == 0 ? 3.0 : c % 3 == 1 ? 30.0 : 3000.0) * (size + rmax) + 4.0 * rmax;
        double o[3] = {target[0] - distance * d[0], target[1] - distance * d[1], target[2] - distance * d[2]};
        long double lref, deepest;
        int href = ref_intersect(&s, o, d, &lref, &deepest);
        double l = 0.0, t = 0.0;
        int h = sl_tubes_sweep_intersect(&s, o, d, 0.0, INFINITY, &l, &t);
        double r2 = rmax * rmax;
        if (href && deepest >= 1e-3 * r2) {
            compared++;
            double err = h ? fabs(l - (double)lref) / rmax : INFINITY;
            if (err > worst)
                worst = err;
            SL_CHECK_MSG(h && err <= 2e-6, "case %d (kind %d): hit %d l %.12g, reference %.12Lg (%.3g r)", c, c % 6, h,
                         l, lref, err);
            /* an l_max just before the entry hides it; just after keeps it */
            double before = (double)lref - 1e-4 * rmax, after = (double)lref + 1e-4 * rmax, l2, t2;
            SL_CHECK_MSG(!sl_tubes_sweep_intersect(&s, o, d, 0.0, before, &l2, &t2), "case %d: a hit before l_max",
                         c);
            SL_CHECK_MSG(sl_tubes_sweep_intersect(&s, o, d, 0.0, after, &l2, &t2), "case %d: l_max hid the entry", c);
            lmax_checked++;
        } else if (deepest < -1e-3 * r2 * 2.0) {
            misses++;
            SL_CHECK_MSG(!h, "case %d (kind %d): hit at %.12g where the reference clears every sphere", c, c % 6, l);
        } else {
            grazing++;
        }
    }
    printf("test_tubes_sweep: %d hits compared (worst %.3g r), %d misses, %d grazing skipped, %d l_max pairs\n",
           compared, worst, misses, grazing, lmax_checked);
    SL_CHECK(compared >= 300 && misses >= 100);
    SL_TEST_END();
}
