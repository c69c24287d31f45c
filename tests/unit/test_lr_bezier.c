/* test_lr_bezier.c — Bézier extraction of LR-spline elements
 * (renderer/lrspline/lr_bezier.c) against the independent reference
 * sl_lr_eval (lr_eval.c, Cox-de Boor straight from the LR basis).
 *
 * At 10^5 random points (plus knot planes and the upper faces) per model,
 * the de Casteljau value and gradient of the element's block agree with
 * the reference to 1e-12 relative (value: of the largest |coefficient|,
 * which bounds every value; gradient: of the largest reference gradient
 * seen), for tensor products of degrees (1,1,1), (2,2,2), (3,3,3), (1,2,3)
 * and (0,1,2) on non-uniform knots, scalar and vector, and for a locally
 * refined model built by hand (two partial mesh lines, scaling weight 0.5,
 * elements with different basis lists; sl_lr_finish checks the partition
 * of unity). Also: the per-element hull bounds every value sampled in it;
 * the univariate Bernstein coefficients of the uniform quadratic B-spline
 * match the hand values.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_bezier.h"
#include "sl_test.h"

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

/* Compares at n random points plus the knot-plane lattice; returns the max relative errors. */
static void compare(const sl_lr_volume *lr, const sl_lr_bezier *bz, int n, const char *name)
{
    double cmax = 0.0;
    for (size_t e = 0; e < bz->element_count * bz->stride; e++)
        cmax = fmax(cmax, fabs(bz->coef[e]));
    double gmax = 1e-300, max_ve = 0.0, max_ge = 0.0;
    int hull_fail = 0, eval_fail = 0;
    double *vr = malloc(sizeof(double) * (size_t)n * 3), *gr = malloc(sizeof(double) * (size_t)n * 9);
    double *vb = malloc(sizeof(double) * (size_t)n * 3), *gb = malloc(sizeof(double) * (size_t)n * 9);
    for (int i = 0; i < n; i++) {
        double p[3];
        for (int d = 0; d < 3; d++) {
            double lo = lr->domain_lo[d], hi = lr->domain_hi[d];
            int kind = i % 10;
            if (kind == 0 && lr->element_count > 0) { /* a knot plane: an element's face */
                size_t e = (size_t)(urand() * (double)lr->element_count);
                p[d] = urand() < 0.5 ? lr->elements[e].lo[d] : lr->elements[e].hi[d];
            } else if (kind == 1 && d == i % 3) {
                p[d] = hi; /* upper face */
            } else {
                p[d] = lo + (hi - lo) * urand();
            }
        }
        long e = sl_lr_find_element_linear(lr, p);
        sl_err err;
        if (e < 0 || sl_lr_eval(lr, p, e, vr + i * 3, gr + i * 9, &err) != SL_OK) {
            eval_fail++;
            continue;
        }
        sl_lr_bezier_eval(bz, (size_t)e, p, vb + i * 3, gb + i * 9);
        double mag = 0.0;
        for (int c = 0; c < lr->dim; c++) {
            max_ve = fmax(max_ve, fabs(vb[i * 3 + c] - vr[i * 3 + c]) / cmax);
            mag += vr[i * 3 + c] * vr[i * 3 + c];
            for (int j = 0; j < 3; j++)
                gmax = fmax(gmax, fabs(gr[i * 9 + c * 3 + j]));
        }
        mag = lr->dim == 1 ? vr[i * 3] : sqrt(mag);
        double slack = 1e-12 * cmax;
        if (mag < bz->hull_min[e] - slack || mag > bz->hull_max[e] + slack)
            hull_fail++;
    }
    for (int i = 0; i < n; i++)
        for (int c = 0; c < lr->dim; c++)
            for (int j = 0; j < 3; j++)
                max_ge = fmax(max_ge, fabs(gb[i * 9 + c * 3 + j] - gr[i * 9 + c * 3 + j]) / gmax);
    printf("%-28s elements %6zu  value rel err %.3e  gradient rel err %.3e\n", name, lr->element_count,
           max_ve, max_ge);
    SL_CHECK_MSG(eval_fail == 0, "%s: %d points not evaluated", name, eval_fail);
    SL_CHECK_MSG(max_ve <= 1e-12, "%s: value error %.3e relative", name, max_ve);
    SL_CHECK_MSG(max_ge <= 1e-12, "%s: gradient error %.3e relative", name, max_ge);
    SL_CHECK_MSG(hull_fail == 0, "%s: %d values outside their element's hull", name, hull_fail);
    free(vr);
    free(gr);
    free(vb);
    free(gb);
}

/* Open knot vector of `order` on [0, len] with `inner` uneven inner knots. */
static int make_knots(double *t, int order, int inner, double len)
{
    int n = 0;
    for (int i = 0; i < order; i++)
        t[n++] = 0.0;
    for (int i = 1; i <= inner; i++) {
        double x = (double)i / (inner + 1);
        t[n++] = len * (x + 0.3 * x * (1 - x) * sin(7.0 * x)); /* strictly increasing, uneven */
    }
    for (int i = 0; i < order; i++)
        t[n++] = len;
    return n;
}

static void test_tensor(int o0, int o1, int o2, int dim)
{
    int order[3] = {o0, o1, o2};
    double kx[32], ky[32], kz[32];
    double *k[3] = {kx, ky, kz};
    int count[3];
    count[0] = make_knots(kx, o0, 5, 2.0);
    count[1] = make_knots(ky, o1, 4, 1.0);
    count[2] = make_knots(kz, o2, 6, 3.5);
    if (o1 >= 3) { /* a double inner knot: reduced continuity */
        ky[o1 + 1] = ky[o1];
    }
    sl_lr_volume lr;
    sl_err err;
    sl_status st = sl_lr_tensor_product(&lr, order, dim, (const double *const *)k, count, coef_random, &dim, &err);
    SL_CHECK_MSG(st == SL_OK, "tensor product: %s", err.message);
    if (st != SL_OK)
        return;
    sl_lr_bezier bz;
    st = sl_lr_bezier_build(&lr, &bz, &err);
    SL_CHECK_MSG(st == SL_OK, "bezier: %s", err.message);
    if (st == SL_OK) {
        char name[64];
        snprintf(name, sizeof name, "tensor degree (%d,%d,%d) dim %d", o0 - 1, o1 - 1, o2 - 1, dim);
        compare(&lr, &bz, 100000, name);
        sl_lr_bezier_free(&bz);
    }
    sl_lr_free(&lr);
}

typedef struct hand_fn { double x[3], y[3]; double gamma; } hand_fn;

/* The locally refined model (x, y linear; z quadratic on [0, 0.4, 1]):
 * the biquadratic... see the header: tensor mesh x, y in {0, 1, 2}, then the
 * line x = 0.5 for y in [0, 1] and the line y = 0.5 for x in [0, 0.5]. */
static void test_refined(int dim)
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
    static const double zk[3][4] = {{0, 0, 0, 0.4}, {0, 0, 0.4, 1}, {0, 0.4, 1, 1}};
    static const double zk_last[4] = {0.4, 1, 1, 1};
    static const double box[][4] = { /* x0 x1 y0 y1, z split at 0.4 */
        {0, 0.5, 0, 0.5}, {0, 0.5, 0.5, 1}, {0.5, 1, 0, 1}, {1, 2, 0, 1}, {0, 1, 1, 2}, {1, 2, 1, 2},
    };
    const size_t nfx = sizeof fn / sizeof fn[0], nz = 4, nbox = sizeof box / sizeof box[0];
    size_t nb = nfx * nz, ne = nbox * 2;
    sl_lr_volume lr;
    sl_err err;
    sl_status st = sl_lr_alloc(&lr, nb, 0, ne, ne * nb, &err);
    SL_CHECK(st == SL_OK);
    if (st != SL_OK)
        return;
    lr.order[0] = 2;
    lr.order[1] = 2;
    lr.order[2] = 3;
    lr.dim = dim;
    for (size_t f = 0; f < nfx; f++)
        for (size_t q = 0; q < nz; q++) {
            sl_lr_basis *b = &lr.basis[f * nz + q];
            memcpy(b->knots[0], fn[f].x, sizeof fn[f].x);
            memcpy(b->knots[1], fn[f].y, sizeof fn[f].y);
            memcpy(b->knots[2], q < 3 ? zk[q] : zk_last, sizeof zk_last);
            b->gamma = fn[f].gamma;
            for (int c = 0; c < dim; c++)
                b->coef[c] = urand() * 4.0 - 2.0;
        }
    size_t off = 0;
    for (size_t e = 0; e < ne; e++) {
        sl_lr_element *el = &lr.elements[e];
        const double *bx = box[e / 2];
        double z0 = (e % 2) ? 0.4 : 0.0, z1 = (e % 2) ? 1.0 : 0.4;
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
    SL_CHECK_MSG(st == SL_OK, "hand-refined model refused: %s", err.message);
    if (st != SL_OK) {
        sl_lr_free(&lr);
        return;
    }
    /* Different basis lists: the refined corner element has other functions than the far one. */
    SL_CHECK(lr.elements[0].basis_count != lr.elements[10].basis_count ||
             memcmp(lr.element_basis + lr.elements[0].basis_offset,
                    lr.element_basis + lr.elements[10].basis_offset,
                    sizeof(uint32_t) * lr.elements[0].basis_count) != 0);
    sl_lr_bezier bz;
    st = sl_lr_bezier_build(&lr, &bz, &err);
    SL_CHECK_MSG(st == SL_OK, "bezier: %s", err.message);
    if (st == SL_OK) {
        compare(&lr, &bz, 100000, dim == 1 ? "locally refined dim 1" : "locally refined dim 3");
        sl_lr_bezier_free(&bz);
    }
    sl_lr_free(&lr);
}

static void test_bernstein_hand(void)
{
    /* Uniform quadratic B-spline on 0,1,2,3: on [1,2] it is
     * (-2x^2 + 6x - 3)/2 with Bernstein coefficients 1/2, 1, 1/2 ... check
     * with the piece's values: f(1) = 1/2, f(2) = 1/2, f'(1) = 1 -> middle
     * coefficient = f(1) + f'(1)/2 = 1. On [0,1]: x^2/2 -> 0, 0, 1/2.
     * On a sub-interval [0.5, 1] of span [0,1]: x^2/2 -> f(.5)=1/8,
     * f(.5)+f'(.5)*0.5/2 = 1/8 + 1/8 = 1/4, f(1) = 1/2. */
    const double t[4] = {0, 1, 2, 3};
    double beta[3];
    sl_lr_bernstein_piece(t, 3, 1, 2, beta);
    SL_CHECK_NEAR(beta[0], 0.5, 1e-15);
    SL_CHECK_NEAR(beta[1], 1.0, 1e-15);
    SL_CHECK_NEAR(beta[2], 0.5, 1e-15);
    sl_lr_bernstein_piece(t, 3, 0, 1, beta);
    SL_CHECK_NEAR(beta[0], 0.0, 1e-15);
    SL_CHECK_NEAR(beta[1], 0.0, 1e-15);
    SL_CHECK_NEAR(beta[2], 0.5, 1e-15);
    sl_lr_bernstein_piece(t, 3, 0.5, 1, beta);
    SL_CHECK_NEAR(beta[0], 0.125, 1e-15);
    SL_CHECK_NEAR(beta[1], 0.25, 1e-15);
    SL_CHECK_NEAR(beta[2], 0.5, 1e-15);
    /* Outside the support: zero. */
    sl_lr_bernstein_piece(t, 3, 3, 4, beta);
    SL_CHECK(beta[0] == 0.0 && beta[1] == 0.0 && beta[2] == 0.0);
}

int main(void)
{
    test_bernstein_hand();
    test_tensor(2, 2, 2, 1);
    test_tensor(3, 3, 3, 1);
    test_tensor(4, 4, 4, 1);
    test_tensor(2, 3, 4, 1);
    test_tensor(1, 2, 3, 1);
    test_tensor(2, 3, 4, 3);
    test_refined(1);
    test_refined(3);
    SL_TEST_END();
}
