/* lr_test_volumes.h — LR-spline volumes and probe points for the element
 * look-up tests and bench-lr-lookup (header-only, static functions).
 *
 * Tensor volumes come from sl_lr_tensor_product (finished models). The
 * locally refined element meshes are built here by recursively splitting
 * boxes near a point and near a sphere's surface (8 children at a fraction
 * `t` of each side: 0.5 dyadic, else non-dyadic) down to a given level; only
 * elements and the domain are filled (lrt_boxes_volume: a TEST-ONLY bypass
 * of sl_lr_finish, which would need a basis — the look-up reads nothing
 * else). Probe points mix uniform points, points on element faces, edges and
 * corners, on the domain's faces, edges and corners, and just outside.
 * Single-threaded; deterministic (own xorshift generator).
 */
#ifndef LR_TEST_VOLUMES_H
#define LR_TEST_VOLUMES_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lrspline/sl_lr.h"

typedef struct lrt_rng { uint64_t s; } lrt_rng;

static inline uint64_t lrt_next(lrt_rng *r)
{
    r->s ^= r->s << 13;
    r->s ^= r->s >> 7;
    r->s ^= r->s << 17;
    return r->s;
}

static inline double lrt_unit(lrt_rng *r) /* [0, 1) */
{
    return (double)(lrt_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

static inline void lrt_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)user;
    (void)ijk;
    coef[0] = g[0] + 2.0 * g[1] - g[2];
}

/* Tensor volume of `order` in every direction on the breakpoints bp[d][0..m[d]-1]
 * (open ends added). */
static inline sl_status lrt_tensor(sl_lr_volume *lr, int order, const double *const bp[3], const int m[3], sl_err *err)
{
    double *knots[3] = {NULL, NULL, NULL};
    int count[3];
    for (int d = 0; d < 3; d++) {
        count[d] = m[d] + 2 * (order - 1);
        knots[d] = malloc((size_t)count[d] * sizeof(double));
        if (!knots[d]) {
            for (int e = 0; e < d; e++)
                free(knots[e]);
            return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
        }
        int k = 0;
        for (int i = 0; i < order - 1; i++)
            knots[d][k++] = bp[d][0];
        for (int i = 0; i < m[d]; i++)
            knots[d][k++] = bp[d][i];
        for (int i = 0; i < order - 1; i++)
            knots[d][k++] = bp[d][m[d] - 1];
    }
    int orders[3] = {order, order, order};
    sl_status st = sl_lr_tensor_product(lr, orders, 1, (const double *const *)knots, count, lrt_coef, NULL, err);
    for (int d = 0; d < 3; d++)
        free(knots[d]);
    return st;
}

typedef struct lrt_boxes {
    double (*lo)[3], (*hi)[3];
    size_t n, cap;
} lrt_boxes;

typedef struct lrt_refine {
    double point[3];     /* refined to point_level around here */
    int point_level;
    double centre[3], radius; /* sphere surface refined to surface_level */
    int surface_level;
    double t;            /* split fraction */
} lrt_refine;

static inline int lrt_push(lrt_boxes *b, const double lo[3], const double hi[3])
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        double(*l)[3] = realloc(b->lo, cap * sizeof *l);
        if (!l)
            return 0;
        b->lo = l;
        double(*h)[3] = realloc(b->hi, cap * sizeof *h);
        if (!h)
            return 0;
        b->hi = h;
        b->cap = cap;
    }
    memcpy(b->lo[b->n], lo, 3 * sizeof(double));
    memcpy(b->hi[b->n], hi, 3 * sizeof(double));
    b->n++;
    return 1;
}

static inline int lrt_split(const lrt_refine *r, const double lo[3], const double hi[3], int level)
{
    if (level < r->point_level) {
        int in = 1;
        for (int d = 0; d < 3; d++)
            in &= r->point[d] >= lo[d] && r->point[d] <= hi[d];
        if (in)
            return 1;
    }
    if (level < r->surface_level) {
        double near = 0.0, far = 0.0;
        for (int d = 0; d < 3; d++) {
            double c = r->centre[d];
            double n = c < lo[d] ? lo[d] - c : c > hi[d] ? c - hi[d] : 0.0;
            double f = fmax(fabs(c - lo[d]), fabs(c - hi[d]));
            near += n * n;
            far += f * f;
        }
        if (sqrt(near) <= r->radius && sqrt(far) >= r->radius)
            return 1;
    }
    return 0;
}

static inline int lrt_refine_box(lrt_boxes *b, const lrt_refine *r, const double lo[3], const double hi[3], int level)
{
    if (!lrt_split(r, lo, hi, level))
        return lrt_push(b, lo, hi);
    double mid[3];
    for (int d = 0; d < 3; d++)
        mid[d] = r->t == 0.5 ? 0.5 * (lo[d] + hi[d]) : lo[d] + r->t * (hi[d] - lo[d]);
    for (int c = 0; c < 8; c++) {
        double a[3], z[3];
        for (int d = 0; d < 3; d++) {
            a[d] = (c >> d & 1) ? mid[d] : lo[d];
            z[d] = (c >> d & 1) ? hi[d] : mid[d];
        }
        if (!lrt_refine_box(b, r, a, z, level + 1))
            return 0;
    }
    return 1;
}

/* TEST-ONLY: a volume holding just the boxes as elements and their union
 * box as the domain, and min/max sides (no basis, not finished). */
static inline sl_status lrt_boxes_volume(sl_lr_volume *lr, const lrt_boxes *b, sl_err *err)
{
    sl_status st = sl_lr_alloc(lr, 0, 0, b->n, 0, err);
    if (st != SL_OK)
        return st;
    for (int d = 0; d < 3; d++) {
        lr->domain_lo[d] = lr->min_side[d] = INFINITY;
        lr->domain_hi[d] = lr->max_side[d] = -INFINITY;
    }
    for (size_t i = 0; i < b->n; i++)
        for (int d = 0; d < 3; d++) {
            lr->elements[i].lo[d] = b->lo[i][d];
            lr->elements[i].hi[d] = b->hi[i][d];
            lr->domain_lo[d] = fmin(lr->domain_lo[d], b->lo[i][d]);
            lr->domain_hi[d] = fmax(lr->domain_hi[d], b->hi[i][d]);
            lr->min_side[d] = fmin(lr->min_side[d], b->hi[i][d] - b->lo[i][d]);
            lr->max_side[d] = fmax(lr->max_side[d], b->hi[i][d] - b->lo[i][d]);
        }
    return SL_OK;
}

/* The refined volume: a base grid of base^3 boxes over [lo, hi], refined. */
static inline sl_status lrt_refined(sl_lr_volume *lr, const double lo[3], const double hi[3], int base, const lrt_refine *r,
                             sl_err *err)
{
    lrt_boxes b = {0};
    int ok = 1;
    for (int k = 0; k < base && ok; k++)
        for (int j = 0; j < base && ok; j++)
            for (int i = 0; i < base && ok; i++) {
                int ijk[3] = {i, j, k};
                double a[3], z[3];
                for (int d = 0; d < 3; d++) {
                    a[d] = ijk[d] == 0 ? lo[d] : lo[d] + (hi[d] - lo[d]) * ijk[d] / base;
                    z[d] = ijk[d] == base - 1 ? hi[d] : lo[d] + (hi[d] - lo[d]) * (ijk[d] + 1) / base;
                }
                ok = lrt_refine_box(&b, r, a, z, 0);
            }
    sl_status st = ok ? lrt_boxes_volume(lr, &b, err) : sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    free(b.lo);
    free(b.hi);
    return st;
}

/* Probe point i of a mix (double): kind = i % 10. */
static inline void lrt_probe(const sl_lr_volume *lr, lrt_rng *r, double p[3])
{
    int kind = (int)(lrt_next(r) % 10);
    const sl_lr_element *e = &lr->elements[lrt_next(r) % lr->element_count];
    for (int d = 0; d < 3; d++) {
        double lo = lr->domain_lo[d], hi = lr->domain_hi[d], w = hi - lo;
        double u = lrt_unit(r);
        switch (kind) {
        case 0: case 1: case 2: /* uniform, slightly beyond the domain */
            p[d] = lo - 0.02 * w + 1.04 * w * u;
            break;
        case 3: case 4: /* inside a random element, on one of its faces in some directions */
            p[d] = lrt_next(r) % 2 ? e->lo[d] + (e->hi[d] - e->lo[d]) * u : (lrt_next(r) % 2 ? e->lo[d] : e->hi[d]);
            break;
        case 5: /* element corners */
            p[d] = lrt_next(r) % 2 ? e->lo[d] : e->hi[d];
            break;
        case 6: /* next to an element face */
            p[d] = nextafter(lrt_next(r) % 2 ? e->lo[d] : e->hi[d], lrt_next(r) % 2 ? INFINITY : -INFINITY);
            break;
        case 7: case 8: /* domain faces, edges, corners */
            p[d] = lrt_next(r) % 2 ? lo + w * u : (lrt_next(r) % 2 ? lo : hi);
            break;
        default: /* just outside or just inside the domain's faces */
            p[d] = lrt_next(r) % 3 == 0 ? lo + w * u
                 : nextafter(lrt_next(r) % 2 ? lo : hi, lrt_next(r) % 2 ? INFINITY : -INFINITY);
            break;
        }
    }
}

/* The same mix for float points: element and domain values rounded to the
 * float below, at or above them. */
static inline void lrt_probe_float(const sl_lr_volume *lr, lrt_rng *r, float p[3])
{
    double q[3];
    lrt_probe(lr, r, q);
    for (int d = 0; d < 3; d++) {
        float f = (float)q[d];
        int s = (int)(lrt_next(r) % 4);
        p[d] = s == 1 ? nextafterf(f, -INFINITY) : s == 2 ? nextafterf(f, INFINITY) : f;
    }
}

#endif
