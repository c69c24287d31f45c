/* test_lr_refine.c — local refinement by mesh rectangle insertion
 * (renderer/lrspline/lr_refine.c).
 *
 * Refinement must not change the function: f is evaluated with sl_lr_eval
 * (from the LR basis) at 10^4 random points and on points of the knot
 * planes (old and new) before and after, and must agree to 1e-12 relative to
 * max |f| (the random local rounds check every fifth random point and all
 * plane points, the last round all 10^4). Every refined model passes sl_lr_finish (partition of unity,
 * coverage, no gap). A full-width plane gives exactly the tensor product with
 * that knot: (n_u + 1) n_v n_w basis functions, all gamma = 1, the same knot
 * vectors as sl_lr_tensor_product builds. Random local rectangles in all
 * three directions and structured refinement of random basis functions keep
 * all this and make the mesh local (sl_lr_level_ratio > 1). Bad rectangles
 * are refused.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_refine.h"
#include "sl_test.h"

static uint64_t rng = 88172645463325252ull;
static double urand(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static void coef_random(void *user, const int ijk[3], const double g[3], double *c)
{
    (void)ijk;
    (void)g;
    int dim = *(int *)user;
    for (int q = 0; q < dim; q++)
        c[q] = 2.0 * urand() - 1.0;
}

#define NPTS 10000
#define NPLANE 3000

typedef struct probe {
    double p[NPTS + NPLANE][3];
    double v[NPTS + NPLANE][3];
    double scale;
} probe;

static void make_points(probe *pr, const sl_lr_volume *lr, const double *planes[3], const int nplanes[3])
{
    for (int i = 0; i < NPTS + NPLANE; i++)
        for (int d = 0; d < 3; d++)
            pr->p[i][d] = lr->domain_lo[d] + urand() * (lr->domain_hi[d] - lr->domain_lo[d]);
    for (int i = NPTS; i < NPTS + NPLANE; i++) {
        int d = i % 3;
        pr->p[i][d] = planes[d][(i / 3) % nplanes[d]];
    }
}

/* Every `step`-th point of the random ones and all plane points. */
static void sample_every(const sl_lr_volume *lr, probe *pr, int store, int step, double *max_diff)
{
    sl_err err = {0};
    *max_diff = 0.0;
    for (int i = 0; i < NPTS + NPLANE; i += i < NPTS ? step : 1) {
        double v[3];
        if (sl_lr_eval(lr, pr->p[i], -1, v, NULL, &err) != SL_OK) {
            *max_diff = INFINITY;
            return;
        }
        for (int c = 0; c < lr->dim; c++) {
            if (store) {
                pr->v[i][c] = v[c];
                pr->scale = fmax(pr->scale, fabs(v[c]));
            } else {
                *max_diff = fmax(*max_diff, fabs(v[c] - pr->v[i][c]));
            }
        }
    }
}

static void sample(const sl_lr_volume *lr, probe *pr, int store, double *max_diff)
{
    sample_every(lr, pr, store, 1, max_diff);
}

static void make_tensor(sl_lr_volume *lr, const int order[3], int dim, const double *k[3], const int n[3])
{
    sl_err err = {0};
    SL_CHECK(sl_lr_tensor_product(lr, order, dim, k, n, coef_random, &dim, &err) == SL_OK);
}

static void test_full_plane(void)
{
    const double u[] = {0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1};
    const double v[] = {0, 0, 0, 1, 2, 2, 2};
    const double w[] = {-1, -1, -1, -0.5, 0, 1, 1, 1};
    const double *k[3] = {u, v, w};
    int order[3] = {3, 3, 3}, n[3] = {9, 7, 8};
    sl_lr_volume lr;
    make_tensor(&lr, order, 1, k, n);
    static probe pr;
    memset(&pr, 0, sizeof pr);
    const double pu[] = {0.25, 0.5, 0.6, 0.75}, pv[] = {1, 0.3}, pw[] = {-0.5, 0, 0.2};
    const double *planes[3] = {pu, pv, pw};
    int np[3] = {4, 2, 3};
    make_points(&pr, &lr, planes, np);
    double diff;
    sample(&lr, &pr, 1, &diff);
    size_t nb0 = lr.basis_count;
    sl_lr_meshrect r = {{0.6, 0, -1}, {0.6, 2, 1}, 1};
    sl_err err = {0};
    SL_CHECK(sl_lr_refine(&lr, &r, 1, &err) == SL_OK);
    SL_CHECK_MSG(lr.basis_count == (6 + 1) * 4 * 5 && nb0 == 6 * 4 * 5, "%zu basis functions", lr.basis_count);
    SL_CHECK(lr.element_count == 5 * 2 * 3);
    sample(&lr, &pr, 0, &diff);
    SL_CHECK_MSG(diff <= 1e-12 * pr.scale, "full plane: f changed by %g", diff);
    double gmin = 1, gmax = 1;
    for (size_t i = 0; i < lr.basis_count; i++) {
        gmin = fmin(gmin, lr.basis[i].gamma);
        gmax = fmax(gmax, lr.basis[i].gamma);
    }
    SL_CHECK_MSG(fabs(gmin - 1) < 1e-14 && fabs(gmax - 1) < 1e-14, "gamma in [%g, %g]", gmin, gmax);
    /* The same knot vectors as the tensor product with the knot. */
    const double u2[] = {0, 0, 0, 0.25, 0.5, 0.6, 0.75, 1, 1, 1};
    const double *k2[3] = {u2, v, w};
    int n2[3] = {10, 7, 8};
    sl_lr_volume t;
    make_tensor(&t, order, 1, k2, n2);
    size_t matched = 0;
    for (size_t i = 0; i < t.basis_count; i++)
        for (size_t j = 0; j < lr.basis_count; j++)
            if (memcmp(t.basis[i].knots, lr.basis[j].knots, sizeof t.basis[i].knots) == 0) {
                matched++;
                break;
            }
    SL_CHECK(matched == t.basis_count);
    sl_lr_free(&t);
    /* The plane again changes nothing. */
    SL_CHECK(sl_lr_refine(&lr, &r, 1, &err) == SL_OK);
    SL_CHECK(lr.basis_count == 7 * 4 * 5);
    /* Refusals. */
    sl_lr_meshrect bad1 = {{0.3, 0, -1}, {0.4, 2, 1}, 1};
    SL_CHECK(sl_lr_refine(&lr, &bad1, 1, &err) == SL_ERR_INVALID);
    sl_lr_meshrect bad2 = {{0.3, 0, -1}, {0.3, 3, 1}, 1};
    SL_CHECK(sl_lr_refine(&lr, &bad2, 1, &err) == SL_ERR_INVALID);
    sl_lr_meshrect bad3 = {{0, 0, -1}, {0, 2, 1}, 1};
    SL_CHECK(sl_lr_refine(&lr, &bad3, 1, &err) == SL_ERR_INVALID);
    SL_CHECK(lr.basis_count == 7 * 4 * 5);
    sl_lr_free(&lr);
}

static void test_local(const int order[3], int dim)
{
    double knots[3][16];
    int n[3];
    const double *k[3];
    for (int d = 0; d < 3; d++) {
        int cells = 3 + d, m = 0;
        for (int q = 0; q < order[d]; q++)
            knots[d][m++] = 0;
        for (int c = 1; c < cells; c++)
            knots[d][m++] = (double)c / cells * (1 + d);
        for (int q = 0; q < order[d]; q++)
            knots[d][m++] = 1 + d;
        n[d] = m;
        k[d] = knots[d];
    }
    sl_lr_volume lr;
    make_tensor(&lr, order, dim, k, n);
    static probe pr;
    memset(&pr, 0, sizeof pr);
    const double pu[] = {1.0 / 3, 0.5, 0.25}, pv[] = {0.5, 1, 1.5}, pw[] = {0.6, 1.5, 2.25};
    const double *planes[3] = {pu, pv, pw};
    int np[3] = {3, 3, 3};
    make_points(&pr, &lr, planes, np);
    double diff;
    sample(&lr, &pr, 1, &diff);
    sl_err err = {0};
    int rect_growth = 0;
    /* Rounds cycle through random rectangles, structured refinement of
     * random basis functions and minimal-span refinement of random elements. */
    for (int round = 0; round < 9; round++) {
        size_t before = lr.basis_count;
        sl_status st;
        int kind = round % 3;
        if (kind == 0) {
            sl_lr_meshrect r[3];
            for (int q = 0; q < 3; q++) {
                int d = (q + round) % 3;
                for (int a = 0; a < 3; a++) {
                    double lo = lr.domain_lo[a], ext = lr.domain_hi[a] - lo;
                    double x0 = lo + urand() * ext * 0.3, x1 = x0 + ext * (0.3 + 0.4 * urand());
                    r[q].lo[a] = x0;
                    r[q].hi[a] = x1;
                }
                double v = lr.domain_lo[d] + (0.1 + 0.8 * urand()) * (lr.domain_hi[d] - lr.domain_lo[d]);
                r[q].lo[d] = r[q].hi[d] = v;
                r[q].multiplicity = 1;
            }
            st = sl_lr_refine(&lr, r, 3, &err);
        } else if (kind == 1) {
            uint32_t ids[4];
            for (int q = 0; q < 4; q++)
                ids[q] = (uint32_t)(urand() * (double)lr.basis_count);
            st = sl_lr_refine_basis(&lr, ids, 4, NULL, round == 4, NULL, &err);
        } else {
            uint32_t ids[3];
            for (int q = 0; q < 3; q++)
                ids[q] = (uint32_t)(urand() * (double)lr.element_count);
            size_t inserted = 0;
            st = sl_lr_refine_elements(&lr, ids, 3, NULL, round == 5, &inserted, &err);
            SL_CHECK(st != SL_OK || inserted == 9); /* one rectangle per direction and element */
            uint32_t bad = (uint32_t)lr.element_count;
            SL_CHECK(sl_lr_refine_elements(&lr, &bad, 1, NULL, 0, NULL, &err) == SL_ERR_INVALID);
        }
        SL_CHECK_MSG(st == SL_OK, "round %d: %s", round, err.message);
        if (st != SL_OK)
            break;
        /* A random rectangle may split no function (the mesh gains it all the
         * same); structured and minimal-span refinement always split one. */
        SL_CHECK_MSG(kind == 0 ? lr.basis_count >= before : lr.basis_count > before,
                     "order %d%d%d round %d: %zu basis functions before and after", order[0], order[1], order[2],
                     round, before);
        rect_growth += kind == 0 && lr.basis_count > before;
        /* A fifth of the random points per round, all of them after the last. */
        sample_every(&lr, &pr, 0, round == 8 ? 1 : 5, &diff);
        SL_CHECK_MSG(diff <= 1e-12 * pr.scale, "order %d%d%d dim %d round %d: f changed by %g (scale %g)",
                     order[0], order[1], order[2], dim, round, diff, pr.scale);
        SL_CHECK(sl_lr_finish(&lr, &err) == SL_OK);
    }
    SL_CHECK_MSG(rect_growth > 0, "no random rectangle split a basis function");
    SL_CHECK_MSG(sl_lr_level_ratio(&lr) > 1.0, "level ratio %g", sl_lr_level_ratio(&lr));
    /* Element lists hold each basis function once, and never more than the
     * basis functions overlapping the element. */
    int dup = 0;
    for (size_t e = 0; e < lr.element_count && !dup; e++) {
        const sl_lr_element *x = &lr.elements[e];
        for (uint32_t a = 0; a < x->basis_count; a++)
            for (uint32_t b = a + 1; b < x->basis_count; b++)
                dup |= lr.element_basis[x->basis_offset + a] == lr.element_basis[x->basis_offset + b];
    }
    SL_CHECK(!dup);
    sl_lr_free(&lr);
}

int main(void)
{
    test_full_plane();
    const int o333[3] = {3, 3, 3}, o234[3] = {2, 3, 4}, o421[3] = {4, 2, 1};
    test_local(o333, 1);
    test_local(o234, 3);
    test_local(o421, 1);
    SL_TEST_END();
}
