/* lr_eval.c — the CPU double-precision reference evaluation of an LR-spline
 * volume straight from its LR basis (no Bézier form): Cox-de Boor on each
 * basis function's local knot vectors, restricted to the polynomial piece of
 * the element the point lies in (see sl_lr.h). This is the reference the GPU
 * path and the Bézier conversion are tested against; keep it independent of
 * both. The element search lives here too: the linear reference and, where
 * the model carries an index (lr_index.c), its look-up. Any thread; no GL. */
#include "sl_lr.h"

#include <math.h>

#include "sl_lr_lookup.h"

void sl_lr_bspline_piece(const double *t, int order, double a, double b, double x,
                         double *value, double *derivative)
{
    *value = 0.0;
    *derivative = 0.0;
    int span = -1;
    for (int i = 0; i < order; i++)
        if (t[i] < t[i + 1] && t[i] <= a && b <= t[i + 1]) {
            span = i;
            break;
        }
    if (span < 0)
        return;
    /* n[j] = N_{j,k}(x) on knots t[j..j+k+1], with the indicator of `span`
     * at k = 0, so every level is the polynomial of that piece. */
    double n[SL_LR_MAX_ORDER + 1] = {0};
    double prev[SL_LR_MAX_ORDER + 1] = {0};
    n[span] = 1.0;
    int degree = order - 1;
    for (int k = 1; k <= degree; k++) {
        for (int j = 0; j + k <= order; j++)
            prev[j] = n[j];
        for (int j = 0; j + k < order; j++) {
            double left = 0.0, right = 0.0;
            double dl = t[j + k] - t[j], dr = t[j + k + 1] - t[j + 1];
            if (dl > 0.0)
                left = (x - t[j]) / dl * prev[j];
            if (dr > 0.0)
                right = (t[j + k + 1] - x) / dr * prev[j + 1];
            n[j] = left + right;
        }
    }
    *value = n[0];
    if (degree >= 1) {
        /* prev holds level degree - 1: N_{0,p-1} and N_{1,p-1}. */
        double d0 = t[degree] - t[0], d1 = t[degree + 1] - t[1];
        double der = 0.0;
        if (d0 > 0.0)
            der += prev[0] / d0;
        if (d1 > 0.0)
            der -= prev[1] / d1;
        *derivative = degree * der;
    }
}

sl_status sl_lr_eval(const sl_lr_volume *lr, const double p[3], long element,
                     double *value, double *gradient, sl_err *err)
{
    if (element < 0)
        element = sl_lr_find_element(lr, p);
    if (element < 0 || (size_t)element >= lr->element_count)
        return sl_err_set(err, SL_ERR_INVALID, "point (%g, %g, %g) is outside the LR-spline's domain",
                          p[0], p[1], p[2]);
    const sl_lr_element *e = &lr->elements[element];
    for (int c = 0; c < lr->dim; c++) {
        value[c] = 0.0;
        if (gradient)
            for (int j = 0; j < 3; j++)
                gradient[c * 3 + j] = 0.0;
    }
    for (uint32_t k = 0; k < e->basis_count; k++) {
        const sl_lr_basis *b = &lr->basis[lr->element_basis[e->basis_offset + k]];
        double nv[3], nd[3];
        for (int d = 0; d < 3; d++)
            sl_lr_bspline_piece(b->knots[d], lr->order[d], e->lo[d], e->hi[d], p[d], &nv[d], &nd[d]);
        double w = b->gamma * nv[0] * nv[1] * nv[2];
        double g[3] = {b->gamma * nd[0] * nv[1] * nv[2], b->gamma * nv[0] * nd[1] * nv[2],
                       b->gamma * nv[0] * nv[1] * nd[2]};
        for (int c = 0; c < lr->dim; c++) {
            value[c] += w * b->coef[c];
            if (gradient)
                for (int j = 0; j < 3; j++)
                    gradient[c * 3 + j] += g[j] * b->coef[c];
        }
    }
    return SL_OK;
}

static int inside_rule(const sl_lr_volume *lr, const sl_lr_element *e, const double p[3])
{
    for (int d = 0; d < 3; d++) {
        if (p[d] < e->lo[d])
            return 0;
        if (p[d] >= e->hi[d] && !(p[d] == e->hi[d] && e->hi[d] == lr->domain_hi[d]))
            return 0;
    }
    return 1;
}

long sl_lr_find_element_linear(const sl_lr_volume *lr, const double p[3])
{
    for (int d = 0; d < 3; d++)
        if (!isfinite(p[d]) || p[d] < lr->domain_lo[d] || p[d] > lr->domain_hi[d])
            return -1;
    for (size_t i = 0; i < lr->element_count; i++)
        if (inside_rule(lr, &lr->elements[i], p))
            return (long)i;
    return -1;
}

long sl_lr_find_element(const sl_lr_volume *lr, const double p[3])
{
    return lr->index ? sl_lr_lookup_find(lr->index, p) : sl_lr_find_element_linear(lr, p);
}
