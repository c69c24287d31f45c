/* lr_tensor.c — the LR form of a tensor-product B-spline volume (see
 * sl_lr_tensor_product in sl_lr.h). Any thread; no GL. */
#include "sl_lr.h"

#include <math.h>
#include <stdlib.h>

/* Distinct knot values (cells lie between consecutive ones). */
static int distinct_values(const double *t, int n, double *out)
{
    int m = 0;
    for (int i = 0; i < n; i++)
        if (m == 0 || t[i] > out[m - 1])
            out[m++] = t[i];
    return m;
}

static int value_count(const double *t, int n, double v)
{
    int c = 0;
    for (int i = 0; i < n; i++)
        c += t[i] == v;
    return c;
}

sl_status sl_lr_tensor_product(sl_lr_volume *lr, const int order[3], int dim,
                               const double *const knots[3], const int knot_count[3],
                               sl_lr_coef_fn coef, void *user, sl_err *err)
{
    static const char axis[3] = {'u', 'v', 'w'};
    size_t nb[3], ncell[3];
    double *distinct[3] = {NULL, NULL, NULL};
    int nd[3];
    sl_status st = SL_OK;
    for (int d = 0; d < 3; d++) {
        if (order[d] < 1 || order[d] > SL_LR_MAX_ORDER)
            return sl_err_set(err, SL_ERR_UNSUPPORTED, "order %d in %c is outside 1..%d", order[d], axis[d],
                              SL_LR_MAX_ORDER);
        if (knot_count[d] < order[d] + 1 || knot_count[d] > 1 << 20)
            return sl_err_set(err, SL_ERR_INVALID, "%d knots in %c: need %d .. %d for order %d",
                              knot_count[d], axis[d], order[d] + 1, 1 << 20, order[d]);
        for (int i = 0; i < knot_count[d]; i++)
            if (!isfinite(knots[d][i]) || (i > 0 && knots[d][i] < knots[d][i - 1]))
                return sl_err_set(err, SL_ERR_INVALID, "%c knot %d is not finite or out of order", axis[d], i);
        nb[d] = (size_t)(knot_count[d] - order[d]);
        const double *t = knots[d];
        int n = knot_count[d];
        if (t[order[d] - 1] != t[0] || t[n - order[d]] != t[n - 1] || !(t[n - 1] > t[0]))
            return sl_err_set(err, SL_ERR_INVALID, "%c knots need open ends: %d equal values at each end"
                              " of a non-empty range", axis[d], order[d]);
    }
    for (int d = 0; d < 3; d++) {
        distinct[d] = malloc(sizeof(double) * (size_t)knot_count[d]);
        if (!distinct[d]) {
            st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for knot vectors");
            goto done;
        }
        nd[d] = distinct_values(knots[d], knot_count[d], distinct[d]);
        ncell[d] = nd[d] > 1 ? (size_t)(nd[d] - 1) : 0;
    }
    size_t basis_count = nb[0] * nb[1] * nb[2];
    size_t element_count = ncell[0] * ncell[1] * ncell[2];
    size_t per_element = (size_t)order[0] * order[1] * order[2];
    size_t rects = (size_t)nd[0] + nd[1] + nd[2];
    if (element_count == 0) {
        st = sl_err_set(err, SL_ERR_INVALID, "the knot vectors span no cell");
        goto done;
    }
    if (element_count > SL_LR_MAX_ELEMENTS || element_count * per_element > SL_LR_MAX_ELEMENT_BASIS) {
        st = sl_err_set(err, SL_ERR_LIMIT, "%zu elements exceed the limits", element_count);
        goto done;
    }
    st = sl_lr_alloc(lr, basis_count, rects, element_count, element_count * per_element, err);
    if (st != SL_OK)
        goto done;
    lr->order[0] = order[0];
    lr->order[1] = order[1];
    lr->order[2] = order[2];
    lr->dim = dim;
    for (size_t k = 0; k < nb[2]; k++)
        for (size_t j = 0; j < nb[1]; j++)
            for (size_t i = 0; i < nb[0]; i++) {
                sl_lr_basis *b = &lr->basis[(k * nb[1] + j) * nb[0] + i];
                size_t idx[3] = {i, j, k};
                double g[3];
                int ijk[3] = {(int)i, (int)j, (int)k};
                for (int d = 0; d < 3; d++) {
                    double sum = 0.0;
                    for (int q = 0; q <= order[d]; q++)
                        b->knots[d][q] = knots[d][idx[d] + (size_t)q];
                    for (int q = 1; q < order[d]; q++)
                        sum += b->knots[d][q];
                    g[d] = order[d] > 1 ? sum / (order[d] - 1)
                                        : 0.5 * (b->knots[d][0] + b->knots[d][1]);
                }
                b->gamma = 1.0;
                coef(user, ijk, g, b->coef);
            }
    size_t r = 0;
    for (int d = 0; d < 3; d++)
        for (int q = 0; q < nd[d]; q++) {
            sl_lr_meshrect *m = &lr->meshrects[r++];
            for (int e = 0; e < 3; e++) {
                m->lo[e] = distinct[e][0];
                m->hi[e] = distinct[e][nd[e] - 1];
            }
            m->lo[d] = m->hi[d] = distinct[d][q];
            m->multiplicity = value_count(knots[d], knot_count[d], distinct[d][q]);
        }
    size_t off = 0, el = 0;
    for (size_t ck = 0; ck < ncell[2]; ck++)
        for (size_t cj = 0; cj < ncell[1]; cj++)
            for (size_t ci = 0; ci < ncell[0]; ci++) {
                sl_lr_element *e = &lr->elements[el++];
                size_t c[3] = {ci, cj, ck};
                for (int d = 0; d < 3; d++) {
                    e->lo[d] = distinct[d][c[d]];
                    e->hi[d] = distinct[d][c[d] + 1];
                }
                e->basis_offset = (uint32_t)off;
                /* Basis functions whose support covers the cell: index range per direction. */
                size_t first[3], last[3];
                for (int d = 0; d < 3; d++) {
                    first[d] = nb[d];
                    last[d] = 0;
                    for (size_t q = 0; q < nb[d]; q++)
                        if (knots[d][q] <= e->lo[d] && e->hi[d] <= knots[d][q + (size_t)order[d]]) {
                            if (q < first[d])
                                first[d] = q;
                            last[d] = q;
                        }
                }
                if (first[0] > last[0] || first[1] > last[1] || first[2] > last[2])
                    continue; /* sl_lr_finish names it */
                for (size_t k = first[2]; k <= last[2]; k++)
                    for (size_t j = first[1]; j <= last[1]; j++)
                        for (size_t i = first[0]; i <= last[0]; i++)
                            lr->element_basis[off++] = (uint32_t)((k * nb[1] + j) * nb[0] + i);
                e->basis_count = (uint32_t)(off - e->basis_offset);
            }
    lr->element_basis_count = off;
    st = sl_lr_finish(lr, err);
    if (st != SL_OK)
        sl_lr_free(lr);
done:
    for (int d = 0; d < 3; d++)
        free(distinct[d]);
    return st;
}
