/* test_lr_roundtrip.c — our LRsplines writer (lr_write.c) and loader
 * (load_lr.c) agree: a locally refined model written as .lr and .lr.gz loads
 * back with the same counts, bit-identical knots, coefficients and scaling
 * weights, and identical values at random points and on knot planes; and a
 * file written by the format's reference library (tests/data/lr, see its
 * README) survives being rewritten by our writer. Runs from the source root.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "data/sl_load.h"
#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_refine.h"
#include "lrspline/sl_lr_write.h"
#include "sl_test.h"

static void coef_wave(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)user;
    (void)ijk;
    coef[0] = sin(3 * g[0]) * cos(2 * g[1]) + g[2] * g[2];
}

static double frand(void) { return rand() / (double)RAND_MAX; }

/* Max |a - b| over random points and points on element faces of a. */
static double max_difference(const sl_lr_volume *a, const sl_lr_volume *b)
{
    double worst = 0;
    for (int s = 0; s < 4000; s++) {
        double p[3];
        if (s < 2000) {
            for (int d = 0; d < 3; d++)
                p[d] = a->domain_lo[d] + frand() * (a->domain_hi[d] - a->domain_lo[d]);
        } else { /* a corner of an element: on knot planes */
            const sl_lr_element *e = &a->elements[(size_t)rand() % a->element_count];
            for (int d = 0; d < 3; d++)
                p[d] = (rand() & 1) ? e->hi[d] : e->lo[d];
        }
        double va[3], vb[3], ga[9], gb[9];
        sl_err err = {0};
        if (sl_lr_eval(a, p, -1, va, ga, &err) != SL_OK || sl_lr_eval(b, p, -1, vb, gb, &err) != SL_OK)
            return INFINITY;
        for (int c = 0; c < a->dim; c++) {
            worst = fmax(worst, fabs(va[c] - vb[c]));
            for (int j = 0; j < 3; j++)
                worst = fmax(worst, fabs(ga[c * 3 + j] - gb[c * 3 + j]));
        }
    }
    return worst;
}

static int same_model(const sl_lr_volume *a, const sl_lr_volume *b)
{
    if (a->basis_count != b->basis_count || a->element_count != b->element_count ||
        a->meshrect_count != b->meshrect_count || a->dim != b->dim ||
        memcmp(a->order, b->order, sizeof a->order) != 0)
        return 0;
    for (size_t i = 0; i < a->basis_count; i++) {
        const sl_lr_basis *x = &a->basis[i], *y = &b->basis[i];
        if (x->gamma != y->gamma)
            return 0;
        for (int c = 0; c < a->dim; c++)
            if (x->coef[c] != y->coef[c])
                return 0;
        for (int d = 0; d < 3; d++)
            for (int k = 0; k <= a->order[d]; k++)
                if (x->knots[d][k] != y->knots[d][k])
                    return 0;
    }
    return 1;
}

static sl_dataset *write_and_load(const sl_lr_volume *lr, const char *path)
{
    sl_err err = {0};
    sl_dataset *ds = NULL;
    sl_status st = sl_lr_write_file(lr, path, &err);
    SL_CHECK_MSG(st == SL_OK, "write %s: %s", path, err.message);
    if (st == SL_OK) {
        st = sl_load_file(path, &ds, &err);
        SL_CHECK_MSG(st == SL_OK, "load %s: %s", path, err.message);
    }
    unlink(path);
    return st == SL_OK ? ds : NULL;
}

static void test_refined_roundtrip(void)
{
    const double k[] = {0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1};
    const double *kk[3] = {k, k, k};
    const int order[3] = {3, 3, 3}, count[3] = {9, 9, 9};
    sl_lr_volume lr;
    sl_err err = {0};
    SL_CHECK(sl_lr_tensor_product(&lr, order, 1, kk, count, coef_wave, NULL, &err) == SL_OK);
    const sl_lr_meshrect rects[] = {
        {{0.125, 0, 0}, {0.125, 0.5, 0.5}, 1},
        {{0, 0.375, 0}, {0.5, 0.375, 0.25}, 1},
        {{0, 0, 0.0625}, {0.25, 0.25, 0.0625}, 1},
    };
    sl_status st = sl_lr_refine(&lr, rects, sizeof rects / sizeof rects[0], &err);
    SL_CHECK_MSG(st == SL_OK, "%s", err.message);
    SL_CHECK(sl_lr_level_ratio(&lr) > 1.5);
    char path[64];
    const char *suffix[2] = {".lr", ".lr.gz"};
    for (int z = 0; z < 2; z++) {
        snprintf(path, sizeof path, "/tmp/sl_roundtrip_%d%s", (int)getpid(), suffix[z]);
        sl_dataset *ds = write_and_load(&lr, path);
        if (!ds)
            continue;
        SL_CHECK(ds->kind == SL_DATASET_LR && ds->lr);
        SL_CHECK(same_model(&lr, ds->lr));
        double diff = max_difference(&lr, ds->lr);
        SL_CHECK_MSG(diff == 0.0, "%s: values differ by %g after the round trip", suffix[z], diff);
        sl_dataset_destroy(ds);
    }
    sl_lr_free(&lr);
}

static void test_reference_file_rewritten(void)
{
    sl_dataset *ref = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file("tests/data/lr/refined_quadratic.lr.gz", &ref, &err);
    SL_CHECK_MSG(st == SL_OK, "%s", err.message);
    if (st != SL_OK)
        return;
    char path[64];
    snprintf(path, sizeof path, "/tmp/sl_rewrite_%d.lr", (int)getpid());
    sl_dataset *again = write_and_load(ref->lr, path);
    if (again) {
        SL_CHECK(same_model(ref->lr, again->lr));
        SL_CHECK(max_difference(ref->lr, again->lr) == 0.0);
        sl_dataset_destroy(again);
    }
    sl_dataset_destroy(ref);
}

int main(void)
{
    test_refined_roundtrip();
    test_reference_file_rewritten();
    SL_TEST_END();
}
