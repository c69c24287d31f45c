/* lr_test_models.h — LR-spline volumes the lrspline tests share: a random
 * generator, uneven open knot vectors (optionally dyadic, so they are exact
 * in float), tensor products with random coefficients, and a locally refined
 * model built by hand (tensor mesh x, y in {0, 1, 2}; the line x = 0.5 for
 * y in [0, 1] splits the functions it crosses, then the line y = 0.5 for
 * x in [0, 0.5], which leaves a function with scaling weight 0.5; z quadratic
 * on the knots 0, 0.4 (0.375 when dyadic), 1). Header-only (static). */
#ifndef LR_TEST_MODELS_H
#define LR_TEST_MODELS_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lrspline/sl_lr.h"

static unsigned long long rng_state = 0x9e3779b97f4a7c15ull;
static double urand(void)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

static void coef_random(void *user, const int ijk[3], const double g[3], double *coef)
{
    int dim = *(int *)user;
    (void)ijk;
    for (int c = 0; c < dim; c++)
        coef[c] = (urand() * 2.0 - 1.0) * 10.0 + 0.3 * g[0] - g[1] * g[2];
}

/* Open knot vector of `order` on [0, len] with `inner` uneven inner knots;
 * dyadic: multiples of 1/256. Returns the knot count. */
static int make_knots(double *t, int order, int inner, double len, int dyadic)
{
    int n = 0;
    for (int i = 0; i < order; i++)
        t[n++] = 0.0;
    for (int i = 1; i <= inner; i++) {
        double x = (double)i / (inner + 1);
        double v = len * (x + 0.3 * x * (1 - x) * sin(7.0 * x)); /* strictly increasing, uneven */
        t[n++] = dyadic ? floor(v * 256.0 + 0.5) / 256.0 : v;
    }
    for (int i = 0; i < order; i++)
        t[n++] = len;
    return n;
}

/* A tensor product of the given orders (non-uniform knots, a double inner
 * knot in y for order >= 3) with random coefficients; 0 on failure. */
static int lr_test_tensor(sl_lr_volume *lr, int o0, int o1, int o2, int dim, int dyadic)
{
    int order[3] = {o0, o1, o2};
    double kx[32], ky[32], kz[32];
    double *k[3] = {kx, ky, kz};
    int count[3];
    count[0] = make_knots(kx, o0, 5, 2.0, dyadic);
    count[1] = make_knots(ky, o1, 4, 1.0, dyadic);
    count[2] = make_knots(kz, o2, 6, 3.5, dyadic);
    if (o1 >= 3)
        ky[o1 + 1] = ky[o1];
    sl_err err;
    if (sl_lr_tensor_product(lr, order, dim, (const double *const *)k, count, coef_random, &dim, &err) != SL_OK) {
        fprintf(stderr, "tensor product: %s\n", err.message);
        return 0;
    }
    return 1;
}

typedef struct hand_fn { double x[3], y[3]; double gamma; } hand_fn;

/* The hand-refined model (see the header): 1 on success. */
static int lr_test_refined(sl_lr_volume *out, int dim, int dyadic)
{
    static const hand_fn fn[] = {
        {{0, 0, 0.5}, {0, 0, 0.5}, 1.0},
        {{0, 0, 0.5}, {0, 0.5, 1}, 0.5},
        {{0, 0.5, 1}, {0, 0, 1}, 1.0},
        {{0.5, 1, 2}, {0, 0, 1}, 1.0},
        {{1, 2, 2}, {0, 0, 1}, 1.0},
        {{0, 0, 1}, {0, 1, 2}, 1.0},
        {{0, 1, 2}, {0, 1, 2}, 1.0},
        {{1, 2, 2}, {0, 1, 2}, 1.0},
        {{0, 0, 1}, {1, 2, 2}, 1.0},
        {{0, 1, 2}, {1, 2, 2}, 1.0},
        {{1, 2, 2}, {1, 2, 2}, 1.0},
    };
    const double zs = dyadic ? 0.375 : 0.4;
    const double zk[4][4] = {{0, 0, 0, zs}, {0, 0, zs, 1}, {0, zs, 1, 1}, {zs, 1, 1, 1}};
    static const double box[][4] = { /* x0 x1 y0 y1, z split at 0.4 */
        {0, 0.5, 0, 0.5}, {0, 0.5, 0.5, 1}, {0.5, 1, 0, 1}, {1, 2, 0, 1}, {0, 1, 1, 2}, {1, 2, 1, 2},
    };
    const size_t nfx = sizeof fn / sizeof fn[0], nz = 4, nbox = sizeof box / sizeof box[0];
    size_t nb = nfx * nz, ne = nbox * 2;
    sl_lr_volume lr;
    sl_err err;
    sl_status st = sl_lr_alloc(&lr, nb, 0, ne, ne * nb, &err);
    if (st != SL_OK)
        return 0;
    lr.order[0] = 2;
    lr.order[1] = 2;
    lr.order[2] = 3;
    lr.dim = dim;
    for (size_t f = 0; f < nfx; f++)
        for (size_t q = 0; q < nz; q++) {
            sl_lr_basis *b = &lr.basis[f * nz + q];
            memcpy(b->knots[0], fn[f].x, sizeof fn[f].x);
            memcpy(b->knots[1], fn[f].y, sizeof fn[f].y);
            memcpy(b->knots[2], zk[q], sizeof zk[q]);
            b->gamma = fn[f].gamma;
            for (int c = 0; c < dim; c++)
                b->coef[c] = urand() * 4.0 - 2.0;
        }
    size_t off = 0;
    for (size_t e = 0; e < ne; e++) {
        sl_lr_element *el = &lr.elements[e];
        const double *bx = box[e / 2];
        double z0 = (e % 2) ? zs : 0.0, z1 = (e % 2) ? 1.0 : zs;
        double lo[3] = {bx[0], bx[2], z0}, hi[3] = {bx[1], bx[3], z1};
        memcpy(el->lo, lo, sizeof lo);
        memcpy(el->hi, hi, sizeof hi);
        el->basis_offset = (uint32_t)off;
        for (size_t b = 0; b < nb; b++) {
            int in = 1;
            for (int d = 0; d < 3; d++)
                in &= lr.basis[b].knots[d][0] <= lo[d] && hi[d] <= lr.basis[b].knots[d][lr.order[d]];
            if (in)
                lr.element_basis[off++] = (uint32_t)b;
        }
        el->basis_count = (uint32_t)(off - el->basis_offset);
    }
    lr.element_basis_count = off;
    st = sl_lr_finish(&lr, &err);
    if (st != SL_OK) {
        fprintf(stderr, "hand-refined model refused: %s\n", err.message);
        sl_lr_free(&lr);
        return 0;
    }
    *out = lr;
    return 1;
}
#endif
