/* ribbons_reference.c — CPU double-precision references for `ribbons` (see ribbons_reference.h).
 *
 * Ray against the elliptic cylinder: in the segment's frame the cross-section
 * is scaled to the unit circle (x / (r w), y / r), which keeps the ray
 * parameter, and the circle's quadratic is solved in the stable form; caps
 * are plane hits tested against the same unit disk. Tangent points: sampled
 * sign changes of the tangency function and bisection, nothing from the
 * conic construction. Any thread, no state.
 */
#include "ribbons_reference.h"

#include <math.h>

#define RR_PI 3.14159265358979323846
#define RR_SAMPLES 65536 /* 2^16 samples of the eccentric anomaly */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void miss(ribbons_ref_hit *hit)
{
    hit->distance = -1.0;
    hit->cos_in = 0.0;
    hit->cos_world = 0.0;
    hit->part = -1;
    hit->inside = 0;
}

int ribbons_ref_ray_ellipse(const double o[3], const double d[3], const ribbons_ref_segment *seg,
                            ribbons_ref_hit *hit)
{
    miss(hit);
    double len = sqrt(dot3(d, d));
    if (!(len > 0.0) || !(seg->r > 0.0) || !(seg->w > 0.0) || !(seg->half_len >= 0.0))
        return -1;
    const double u[3] = {d[0] / len, d[1] / len, d[2] / len};
    const double rel[3] = {o[0] - seg->x0[0], o[1] - seg->x0[1], o[2] - seg->x0[2]};
    const double an = seg->r * seg->w, ab = seg->r; /* semi-axes along n and b */
    /* Circle space: origin q, direction e (across the axis), axial ot + s ut. */
    const double qn = dot3(rel, seg->n) / an, qb = dot3(rel, seg->b) / ab, ot = dot3(rel, seg->t);
    const double en = dot3(u, seg->n) / an, eb = dot3(u, seg->b) / ab, ut = dot3(u, seg->t);
    const double A = en * en + eb * eb, B = qn * en + qb * eb, C = qn * qn + qb * qb - 1.0;
    hit->inside = C < 0.0 && fabs(ot) < seg->half_len;
    double best = HUGE_VAL, best_cos = 0.0;
    int part = -1;
    if (A > 0.0) {
        double D = B * B - A * C;
        if (D >= 0.0) {
            double sq = sqrt(D);
            /* Stable roots: q = -(B + sign(B) sq); s = q / A and C / q. */
            double qq = -(B + (B >= 0.0 ? sq : -sq));
            double s1 = qq / A, s2 = qq != 0.0 ? C / qq : s1;
            double lo = fmin(s1, s2), hi = fmax(s1, s2);
            /* At the entry root q.e = B + s A = -sq, at the exit root +sq. */
            const double roots[2] = {lo, hi}, cosines[2] = {sq / sqrt(A), -sq / sqrt(A)};
            for (int k = 0; k < 2; k++) {
                double s = roots[k];
                if (s > 0.0 && fabs(ot + s * ut) <= seg->half_len && s < best) {
                    best = s;
                    best_cos = cosines[k];
                    part = RIBBONS_REF_MANTLE;
                }
            }
        }
    }
    if (ut != 0.0) {
        for (int k = 0; k < 2; k++) {
            double z = k ? seg->half_len : -seg->half_len;
            double s = (z - ot) / ut;
            double pn = qn + s * en, pb = qb + s * eb;
            if (s > 0.0 && pn * pn + pb * pb <= 1.0 && s < best) {
                best = s;
                best_cos = fabs(ut);
                part = k ? RIBBONS_REF_CAP_END : RIBBONS_REF_CAP_START;
            }
        }
    }
    if (part < 0)
        return 0;
    double N[3];
    if (part == RIBBONS_REF_MANTLE) {
        /* Gradient of (y_n / an)^2 + (y_b / ab)^2: (q_n / an) n + (q_b / ab) b. */
        double pn = (qn + best * en) / an, pb = (qb + best * eb) / ab;
        for (int c = 0; c < 3; c++)
            N[c] = pn * seg->n[c] + pb * seg->b[c];
    } else {
        double sign = part == RIBBONS_REF_CAP_END ? 1.0 : -1.0;
        for (int c = 0; c < 3; c++)
            N[c] = sign * seg->t[c];
    }
    double nl = sqrt(dot3(N, N));
    hit->distance = best;
    hit->cos_in = best_cos;
    hit->cos_world = nl > 0.0 ? -dot3(u, N) / nl : 0.0;
    hit->part = part;
    return 1;
}

double ribbons_ref_polygon_bound(const double d[3], const ribbons_ref_segment *seg, int sides, double cos_in)
{
    double len = sqrt(dot3(d, d));
    if (sides < 3 || !(len > 0.0) || !(seg->r > 0.0) || !(seg->w > 0.0))
        return HUGE_VAL;
    double en = dot3(d, seg->n) / len / (seg->r * seg->w), eb = dot3(d, seg->b) / len / seg->r;
    double across = sqrt(en * en + eb * eb);
    double sn = sin(RR_PI / sides), c = fmin(cos_in, 1.0);
    if (!(across > 0.0) || !(c >= sn))
        return HUGE_VAL;
    return sn * sn / (c + sqrt(c * c - sn * sn)) / across;
}

/* cross(e(theta) - c, e'(theta)) times c_z, e = (w cos, sin). */
static double tangency(const double c[3], double w, double theta)
{
    return w * c[2] - c[0] * cos(theta) - w * c[1] * sin(theta);
}

int ribbons_ref_tangent_points(const double c[3], double w, double theta[2])
{
    if (!(w > 0.0) || (c[0] == 0.0 && c[1] == 0.0 && c[2] == 0.0))
        return 0;
    if (c[0] * c[0] / (w * w) + c[1] * c[1] - c[2] * c[2] <= 0.0)
        return 0;
    const double step = 2.0 * RR_PI / RR_SAMPLES;
    double found[2];
    int count = 0;
    double g_first = tangency(c, w, 0.0), g_prev = g_first;
    for (int k = 1; k <= RR_SAMPLES; k++) {
        double lo = (double)(k - 1) * step, hi = (double)k * step;
        double g = k == RR_SAMPLES ? g_first : tangency(c, w, hi);
        if ((g_prev < 0.0) != (g < 0.0)) {
            double g_lo = g_prev;
            for (int it = 0; it < 200 && hi - lo > 1e-15; it++) {
                double mid = 0.5 * (lo + hi), gm = tangency(c, w, mid);
                if ((gm < 0.0) == (g_lo < 0.0)) {
                    lo = mid;
                    g_lo = gm;
                } else {
                    hi = mid;
                }
            }
            double root = 0.5 * (lo + hi);
            if (root >= 2.0 * RR_PI)
                root -= 2.0 * RR_PI;
            if (count < 2)
                found[count] = root;
            count++;
        }
        g_prev = g;
    }
    if (count != 2)
        return 0;
    theta[0] = fmin(found[0], found[1]);
    theta[1] = fmax(found[0], found[1]);
    return 2;
}

int ribbons_ref_lambda(const double p[2], const double c[3], double w, double *lambda)
{
    *lambda = 0.0;
    double th[2];
    if (ribbons_ref_tangent_points(c, w, th) != 2)
        return 0;
    const double P0[2] = {w * cos(th[0]), sin(th[0])}, P1[2] = {w * cos(th[1]), sin(th[1])};
    double dir[2];
    if (c[2] != 0.0) {
        dir[0] = p[0] - c[0] / c[2];
        dir[1] = p[1] - c[1] / c[2];
    } else {
        dir[0] = c[0];
        dir[1] = c[1];
    }
    /* P0 + u (P1 - P0) = p + v dir, by Cramer's rule. */
    const double ch[2] = {P1[0] - P0[0], P1[1] - P0[1]}, rhs[2] = {p[0] - P0[0], p[1] - P0[1]};
    double det = dir[0] * ch[1] - ch[0] * dir[1];
    double scale = hypot(ch[0], ch[1]) * hypot(dir[0], dir[1]);
    if (!(fabs(det) > 1e-14 * scale))
        return 0;
    double u = (dir[0] * rhs[1] - rhs[0] * dir[1]) / det;
    *lambda = fabs(2.0 * fabs(u) - 1.0);
    return 1;
}

int ribbons_ref_twist_stripes(double R, double f, int k, double *phi)
{
    if (k < 1)
        return 0;
    const double two_pi = 2.0 * RR_PI;
    for (int m = 0; m < k; m++) {
        double a = fmod(f * R + two_pi * m / k, two_pi);
        if (a < 0.0)
            a += two_pi;
        if (a >= two_pi)
            a -= two_pi;
        /* Insertion into the ascending prefix phi[0..m-1]. */
        int j = m;
        while (j > 0 && phi[j - 1] > a) {
            phi[j] = phi[j - 1];
            j--;
        }
        phi[j] = a;
    }
    return k;
}

double ribbons_ref_twist_width(double w_r, double slope)
{
    return w_r / cos(atan(slope));
}

double ribbons_ref_twist_slope(double r, double f, double dR_ds)
{
    return r * f * dR_ds;
}

int ribbons_ref_twist_covered(double phi_frag, const double *phi, int k, double w_u)
{
    const double two_pi = 2.0 * RR_PI;
    for (int m = 0; m < k; m++) {
        double d = fmod(fabs(phi_frag - phi[m]), two_pi);
        if (fmin(d, two_pi - d) <= 0.5 * w_u)
            return 1;
    }
    return 0;
}
