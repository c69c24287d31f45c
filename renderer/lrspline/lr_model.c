/* lr_model.c — allocation, validation and derived fields of an LR-spline
 * volume model and the mesh-rectangle rule shared with the loader (see
 * sl_lr.h); the element search is lr_eval.c's. Mesh rectangles are checked against
 * the domain box the elements span, so after the elements.
 * Any thread; no GL. */
#include "sl_lr.h"
#include "lr_index.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

sl_status sl_lr_alloc(sl_lr_volume *lr, size_t basis_count, size_t meshrect_count,
                      size_t element_count, size_t element_basis_count, sl_err *err)
{
    memset(lr, 0, sizeof *lr);
    if (basis_count > SL_LR_MAX_BASIS)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu basis functions exceed the limit of %u",
                          basis_count, SL_LR_MAX_BASIS);
    if (element_count > SL_LR_MAX_ELEMENTS)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu elements exceed the limit of %u",
                          element_count, SL_LR_MAX_ELEMENTS);
    if (meshrect_count > SL_LR_MAX_MESHRECTS)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu mesh rectangles exceed the limit of %u",
                          meshrect_count, SL_LR_MAX_MESHRECTS);
    if (element_basis_count > SL_LR_MAX_ELEMENT_BASIS)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu element-basis entries exceed the limit of %u",
                          element_basis_count, SL_LR_MAX_ELEMENT_BASIS);
    lr->basis = calloc(basis_count ? basis_count : 1, sizeof *lr->basis);
    lr->meshrects = calloc(meshrect_count ? meshrect_count : 1, sizeof *lr->meshrects);
    lr->elements = calloc(element_count ? element_count : 1, sizeof *lr->elements);
    lr->element_basis = calloc(element_basis_count ? element_basis_count : 1,
                               sizeof *lr->element_basis);
    if (!lr->basis || !lr->meshrects || !lr->elements || !lr->element_basis) {
        sl_lr_free(lr);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for an LR-spline of %zu basis functions"
                          " and %zu elements", basis_count, element_count);
    }
    lr->basis_count = basis_count;
    lr->meshrect_count = meshrect_count;
    lr->element_count = element_count;
    lr->element_basis_count = element_basis_count;
    return SL_OK;
}

void sl_lr_free(sl_lr_volume *lr)
{
    if (!lr)
        return;
    sl_lr_drop_index(lr);
    free(lr->basis);
    free(lr->meshrects);
    free(lr->elements);
    free(lr->element_basis);
    memset(lr, 0, sizeof *lr);
}

static const char axis_name[3] = {'u', 'v', 'w'};

static sl_status check_basis(const sl_lr_volume *lr, size_t i, sl_err *err)
{
    const sl_lr_basis *b = &lr->basis[i];
    for (int d = 0; d < 3; d++) {
        const double *t = b->knots[d];
        for (int k = 0; k <= lr->order[d]; k++) {
            if (!isfinite(t[k]))
                return sl_err_set(err, SL_ERR_FORMAT, "basis function %zu: %c knot %d is not finite",
                                  i, axis_name[d], k);
            if (k > 0 && t[k] < t[k - 1])
                return sl_err_set(err, SL_ERR_FORMAT, "basis function %zu: %c knots out of order"
                                  " (%.17g after %.17g)", i, axis_name[d], t[k], t[k - 1]);
        }
        if (!(t[lr->order[d]] > t[0]))
            return sl_err_set(err, SL_ERR_FORMAT, "basis function %zu: empty support in %c",
                              i, axis_name[d]);
    }
    for (int c = 0; c < lr->dim; c++)
        if (!isfinite(b->coef[c]))
            return sl_err_set(err, SL_ERR_FORMAT, "basis function %zu: coefficient %d is not finite", i, c);
    if (!(b->gamma > 0.0) || !isfinite(b->gamma))
        return sl_err_set(err, SL_ERR_FORMAT, "basis function %zu: scaling weight %g is not positive",
                          i, b->gamma);
    return SL_OK;
}

int sl_lr_meshrect_const_dir(const sl_lr_meshrect *m)
{
    int dir = -1;
    for (int d = 0; d < 3; d++)
        if (m->lo[d] == m->hi[d])
            dir = d;
    return dir;
}

/* Mesh rectangle i against the domain box (filled from the elements):
 * flat in one or two directions (a segment, as the reference library keeps
 * them), inside the closed box, multiplicity within the order. */
static sl_status check_meshrect(const sl_lr_volume *lr, size_t i, sl_err *err)
{
    const sl_lr_meshrect *m = &lr->meshrects[i];
    int flat = 0;
    for (int d = 0; d < 3; d++) {
        if (!isfinite(m->lo[d]) || !isfinite(m->hi[d]) || m->hi[d] < m->lo[d])
            return sl_err_set(err, SL_ERR_FORMAT, "mesh rectangle %zu: bad extent in %c", i, axis_name[d]);
        if (m->lo[d] < lr->domain_lo[d] || m->hi[d] > lr->domain_hi[d])
            return sl_err_set(err, SL_ERR_FORMAT, "mesh rectangle %zu: %c extent [%.17g, %.17g] is outside the"
                              " domain [%.17g, %.17g]", i, axis_name[d], m->lo[d], m->hi[d], lr->domain_lo[d],
                              lr->domain_hi[d]);
        flat += m->lo[d] == m->hi[d];
    }
    if (flat == 0)
        return sl_err_set(err, SL_ERR_FORMAT, "mesh rectangle %zu is not flat in any direction", i);
    if (flat == 3)
        return sl_err_set(err, SL_ERR_FORMAT, "mesh rectangle %zu is a point (flat in all three directions)", i);
    int d = sl_lr_meshrect_const_dir(m);
    if (m->multiplicity < 1 || m->multiplicity > lr->order[d])
        return sl_err_set(err, SL_ERR_FORMAT, "mesh rectangle %zu: multiplicity %d is outside 1..%d (the order"
                          " in %c)", i, m->multiplicity, lr->order[d], axis_name[d]);
    return SL_OK;
}

/* Whether basis b's support covers the element box and no knot of b lies
 * strictly inside it (the box is inside one polynomial piece). */
static int basis_covers(const sl_lr_volume *lr, const sl_lr_basis *b, const sl_lr_element *e)
{
    for (int d = 0; d < 3; d++) {
        const double *t = b->knots[d];
        int p = lr->order[d];
        if (e->lo[d] < t[0] || e->hi[d] > t[p])
            return 0;
        for (int k = 0; k <= p; k++)
            if (t[k] > e->lo[d] && t[k] < e->hi[d])
                return 0;
    }
    return 1;
}

static void add_value_sample(sl_lr_volume *lr, const double *v)
{
    double m = v[0];
    if (lr->dim == 3)
        m = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (m < lr->value_min)
        lr->value_min = m;
    if (m > lr->value_max)
        lr->value_max = m;
}

sl_status sl_lr_finish(sl_lr_volume *lr, sl_err *err)
{
    sl_lr_drop_index(lr);
    for (int d = 0; d < 3; d++)
        if (lr->order[d] < 1 || lr->order[d] > SL_LR_MAX_ORDER)
            return sl_err_set(err, SL_ERR_UNSUPPORTED, "order %d in %c is outside 1..%d (degree up to %d)",
                              lr->order[d], axis_name[d], SL_LR_MAX_ORDER, SL_LR_MAX_ORDER - 1);
    if (lr->dim != 1 && lr->dim != 3)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "dimension %d: only scalar (1) and vector (3)"
                          " LR-spline volumes are supported", lr->dim);
    if (lr->element_count == 0 || lr->basis_count == 0)
        return sl_err_set(err, SL_ERR_FORMAT, "an LR-spline volume needs at least one element and"
                          " one basis function (%zu, %zu)", lr->element_count, lr->basis_count);
    for (size_t i = 0; i < lr->basis_count; i++) {
        sl_status st = check_basis(lr, i, err);
        if (st != SL_OK)
            return st;
    }
    for (int d = 0; d < 3; d++) {
        lr->domain_lo[d] = DBL_MAX;
        lr->domain_hi[d] = -DBL_MAX;
        lr->min_side[d] = DBL_MAX;
        lr->max_side[d] = 0.0;
    }
    double volume_sum = 0.0;
    for (size_t i = 0; i < lr->element_count; i++) {
        const sl_lr_element *e = &lr->elements[i];
        double vol = 1.0;
        for (int d = 0; d < 3; d++) {
            if (!isfinite(e->lo[d]) || !isfinite(e->hi[d]) || !(e->hi[d] > e->lo[d]))
                return sl_err_set(err, SL_ERR_FORMAT, "element %zu: empty or non-finite box in %c",
                                  i, axis_name[d]);
            double side = e->hi[d] - e->lo[d];
            vol *= side;
            lr->domain_lo[d] = fmin(lr->domain_lo[d], e->lo[d]);
            lr->domain_hi[d] = fmax(lr->domain_hi[d], e->hi[d]);
            lr->min_side[d] = fmin(lr->min_side[d], side);
            lr->max_side[d] = fmax(lr->max_side[d], side);
        }
        volume_sum += vol;
        if (e->basis_count == 0)
            return sl_err_set(err, SL_ERR_FORMAT, "element %zu: no basis function covers it", i);
        if ((size_t)e->basis_offset + e->basis_count > lr->element_basis_count)
            return sl_err_set(err, SL_ERR_FORMAT, "element %zu: basis list overruns the %zu entries",
                              i, lr->element_basis_count);
        for (uint32_t k = 0; k < e->basis_count; k++) {
            uint32_t id = lr->element_basis[e->basis_offset + k];
            if (id >= lr->basis_count)
                return sl_err_set(err, SL_ERR_FORMAT, "element %zu: basis id %u out of range (%zu basis"
                                  " functions)", i, id, lr->basis_count);
            if (!basis_covers(lr, &lr->basis[id], e))
                return sl_err_set(err, SL_ERR_FORMAT, "element %zu: listed basis function %u does not"
                                  " cover it with one polynomial piece", i, id);
        }
    }
    for (size_t i = 0; i < lr->meshrect_count; i++) {
        sl_status st = check_meshrect(lr, i, err);
        if (st != SL_OK)
            return st;
    }
    double domain_volume = 1.0;
    for (int d = 0; d < 3; d++)
        domain_volume *= lr->domain_hi[d] - lr->domain_lo[d];
    if (fabs(volume_sum - domain_volume) > 1e-9 * domain_volume)
        return sl_err_set(err, SL_ERR_FORMAT, "the elements' volumes add up to %.17g, not the domain's"
                          " %.17g: they leave a gap or overlap", volume_sum, domain_volume);
    lr->value_min = DBL_MAX;
    lr->value_max = -DBL_MAX;
    for (size_t i = 0; i < lr->element_count; i++) {
        const sl_lr_element *e = &lr->elements[i];
        for (int a = 0; a < 9; a++) {
            double p[3], v[SL_LR_MAX_DIM];
            for (int d = 0; d < 3; d++)
                p[d] = a == 8 ? 0.5 * (e->lo[d] + e->hi[d]) : (a >> d & 1) ? e->hi[d] : e->lo[d];
            sl_status st = sl_lr_eval(lr, p, (long)i, v, NULL, err);
            if (st != SL_OK)
                return st;
            if (a == 8) {
                /* The centre: the scaled basis must be a partition of unity. */
                double sum = 0.0;
                for (uint32_t k = 0; k < e->basis_count; k++) {
                    const sl_lr_basis *b = &lr->basis[lr->element_basis[e->basis_offset + k]];
                    double prod = b->gamma, nv, nd;
                    for (int d = 0; d < 3; d++) {
                        sl_lr_bspline_piece(b->knots[d], lr->order[d], e->lo[d], e->hi[d], p[d], &nv, &nd);
                        prod *= nv;
                    }
                    sum += prod;
                }
                if (fabs(sum - 1.0) > 1e-6)
                    return sl_err_set(err, SL_ERR_FORMAT, "element %zu: the scaled basis functions sum to"
                                      " %.9g at its centre, not 1 (wrong scaling weights or a missing"
                                      " basis function)", i, sum);
            }
            for (int c = 0; c < lr->dim; c++)
                if (!isfinite(v[c]))
                    return sl_err_set(err, SL_ERR_FORMAT, "element %zu: value not finite", i);
            add_value_sample(lr, v);
        }
    }
    return SL_OK;
}

double sl_lr_level_ratio(const sl_lr_volume *lr)
{
    double ratio = 1.0;
    for (int d = 0; d < 3; d++)
        if (lr->min_side[d] > 0.0 && lr->min_side[d] < DBL_MAX)
            ratio = fmax(ratio, lr->max_side[d] / lr->min_side[d]);
    return ratio;
}
