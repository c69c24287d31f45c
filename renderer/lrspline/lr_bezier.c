/* lr_bezier.c — exact Bézier extraction of an LR-spline volume's elements
 * by blossoming, the per-element value hull and the CPU de Casteljau
 * evaluation in double (see sl_lr_bezier.h for the derivation and layout).
 * Any thread; no GL. A built block set is read-only. */
#include "sl_lr_bezier.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Blossom of the piece on span s of the B-spline on t[0..order] at u[0..order-2]:
 * de Boor's recurrence with control vector e_0 on the span's local knots,
 * padded outside t[0..order] (B-spline 0 depends on t[0..order] only, and no
 * denominator involves only padding knots on a non-empty span). */
static double blossom(const double *t, int order, int s, const double *u)
{
    int p = order - 1;
    if (p == 0)
        return 1.0;
    /* Knots T[i] for i = s-p+1 .. s+p (index i + p in `pad`), i.e. -p+1 .. 2p. */
    double pad[3 * SL_LR_MAX_ORDER + 2];
    double span = t[order] - t[0];
    for (int i = -p; i <= 2 * p + 1; i++) {
        double v;
        if (i < 0)
            v = t[0] + i * span;
        else if (i > order)
            v = t[order] + (i - order) * span;
        else
            v = t[i];
        pad[i + p] = v;
    }
#define T(i) pad[(i) + p]
    /* Control points d_i, i = s-p .. s: 1 at i == 0. */
    double d[SL_LR_MAX_ORDER];
    for (int i = 0; i <= p; i++)
        d[i] = (s - p + i) == 0 ? 1.0 : 0.0;
    for (int r = 1; r <= p; r++) {
        double x = u[r - 1];
        for (int i = p; i >= r; i--) {
            int gi = s - p + i; /* global index of d[i] */
            double lo = T(gi), hi = T(gi + p + 1 - r);
            double a = (x - lo) / (hi - lo);
            d[i] = (1.0 - a) * d[i - 1] + a * d[i];
        }
    }
#undef T
    return d[p];
}

void sl_lr_bernstein_piece(const double *t, int order, double a, double b, double *beta)
{
    int span = -1;
    for (int i = 0; i < order; i++)
        if (t[i] < t[i + 1] && t[i] <= a && b <= t[i + 1]) {
            span = i;
            break;
        }
    for (int j = 0; j < order; j++) {
        if (span < 0) {
            beta[j] = 0.0;
            continue;
        }
        double u[SL_LR_MAX_ORDER];
        int p = order - 1;
        for (int q = 0; q < p; q++)
            u[q] = q < p - j ? a : b;
        beta[j] = blossom(t, order, span, u);
    }
}

void sl_lr_bezier_free(sl_lr_bezier *bz)
{
    if (!bz)
        return;
    free(bz->lo);
    free(bz->hi);
    free(bz->coef);
    free(bz->hull_min);
    free(bz->hull_max);
    sl_lr_lookup_deinit(&bz->own_lookup);
    memset(bz, 0, sizeof *bz);
}

static void block_hull(const double *c, size_t n, int dim, double *lo, double *hi)
{
    if (dim == 1) {
        double mn = c[0], mx = c[0];
        for (size_t i = 1; i < n; i++) {
            mn = fmin(mn, c[i]);
            mx = fmax(mx, c[i]);
        }
        *lo = mn;
        *hi = mx;
        return;
    }
    double bmin[SL_LR_MAX_DIM], bmax[SL_LR_MAX_DIM], mag = 0.0;
    for (int k = 0; k < dim; k++)
        bmin[k] = bmax[k] = c[k];
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (int k = 0; k < dim; k++) {
            double v = c[i * (size_t)dim + (size_t)k];
            bmin[k] = fmin(bmin[k], v);
            bmax[k] = fmax(bmax[k], v);
            s += v * v;
        }
        mag = fmax(mag, sqrt(s));
    }
    double dist = 0.0;
    for (int k = 0; k < dim; k++) {
        double g = bmin[k] > 0.0 ? bmin[k] : (bmax[k] < 0.0 ? -bmax[k] : 0.0);
        dist += g * g;
    }
    *lo = sqrt(dist);
    *hi = mag;
}

static sl_status build_blocks(const sl_lr_volume *lr, sl_lr_bezier *bz, sl_err *err);

sl_status sl_lr_bezier_build(const sl_lr_volume *lr, sl_lr_lookup_kind lookup, int forest_axis,
                             sl_lr_bezier *bz, sl_err *err)
{
    sl_status st = build_blocks(lr, bz, err);
    if (st != SL_OK)
        return st;
    bz->lookup = sl_lr_index_match(lr, lookup, forest_axis);
    if (!bz->lookup) {
        if ((st = sl_lr_lookup_init(&bz->own_lookup, lr, lookup, forest_axis, err)) != SL_OK) {
            sl_lr_bezier_free(bz);
            return st;
        }
        bz->lookup = &bz->own_lookup;
    }
    bz->lookup_kind = bz->lookup->kind;
    return SL_OK;
}

static sl_status build_blocks(const sl_lr_volume *lr, sl_lr_bezier *bz, sl_err *err)
{
    memset(bz, 0, sizeof *bz);
    size_t n = (size_t)lr->order[0] * (size_t)lr->order[1] * (size_t)lr->order[2];
    size_t stride = n * (size_t)lr->dim;
    size_t ne = lr->element_count;
    if (ne == 0 || ne > SL_LR_MAX_ELEMENTS || stride * ne > ((size_t)1 << 31) / sizeof(float))
        return sl_err_set(err, SL_ERR_LIMIT, "%zu elements of %zu coefficients exceed the Bézier"
                          " block limit of 2 GiB", ne, stride);
    for (int d = 0; d < 3; d++)
        bz->order[d] = lr->order[d];
    bz->dim = lr->dim;
    bz->element_count = ne;
    bz->stride = stride;
    bz->lo = malloc(sizeof(double) * 3 * ne);
    bz->hi = malloc(sizeof(double) * 3 * ne);
    bz->coef = calloc(ne * stride, sizeof(double));
    bz->hull_min = malloc(sizeof(double) * ne);
    bz->hull_max = malloc(sizeof(double) * ne);
    if (!bz->lo || !bz->hi || !bz->coef || !bz->hull_min || !bz->hull_max) {
        sl_lr_bezier_free(bz);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu Bézier blocks", ne);
    }
    const int o0 = lr->order[0], o1 = lr->order[1], o2 = lr->order[2], dim = lr->dim;
    for (size_t e = 0; e < ne; e++) {
        const sl_lr_element *el = &lr->elements[e];
        double *c = bz->coef + e * stride;
        for (int d = 0; d < 3; d++) {
            bz->lo[e * 3 + (size_t)d] = el->lo[d];
            bz->hi[e * 3 + (size_t)d] = el->hi[d];
        }
        for (uint32_t q = 0; q < el->basis_count; q++) {
            const sl_lr_basis *b = &lr->basis[lr->element_basis[el->basis_offset + q]];
            double beta[3][SL_LR_MAX_ORDER];
            for (int d = 0; d < 3; d++)
                sl_lr_bernstein_piece(b->knots[d], lr->order[d], el->lo[d], el->hi[d], beta[d]);
            for (int k = 0; k < o2; k++)
                for (int j = 0; j < o1; j++) {
                    double wjk = b->gamma * beta[2][k] * beta[1][j];
                    for (int i = 0; i < o0; i++) {
                        double w = wjk * beta[0][i];
                        double *dst = c + ((size_t)(k * o1 + j) * (size_t)o0 + (size_t)i) * (size_t)dim;
                        for (int m = 0; m < dim; m++)
                            dst[m] += w * b->coef[m];
                    }
                }
        }
        for (int d = 0; d < 3; d++) {
            bz->domain_lo[d] = e == 0 ? (float)el->lo[d] : fminf(bz->domain_lo[d], (float)el->lo[d]);
            bz->domain_hi[d] = e == 0 ? (float)el->hi[d] : fmaxf(bz->domain_hi[d], (float)el->hi[d]);
        }
        block_hull(c, n, dim, &bz->hull_min[e], &bz->hull_max[e]);
        if (e == 0 || bz->hull_min[e] < bz->hull_lo)
            bz->hull_lo = bz->hull_min[e];
        if (e == 0 || bz->hull_max[e] > bz->hull_hi)
            bz->hull_hi = bz->hull_max[e];
    }
    return SL_OK;
}

/* de Casteljau on b[0..n-1] (stride s) at u: value and derivative in u. */
static void decasteljau(const double *b, size_t s, int n, double u, double *v, double *dv)
{
    double w[SL_LR_MAX_ORDER] = {0};
    for (int i = 0; i < n && i < SL_LR_MAX_ORDER; i++)
        w[i] = b[(size_t)i * s];
    if (n == 1) {
        *v = w[0];
        if (dv)
            *dv = 0.0;
        return;
    }
    for (int r = n - 1; r >= 2; r--)
        for (int i = 0; i < r; i++)
            w[i] = (1.0 - u) * w[i] + u * w[i + 1];
    *v = (1.0 - u) * w[0] + u * w[1];
    if (dv)
        *dv = (n - 1) * (w[1] - w[0]);
}

void sl_lr_bezier_eval(const sl_lr_bezier *bz, size_t element, const double p[3],
                       double *value, double *gradient)
{
    const int o0 = bz->order[0], o1 = bz->order[1], o2 = bz->order[2], dim = bz->dim;
    const double *lo = bz->lo + element * 3, *hi = bz->hi + element * 3;
    const double *c = bz->coef + element * bz->stride;
    double u[3], h[3];
    for (int d = 0; d < 3; d++) {
        h[d] = hi[d] - lo[d];
        u[d] = (p[d] - lo[d]) / h[d];
    }
    for (int m = 0; m < dim; m++) {
        /* x: rows (j, k) -> V, Dx; y: -> V2, Dy, Dx2; z: -> value and gradient. */
        double V[SL_LR_MAX_ORDER][SL_LR_MAX_ORDER], Dx[SL_LR_MAX_ORDER][SL_LR_MAX_ORDER];
        for (int k = 0; k < o2; k++)
            for (int j = 0; j < o1; j++)
                decasteljau(c + ((size_t)(k * o1 + j) * (size_t)o0) * (size_t)dim + (size_t)m, (size_t)dim,
                            o0, u[0], &V[k][j], &Dx[k][j]);
        double V2[SL_LR_MAX_ORDER], Dy2[SL_LR_MAX_ORDER], Dx2[SL_LR_MAX_ORDER];
        for (int k = 0; k < o2; k++) {
            decasteljau(V[k], 1, o1, u[1], &V2[k], &Dy2[k]);
            decasteljau(Dx[k], 1, o1, u[1], &Dx2[k], NULL);
        }
        double v, dz, dy, dx;
        decasteljau(V2, 1, o2, u[2], &v, &dz);
        value[m] = v;
        if (gradient) {
            decasteljau(Dy2, 1, o2, u[2], &dy, NULL);
            decasteljau(Dx2, 1, o2, u[2], &dx, NULL);
            gradient[m * 3 + 0] = dx / h[0];
            gradient[m * 3 + 1] = dy / h[1];
            gradient[m * 3 + 2] = dz / h[2];
        }
    }
}
