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
 * match the hand values; the blocks reuse the model's look-up only when it is
 * the structure asked for (auto, the default forest), and their float domain
 * box is the union of the element boxes.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_bezier.h"
#include "lrspline/sl_lr_lookup.h"
#include "lr_test_models.h"
#include "sl_test.h"

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

static void test_tensor(int o0, int o1, int o2, int dim)
{
    sl_lr_volume lr;
    memset(&lr, 0, sizeof lr);
    SL_CHECK(lr_test_tensor(&lr, o0, o1, o2, dim, 0));
    if (!lr.element_count)
        return;
    sl_err err;
    sl_lr_bezier bz;
    sl_status st = sl_lr_bezier_build(&lr, SL_LR_LOOKUP_AUTO, 0, &bz, &err);
    SL_CHECK_MSG(st == SL_OK, "bezier: %s", err.message);
    if (st == SL_OK) {
        char name[64];
        snprintf(name, sizeof name, "tensor degree (%d,%d,%d) dim %d", o0 - 1, o1 - 1, o2 - 1, dim);
        compare(&lr, &bz, 100000, name);
        sl_lr_bezier_free(&bz);
    }
    sl_lr_free(&lr);
}

static void test_refined(int dim)
{
    sl_lr_volume lr;
    memset(&lr, 0, sizeof lr);
    SL_CHECK(lr_test_refined(&lr, dim, 0));
    if (!lr.element_count)
        return;
    sl_err err;
    /* Different basis lists: the refined corner element has other functions than the far one. */
    SL_CHECK(lr.elements[0].basis_count != lr.elements[10].basis_count ||
             memcmp(lr.element_basis + lr.elements[0].basis_offset,
                    lr.element_basis + lr.elements[10].basis_offset,
                    sizeof(uint32_t) * lr.elements[0].basis_count) != 0);
    sl_lr_bezier bz;
    sl_status st = sl_lr_bezier_build(&lr, SL_LR_LOOKUP_AUTO, 0, &bz, &err);
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

/* The blocks take the model's index when it is the structure asked for
 * (auto; the texture; the default forest) and build their own otherwise;
 * the domain box the GPU uniforms use is the float union of the element
 * boxes. Two models: the hand-refined one (knots on a 0.5 grid: the index is
 * the texture) and an uneven tensor product (the index is the forest). */
static void check_lookup_reuse(sl_lr_volume *lr, sl_lr_lookup_kind index_kind)
{
    sl_err err;
    sl_lr_bezier bz;
    /* No index yet: built. */
    SL_CHECK(lr->index == NULL);
    SL_CHECK(sl_lr_bezier_build(lr, SL_LR_LOOKUP_AUTO, 0, &bz, &err) == SL_OK);
    SL_CHECK(bz.lookup == &bz.own_lookup && bz.lookup_kind == index_kind);
    for (int d = 0; d < 3; d++)
        SL_CHECK(bz.domain_lo[d] == (float)lr->domain_lo[d] && bz.domain_hi[d] == (float)lr->domain_hi[d]);
    sl_lr_bezier_free(&bz);
    SL_CHECK(sl_lr_index(lr, &err) == SL_OK);
    SL_CHECK(lr->index && lr->index->kind == index_kind);
    int texture = index_kind == SL_LR_LOOKUP_TEXTURE;
    const struct { sl_lr_lookup_kind kind; int axis, reused; } cases[] = {
        {SL_LR_LOOKUP_AUTO, 0, 1}, {SL_LR_LOOKUP_AUTO, 8, 1}, {SL_LR_LOOKUP_TEXTURE, 0, texture},
        {SL_LR_LOOKUP_KDFOREST, 0, !texture}, {SL_LR_LOOKUP_KDFOREST, SL_LR_FOREST_DEFAULT_AXIS, !texture},
        {SL_LR_LOOKUP_KDFOREST, 4, 0}, {SL_LR_LOOKUP_KDTREE, 0, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        sl_status st = sl_lr_bezier_build(lr, cases[i].kind, cases[i].axis, &bz, &err);
        if (cases[i].kind == SL_LR_LOOKUP_TEXTURE && !texture) { /* refused by the builder, not taken from the index */
            SL_CHECK(st == SL_ERR_UNSUPPORTED);
            continue;
        }
        SL_CHECK_MSG(st == SL_OK, "case %zu: %s", i, err.message);
        if (st != SL_OK)
            continue;
        SL_CHECK_MSG((bz.lookup == lr->index) == cases[i].reused, "case %zu: index %s", i,
                     cases[i].reused ? "not reused" : "reused for another structure");
        SL_CHECK(bz.lookup_kind == bz.lookup->kind);
        sl_lr_bezier_free(&bz);
    }
}

static void test_lookup_reuse(void)
{
    sl_lr_volume lr;
    memset(&lr, 0, sizeof lr);
    SL_CHECK(lr_test_refined(&lr, 1, 0));
    if (lr.element_count)
        check_lookup_reuse(&lr, SL_LR_LOOKUP_TEXTURE);
    sl_lr_free(&lr);
    memset(&lr, 0, sizeof lr);
    SL_CHECK(lr_test_tensor(&lr, 3, 3, 3, 1, 0));
    if (lr.element_count)
        check_lookup_reuse(&lr, SL_LR_LOOKUP_KDFOREST);
    sl_lr_free(&lr);
}

int main(void)
{
    test_bernstein_hand();
    test_lookup_reuse();
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
