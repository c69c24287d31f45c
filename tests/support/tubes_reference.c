/* tubes_reference.c — brute-force reference for the swept-sphere tube surface (see tubes_reference.h).
 *
 * For a ray o + l d and the sphere at sweep parameter s (centre c(s), radius
 * r(s)), the entry distance is e(s) = w.d - sqrt((w.d)^2 - |w|^2 + r^2) with
 * w = c(s) - o, defined where the discriminant is >= 0. The visible hit is the
 * smallest local minimum (or end point) of e that lies beyond the near plane.
 * We sample s densely, refine every sampled local minimum by golden-section
 * search, and catch narrow grazing intervals through the local maxima of the
 * discriminant. Single thread; no GL; double precision throughout.
 */
#include "tubes_reference.h"

#include <math.h>
#include <stdlib.h>

/* One sweep piece: position and radius as Bezier (quadratic) or Hermite (cubic). */
typedef struct piece {
    int cubic;
    sl_vec3 p[4];    /* quadratic: Bezier control points p[0..2]; cubic: p0, t0, p1, t1 */
    double r[4];     /* same layout for the radius */
    sl_vec3 centre;  /* bounding sphere */
    double bound;
    int samples;     /* samples of s: enough to separate the local minima of the entry distance */
    int segment;
} piece;

static void eval_piece(const piece *pc, double s, sl_vec3 *pos, double *rad)
{
    if (!pc->cubic) {
        /* de Casteljau */
        double u = 1.0 - s;
        sl_vec3 a = sl_v3_add(sl_v3_scale(pc->p[0], u), sl_v3_scale(pc->p[1], s));
        sl_vec3 b = sl_v3_add(sl_v3_scale(pc->p[1], u), sl_v3_scale(pc->p[2], s));
        *pos = sl_v3_add(sl_v3_scale(a, u), sl_v3_scale(b, s));
        double ra = pc->r[0] * u + pc->r[1] * s, rb = pc->r[1] * u + pc->r[2] * s;
        *rad = ra * u + rb * s;
        return;
    }
    double s2 = s * s, s3 = s2 * s;
    double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
    *pos = sl_v3_add(sl_v3_add(sl_v3_scale(pc->p[0], h00), sl_v3_scale(pc->p[1], h10)),
                     sl_v3_add(sl_v3_scale(pc->p[2], h01), sl_v3_scale(pc->p[3], h11)));
    *rad = pc->r[0] * h00 + pc->r[1] * h10 + pc->r[2] * h01 + pc->r[3] * h11;
}

typedef struct ray { sl_vec3 o, d; double lmin; } ray;

/* Entry distance (INFINITY where the ray misses the sphere) and discriminant. */
static double entry(const piece *pc, const ray *ry, double s, double *disc_out, double *rad_out)
{
    sl_vec3 c;
    double r;
    eval_piece(pc, s, &c, &r);
    sl_vec3 w = sl_v3_sub(c, ry->o);
    double b = sl_v3_dot(w, ry->d);
    sl_vec3 perp = sl_v3_sub(w, sl_v3_scale(ry->d, b));
    double disc = r * r - sl_v3_dot(perp, perp);
    if (disc_out)
        *disc_out = disc;
    if (rad_out)
        *rad_out = fabs(r);
    return disc >= 0.0 ? b - sqrt(disc) : INFINITY;
}

#define GOLD 0.3819660112501051

/* Golden-section minimum of g(s) = sign * value on [a, b]; which = 0: entry, 1: -disc. */
static double golden(const piece *pc, const ray *ry, double a, double b, int which)
{
    double x1 = a + GOLD * (b - a), x2 = b - GOLD * (b - a);
    double d1, d2;
    double f1 = entry(pc, ry, x1, &d1, NULL), f2 = entry(pc, ry, x2, &d2, NULL);
    if (which) { f1 = -d1; f2 = -d2; }
    for (int it = 0; it < 80 && b - a > 1e-15; it++) {
        if (f1 <= f2) {
            b = x2; x2 = x1; f2 = f1;
            x1 = a + GOLD * (b - a);
            f1 = entry(pc, ry, x1, &d1, NULL);
            if (which) f1 = -d1;
        } else {
            a = x1; x1 = x2; f1 = f2;
            x2 = b - GOLD * (b - a);
            f2 = entry(pc, ry, x2, &d2, NULL);
            if (which) f2 = -d2;
        }
    }
    return 0.5 * (a + b);
}

/* Keeps the candidate at s when it beats *best and lies beyond the near plane. */
static void consider(const piece *pc, const ray *ry, double s, double *best, double *best_r)
{
    double rad;
    double l = entry(pc, ry, s, NULL, &rad);
    if (isfinite(l) && l >= ry->lmin && l < *best) {
        *best = l;
        *best_r = rad;
    }
}

static void intersect_piece(const piece *pc, const ray *ry, int n, double *fs, double *ds,
                            double *best, double *best_r)
{
    for (int i = 0; i <= n; i++)
        fs[i] = entry(pc, ry, (double)i / n, &ds[i], NULL);
    consider(pc, ry, 0.0, best, best_r);
    consider(pc, ry, 1.0, best, best_r);
    for (int i = 0; i <= n; i++) {
        double lo = (double)(i > 0 ? i - 1 : 0) / n, hi = (double)(i < n ? i + 1 : n) / n;
        double fl = i > 0 ? fs[i - 1] : INFINITY, fr = i < n ? fs[i + 1] : INFINITY;
        if (isfinite(fs[i]) && fs[i] <= fl && fs[i] <= fr) {
            consider(pc, ry, golden(pc, ry, lo, hi, 0), best, best_r);
        }
        double dl = i > 0 ? ds[i - 1] : -INFINITY, dr = i < n ? ds[i + 1] : -INFINITY;
        if (ds[i] < 0.0 && ds[i] >= dl && ds[i] >= dr) {
            /* Grazing: the discriminant may become >= 0 between samples. */
            double s = golden(pc, ry, lo, hi, 1);
            double d;
            entry(pc, ry, s, &d, NULL);
            if (d >= 0.0) {
                consider(pc, ry, s, best, best_r);
                /* refine the entry minimum inside the tiny interval around s */
                double a = s, b = s, step = 1.0 / n;
                double da, db;
                for (int k = 0; k < 60; k++, step *= 0.5) {
                    entry(pc, ry, a - step, &da, NULL);
                    if (a - step >= lo && da >= 0.0) a -= step;
                    entry(pc, ry, b + step, &db, NULL);
                    if (b + step <= hi && db >= 0.0) b += step;
                }
                consider(pc, ry, golden(pc, ry, a, b, 0), best, best_r);
            }
        }
    }
}

/* Samples of one piece: 16 + 16 per radius of control-polygon length, the
 * radius being the piece's smallest |control radius| (the sweep radius never
 * drops below it inside the piece, by the convex hull property), floored at
 * 1/64 of the largest (a radius through 0 would ask for unbounded samples).
 * A sphere of radius r seen by a ray is hit over a parameter range of about
 * r / length, so this puts >= 16 samples across the narrowest hit and its
 * discriminant maximum; 16 x len / r_max (the former rule) missed narrow hits
 * on thin parts of long pieces. Capped by desc->samples (default
 * TUBES_REF_MAX_SAMPLES). */
#define TUBES_REF_MAX_SAMPLES 8192
static int piece_samples(const tubes_ref_desc *desc, const sl_vec3 *cp, int n, const double *r)
{
    double len = 0.0, rmin = INFINITY, rmax = 0.0;
    for (int i = 0; i + 1 < n; i++)
        len += sl_v3_length(sl_v3_sub(cp[i + 1], cp[i]));
    for (int i = 0; i < n; i++) {
        rmin = fmin(rmin, fabs(r[i]));
        rmax = fmax(rmax, fabs(r[i]));
    }
    int cap = desc->samples > 0 ? desc->samples : TUBES_REF_MAX_SAMPLES;
    double rlow = fmax(rmin, rmax / 64.0);
    double want = rlow > 0.0 ? 16.0 + 16.0 * len / rlow : cap;
    return want < cap ? (int)want : cap;
}

static void make_pieces(const tubes_ref_desc *desc, piece *pcs, size_t *count)
{
    size_t k = 0;
    for (size_t s = 0; s < desc->segment_count; s++) {
        const tubes_ref_segment *g = &desc->segments[s];
        sl_vec3 pa = g->p0, ta = g->t0, pb = g->p1, tb = g->t1;
        double ra = g->r0, dra = g->dr0, rb = g->r1, drb = g->dr1;
        piece *q = &pcs[k];
        if (desc->cubic) {
            q->cubic = 1;
            q->p[0] = pa; q->p[1] = ta; q->p[2] = pb; q->p[3] = tb;
            q->r[0] = ra; q->r[1] = dra; q->r[2] = rb; q->r[3] = drb;
            q->segment = (int)s;
            /* bound: the Bezier hull of the cubic */
            sl_vec3 hull[4] = {pa, sl_v3_add(pa, sl_v3_scale(ta, 1.0 / 3)), sl_v3_sub(pb, sl_v3_scale(tb, 1.0 / 3)), pb};
            double rh[4] = {ra, ra + dra / 3, rb - drb / 3, rb};
            sl_vec3 c = sl_v3_scale(sl_v3_add(sl_v3_add(hull[0], hull[1]), sl_v3_add(hull[2], hull[3])), 0.25);
            double bd = 0.0, rm = 0.0;
            for (int i = 0; i < 4; i++) {
                bd = fmax(bd, sl_v3_length(sl_v3_sub(hull[i], c)));
                rm = fmax(rm, fabs(rh[i]));
            }
            q->centre = c;
            q->bound = bd + rm;
            q->samples = piece_samples(desc, hull, 4, rh);
            k++;
            continue;
        }
        sl_vec3 a2 = sl_v3_add(pa, sl_v3_scale(ta, 1.0 / 3)), b2 = sl_v3_sub(pb, sl_v3_scale(tb, 1.0 / 3));
        sl_vec3 mid = sl_v3_scale(sl_v3_add(a2, b2), 0.5);
        double ra2 = ra + dra / 3, rb2 = rb - drb / 3, rmid = 0.5 * (ra2 + rb2);
        sl_vec3 cp[2][3] = {{pa, a2, mid}, {mid, b2, pb}};
        double cr[2][3] = {{ra, ra2, rmid}, {rmid, rb2, rb}};
        for (int h = 0; h < 2; h++, k++) {
            piece *p = &pcs[k];
            p->cubic = 0;
            double rm = 0.0;
            for (int i = 0; i < 3; i++) {
                p->p[i] = cp[h][i];
                p->r[i] = cr[h][i];
                rm = fmax(rm, fabs(cr[h][i]));
            }
            p->centre = sl_v3_scale(sl_v3_add(sl_v3_add(cp[h][0], cp[h][1]), cp[h][2]), 1.0 / 3);
            double bd = 0.0;
            for (int i = 0; i < 3; i++)
                bd = fmax(bd, sl_v3_length(sl_v3_sub(cp[h][i], p->centre)));
            p->bound = bd + rm;
            p->samples = piece_samples(desc, cp[h], 3, cr[h]);
            p->segment = (int)s;
        }
    }
    *count = k;
}

void tubes_ref_render(const tubes_ref_desc *desc, float *distance, float *radius, int *segment)
{
    const sl_view *v = desc->view;
    size_t cap = desc->segment_count * 2 + 1;
    piece *pcs = malloc(cap * sizeof *pcs);
    int n = desc->samples > 0 ? desc->samples : TUBES_REF_MAX_SAMPLES;
    double *fs = malloc((size_t)(n + 1) * sizeof *fs), *ds = malloc((size_t)(n + 1) * sizeof *ds);
    size_t np = 0;
    if (pcs && fs && ds)
        make_pieces(desc, pcs, &np);
    sl_vec3 eye = sl_v3_sub(v->camera.eye, desc->origin);
    for (int j = 0; j < v->height; j++)
        for (int i = 0; i < v->width; i++) {
            ray ry = {eye, sl_view_ray_dir(v, i, j), 0.0};
            ry.lmin = v->near_plane / sl_v3_dot(ry.d, v->forward);
            double best = INFINITY, best_r = 0.0;
            int best_seg = -1;
            for (size_t k = 0; k < np; k++) {
                const piece *pc = &pcs[k];
                sl_vec3 w = sl_v3_sub(pc->centre, ry.o);
                double b = sl_v3_dot(w, ry.d);
                double perp2 = sl_v3_dot(w, w) - b * b;
                if (perp2 > pc->bound * pc->bound * (1.0 + 1e-9) || b + pc->bound < ry.lmin)
                    continue;
                double before = best;
                intersect_piece(pc, &ry, pc->samples, fs, ds, &best, &best_r);
                if (best < before)
                    best_seg = pc->segment;
            }
            size_t px = (size_t)j * (size_t)v->width + (size_t)i;
            int hit = isfinite(best);
            distance[px] = hit ? (float)best : 0.0f;
            if (radius)
                radius[px] = hit ? (float)best_r : 0.0f;
            if (segment)
                segment[px] = hit ? best_seg : -1;
        }
    free(pcs);
    free(fs);
    free(ds);
}

int tubes_ref_silhouette(const float *ref, const float *rad, int w, int h, int i, int j)
{
    size_t c = (size_t)j * (size_t)w + (size_t)i;
    for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++) {
            int x = i + di, y = j + dj;
            if (x < 0 || y < 0 || x >= w || y >= h)
                continue;
            size_t n = (size_t)y * (size_t)w + (size_t)x;
            if ((ref[n] > 0.0f) != (ref[c] > 0.0f))
                return 1;
            if (ref[c] > 0.0f && ref[n] > 0.0f && fabsf(ref[n] - ref[c]) > fmaxf(rad[c], rad[n]))
                return 1;
        }
    return 0;
}
