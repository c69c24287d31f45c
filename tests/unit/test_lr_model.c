/* test_lr_model.c — the LR-spline model and its CPU reference evaluator
 * (renderer/lrspline: lr_model.c, lr_eval.c, lr_tensor.c).
 *
 * Checked against formulas written out by hand, sharing no code with the
 * evaluator: the uniform cubic B-spline's four pieces and their derivatives;
 * linear precision (coefficients at the Greville points reproduce x, for
 * scalar and vector volumes of mixed degree 0..3 and uneven knots, with the
 * Jacobian the identity); quadratic reproduction (degree-2 coefficients
 * t1*t2 reproduce x^2); the element rule on knot planes, the upper face and
 * outside; and the refusals of sl_lr_finish on broken models.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lrspline/sl_lr.h"
#include "sl_test.h"

static double cubic_piece(double x)
{
    if (x < 0 || x > 4) return 0;
    if (x <= 1) return x * x * x / 6;
    if (x <= 2) return (-3 * x * x * x + 12 * x * x - 12 * x + 4) / 6;
    if (x <= 3) return (3 * x * x * x - 24 * x * x + 60 * x - 44) / 6;
    return (4 - x) * (4 - x) * (4 - x) / 6;
}

static double cubic_derivative(double x)
{
    if (x < 0 || x > 4) return 0;
    if (x <= 1) return x * x / 2;
    if (x <= 2) return (-9 * x * x + 24 * x - 12) / 6;
    if (x <= 3) return (9 * x * x - 48 * x + 60) / 6;
    return -(4 - x) * (4 - x) / 2;
}

static void test_uniform_cubic(void)
{
    const double t[5] = {0, 1, 2, 3, 4};
    for (int span = 0; span < 4; span++)
        for (int s = 0; s <= 20; s++) {
            double x = span + s / 20.0, v, d;
            sl_lr_bspline_piece(t, 4, span, span + 1, x, &v, &d);
            SL_CHECK_NEAR(v, cubic_piece(x), 1e-14);
            SL_CHECK_NEAR(d, cubic_derivative(x), 1e-13);
        }
    double v, d;
    sl_lr_bspline_piece(t, 4, 4, 5, 4.5, &v, &d);
    SL_CHECK(v == 0 && d == 0);
}

typedef struct knot_set {
    const double *knots[3];
    int order[3];
    int mode; /* 0: x (Greville), 1: vector = Greville point, 2: x^2 by blossom */
} knot_set;

static void coef_fn(void *user, const int ijk[3], const double g[3], double *coef)
{
    const knot_set *ks = user;
    if (ks->mode == 0)
        coef[0] = g[0];
    else if (ks->mode == 1) {
        coef[0] = g[0];
        coef[1] = g[1];
        coef[2] = g[2];
    } else {
        const double *t = ks->knots[0] + ijk[0];
        coef[0] = t[1] * t[2]; /* blossom of x^2 at the inner knots, order 3 */
    }
}

static double frand(void) { return rand() / (double)RAND_MAX; }

static void test_precision(void)
{
    const double ku[] = {0, 0, 0, 0.3, 1.1, 2, 2, 2};           /* order 3 */
    const double kv[] = {-1, -1, -1, -1, 0.5, 0.75, 2, 2, 2, 2}; /* order 4 */
    const double kw[] = {5, 5, 6, 8, 8};                       /* order 2 */
    const int count[3] = {8, 10, 5};
    for (int mode = 0; mode < 3; mode++) {
        knot_set ks = {{ku, kv, kw}, {3, 4, 2}, mode};
        sl_lr_volume lr;
        sl_err err = {0};
        sl_status st = sl_lr_tensor_product(&lr, ks.order, mode == 1 ? 3 : 1, ks.knots, count, coef_fn, &ks, &err);
        SL_CHECK_MSG(st == SL_OK, "%s", err.message);
        if (st != SL_OK)
            continue;
        SL_CHECK(lr.element_count == 3 * 3 * 2);
        SL_CHECK(lr.basis_count == 5 * 6 * 3);
        SL_CHECK_NEAR(sl_lr_level_ratio(&lr), 1.5 / 0.25, 1e-12);
        double worst = 0, worst_grad = 0;
        for (int s = 0; s < 2000; s++) {
            double p[3] = {2 * frand(), -1 + 3 * frand(), 5 + 3 * frand()};
            if (s < 8) { /* corners of the domain */
                p[0] = s & 1 ? 2 : 0;
                p[1] = s & 2 ? 2 : -1;
                p[2] = s & 4 ? 8 : 5;
            }
            double v[3], g[9];
            st = sl_lr_eval(&lr, p, -1, v, g, &err);
            SL_CHECK_MSG(st == SL_OK, "%s", err.message);
            if (mode == 0) {
                worst = fmax(worst, fabs(v[0] - p[0]));
                worst_grad = fmax(worst_grad, fabs(g[0] - 1) + fabs(g[1]) + fabs(g[2]));
            } else if (mode == 1) {
                for (int c = 0; c < 3; c++) {
                    worst = fmax(worst, fabs(v[c] - p[c]));
                    for (int j = 0; j < 3; j++)
                        worst_grad = fmax(worst_grad, fabs(g[c * 3 + j] - (c == j)));
                }
            } else {
                worst = fmax(worst, fabs(v[0] - p[0] * p[0]));
                worst_grad = fmax(worst_grad, fabs(g[0] - 2 * p[0]) + fabs(g[1]) + fabs(g[2]));
            }
        }
        SL_CHECK_MSG(worst < 1e-13, "mode %d: value error %g", mode, worst);
        SL_CHECK_MSG(worst_grad < 1e-12, "mode %d: gradient error %g", mode, worst_grad);
        if (mode == 2)
            SL_CHECK_NEAR(lr.value_max, 4.0, 1e-12);
        sl_lr_free(&lr);
    }
}

static void test_element_rule(void)
{
    const double k[] = {0, 0, 1, 2, 2};
    const double *kk[3] = {k, k, k};
    const int order[3] = {2, 2, 2}, count[3] = {5, 5, 5};
    knot_set ks = {{k, k, k}, {2, 2, 2}, 0};
    sl_lr_volume lr;
    sl_err err = {0};
    SL_CHECK(sl_lr_tensor_product(&lr, order, 1, kk, count, coef_fn, &ks, &err) == SL_OK);
    /* Elements are x fastest: index = (k*2 + j)*2 + i. */
    double on_plane[3] = {1, 0.5, 1.5};
    SL_CHECK(sl_lr_find_element_linear(&lr, on_plane) == (1 * 2 + 0) * 2 + 1);
    double upper[3] = {2, 2, 2};
    SL_CHECK(sl_lr_find_element_linear(&lr, upper) == 7);
    double lower[3] = {0, 0, 0};
    SL_CHECK(sl_lr_find_element_linear(&lr, lower) == 0);
    double outside[3] = {2.0000001, 1, 1}, nan_point[3] = {NAN, 1, 1};
    SL_CHECK(sl_lr_find_element_linear(&lr, outside) == -1);
    SL_CHECK(sl_lr_find_element_linear(&lr, nan_point) == -1);
    double v;
    SL_CHECK(sl_lr_eval(&lr, outside, -1, &v, NULL, &err) == SL_ERR_INVALID);
    SL_CHECK(strstr(err.message, "outside") != NULL);

    /* Refusals, each on a fresh copy broken one way. */
    struct { const char *what; int kind; } cases[] = {
        {"out of range", 0}, {"no basis function", 1}, {"sum to", 2}, {"out of order", 3},
        {"gap or overlap", 4}, {"does not", 5}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        sl_lr_volume b;
        SL_CHECK(sl_lr_tensor_product(&b, order, 1, kk, count, coef_fn, &ks, &err) == SL_OK);
        switch (cases[c].kind) {
        case 0: b.element_basis[3] = (uint32_t)b.basis_count; break;
        case 1: b.elements[2].basis_count = 0; break;
        case 2: b.basis[4].gamma = 2.0; break;
        case 3: b.basis[1].knots[1][2] = -5; break;
        case 4: b.elements[5].hi[0] -= 0.25; break;
        case 5: b.element_basis[b.elements[0].basis_offset] = (uint32_t)(b.basis_count - 1); break;
        }
        sl_err e2 = {0};
        SL_CHECK(sl_lr_finish(&b, &e2) == SL_ERR_FORMAT);
        SL_CHECK_MSG(strstr(e2.message, cases[c].what) != NULL, "case %zu: %s", c, e2.message);
        sl_lr_free(&b);
    }
    sl_lr_free(&lr);
}

int main(void)
{
    test_uniform_cubic();
    test_precision();
    test_element_rule();
    SL_TEST_END();
}
