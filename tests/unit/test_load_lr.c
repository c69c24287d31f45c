/* test_load_lr.c — the LRsplines text loader (renderer/data/load_lr.c) and
 * its dispatch through sl_load_file.
 *
 * Good files: a file written by the format's reference library
 * (tests/data/lr/refined_quadratic.lr.gz, see the README there: locally
 * refined, scaling weights 0.9375, a vector field that is the identity map,
 * checked at random points to 1e-12); a tensor-product file from
 * lr_test_text.h compared against sl_lr_tensor_product on the same knots and
 * coefficients (value and gradient to 1e-12); and a hand-written locally
 * refined file (one element of a 2x2x1 mesh split, coefficients by Boehm's
 * knot insertion) that must equal the unrefined tensor spline (1e-12); and
 * tests/data/lr/two_lines.lr (two partial mesh lines, scaling weights 7/16,
 * made by make_two_lines.py), equal to its tensor spline to 1e-12.
 * Hostile files: lying counts both ways, knots out of order, a basis id out
 * of range or listed twice, a mesh rectangle outside the domain or a point
 * (a segment loads: test_load_lr_degenerate.c has the reference's), an element no listed basis covers, wrong ids,
 * truncation (every prefix of a small file), a truncated gzip, rat = 1,
 * order 5, surfaces, a second patch, garbage, huge counts in a tiny file.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "data/sl_load.h"
#include "lr_test_text.h"
#include "lrspline/sl_lr.h"
#include "sl_test.h"

static char tmpdir[256];

static const char *write_tmp(const char *name, const void *data, size_t n)
{
    static char path[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(path[k], sizeof path[k], "%s/%s", tmpdir, name);
    FILE *f = fopen(path[k], "wb");
    if (!f || fwrite(data, 1, n, f) != n) {
        perror(path[k]);
        exit(2);
    }
    fclose(f);
    return path[k];
}

static sl_dataset *load_text(const char *text, sl_status *st, sl_err *err)
{
    sl_dataset *ds = NULL;
    *st = sl_load_lr((const uint8_t *)text, strlen(text), "t.lr", &ds, err);
    SL_CHECK_MSG((*st == SL_OK) == (ds != NULL), "status %d and dataset %p disagree", (int)*st, (void *)ds);
    return ds;
}

/* The text must be refused with status `want` and a message containing `needle`. */
static void expect_refused(const char *label, const char *text, sl_status want, const char *needle)
{
    sl_err err = {0};
    sl_status st;
    sl_dataset *ds = load_text(text, &st, &err);
    SL_CHECK_MSG(st == want && ds == NULL, "%s: status %d (want %d): %s", label, (int)st, (int)want, err.message);
    SL_CHECK_MSG(strstr(err.message, needle) != NULL, "%s: message lacks \"%s\": %s", label, needle, err.message);
    sl_dataset_destroy(ds);
}

static char *replace(const char *s, const char *from, const char *to)
{
    const char *at = strstr(s, from);
    if (!at) {
        fprintf(stderr, "test: \"%s\" not in the text\n", from);
        exit(2);
    }
    size_t a = (size_t)(at - s), fl = strlen(from), tl = strlen(to), n = strlen(s);
    char *r = malloc(n - fl + tl + 1);
    memcpy(r, s, a);
    memcpy(r + a, to, tl);
    memcpy(r + a + tl, at + fl, n - a - fl + 1);
    return r;
}

static double frand(void) { return rand() / (double)RAND_MAX; }

/* ---- the hand-written locally refined file ----
 * Tensor spline: u order 3 on {0,0,0,1,2,2,2} (A B C D), v order 2 on
 * {0,0,1,2,2} (P Q R), w order 1 on {0,1}; coefficient c(i,j) below. The
 * mesh rectangle u = 0.5 over v in [0,1] splits the element [0,1]x[0,1] and
 * the functions of row P whose u-support it crosses (A, B, C): A = A1 +
 * A2/2, B = B2'/2 + B3*3/4, C = C3/4 + C4 (Boehm), merged: A1 [0 0 0 .5],
 * A2 [0 0 .5 1] (gamma 1, coefficient (cA + cB)/2), B3 [0 .5 1 2] (gamma 1,
 * (3cB + cC)/4), C4 [.5 1 2 2] (cC), D unchanged. */
static double refined_c(int i, int j) { return 1.0 + 0.5 * i - 0.75 * j + 0.3 * i * j + (i == 2) * 0.2; }

static char *refined_text(void)
{
    static char buf[8192];
    double cA = refined_c(0, 0), cB = refined_c(1, 0), cC = refined_c(2, 0), cD = refined_c(3, 0);
    int n = snprintf(buf, sizeof buf,
        "# LRSPLINE VOLUME\n#\tp1\tp2\tp3\tNbasis\tNline\tNel\tdim\trat\n\t3\t2\t1\t13\t9\t5\t1\t0\n"
        "# Basis functions:\n"
        "0: [0 0 0 0.5 ] x [0 0 1 ] x [0 1 ] %.17g (1)\n"
        "1: [0 0 0.5 1 ] x [0 0 1 ] x [0 1 ] %.17g (1)\n"
        "2: [0 0.5 1 2 ] x [0 0 1 ] x [0 1 ] %.17g (1)\n"
        "3: [0.5 1 2 2 ] x [0 0 1 ] x [0 1 ] %.17g (1)\n"
        "4: [1 2 2 2 ] x [0 0 1 ] x [0 1 ] %.17g (1)\n",
        cA, 0.5 * (cA + cB), 0.75 * cB + 0.25 * cC, cC, cD);
    static const char *const u[4] = {"[0 0 0 1 ]", "[0 0 1 2 ]", "[0 1 2 2 ]", "[1 2 2 2 ]"};
    static const char *const v[3] = {"", "[0 1 2 ]", "[1 2 2 ]"};
    int id = 5;
    for (int j = 1; j < 3; j++)
        for (int i = 0; i < 4; i++)
            n += snprintf(buf + n, sizeof buf - (size_t)n, "%d: %s x %s x [0 1 ] %.17g (1)\n", id++, u[i], v[j],
                          refined_c(i, j));
    /* Ids: row Q = 5 + i, row R = 9 + i. */
    snprintf(buf + n, sizeof buf - (size_t)n,
             "# Mesh rectangles:\n"
             "[0, 0] x [0, 2] x [0, 1] (3)\n[0.5, 0.5] x [0, 1] x [0, 1] (1)\n[1, 1] x [0, 2] x [0, 1] (1)\n"
             "[2, 2] x [0, 2] x [0, 1] (3)\n[0, 2] x [0, 0] x [0, 1] (2)\n[0, 2] x [1, 1] x [0, 1] (1)\n"
             "[0, 2] x [2, 2] x [0, 1] (2)\n[0, 2] x [0, 2] x [0, 0] (1)\n[0, 2] x [0, 2] x [1, 1] (1)\n"
             "# Elements:\n"
             "0 [3] : (0, 0, 0) x (0.5, 1, 1)    {0, 1, 2, 5, 6, 7}\n"
             "1 [3] : (0.5, 0, 0) x (1, 1, 1)    {1, 2, 3, 5, 6, 7}\n"
             "2 [3] : (1, 0, 0) x (2, 1, 1)    {2, 3, 4, 6, 7, 8}\n"
             "3 [3] : (0, 1, 0) x (1, 2, 1)    {5, 6, 7, 9, 10, 11}\n"
             "4 [3] : (1, 1, 0) x (2, 2, 1)    {6, 7, 8, 10, 11, 12}\n");
    return buf;
}

static void refined_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)user;
    (void)g;
    coef[0] = refined_c(ijk[0], ijk[1]);
}

static void test_refined(void)
{
    sl_err err = {0};
    sl_status st;
    sl_dataset *ds = load_text(refined_text(), &st, &err);
    SL_CHECK_MSG(st == SL_OK, "refined: %s", err.message);
    if (!ds)
        return;
    const sl_lr_volume *lr = ds->lr;
    SL_CHECK(ds->kind == SL_DATASET_LR && lr && lr->basis_count == 13 && lr->element_count == 5 &&
             lr->meshrect_count == 9 && lr->dim == 1);
    SL_CHECK(strcmp(ds->name, "t") == 0);
    SL_CHECK(ds->bounds_min.x == 0 && ds->bounds_max.x == 2 && ds->bounds_max.y == 2 && ds->bounds_max.z == 1);
    SL_CHECK(ds->origin.x == 0 && ds->origin.y == 0 && ds->origin.z == 0);
    SL_CHECK_NEAR(sl_lr_level_ratio(lr), 2.0, 0);
    const double ku[] = {0, 0, 0, 1, 2, 2, 2}, kv[] = {0, 0, 1, 2, 2}, kw[] = {0, 1};
    const double *knots[3] = {ku, kv, kw};
    const int order[3] = {3, 2, 1}, count[3] = {7, 5, 2};
    sl_lr_volume ref;
    st = sl_lr_tensor_product(&ref, order, 1, knots, count, refined_coef, NULL, &err);
    SL_CHECK_MSG(st == SL_OK, "tensor: %s", err.message);
    double worst = 0, worst_g = 0;
    for (int s = 0; s < 2000 && st == SL_OK; s++) {
        double p[3] = {2 * frand(), 2 * frand(), frand()};
        if (s < 3) { /* on the new knot plane and the domain's upper corner */
            p[0] = s == 2 ? 2.0 : 0.5;
            p[1] = s == 2 ? 2.0 : 0.25 + 0.5 * s;
        }
        double a, b, ga[3], gb[3];
        sl_status s1 = sl_lr_eval(lr, p, -1, &a, ga, &err), s2 = sl_lr_eval(&ref, p, -1, &b, gb, &err);
        SL_CHECK(s1 == SL_OK && s2 == SL_OK);
        worst = fmax(worst, fabs(a - b));
        for (int j = 0; j < 3; j++)
            worst_g = fmax(worst_g, fabs(ga[j] - gb[j]));
    }
    SL_CHECK_MSG(worst <= 1e-12 && worst_g <= 1e-11, "refined vs tensor: value %.3g, gradient %.3g", worst, worst_g);
    sl_lr_free(&ref);
    sl_dataset_destroy(ds);

    /* Dropping the split leaves element 0 without a full basis: partition of unity fails. */
    char *t = replace(refined_text(), "{0, 1, 2, 5, 6, 7}", "{1, 2, 5, 6, 7}");
    expect_refused("missing basis function", t, SL_ERR_FORMAT, "sum to");
    free(t);
    /* Basis 4 ([1 2 2 2] in u) does not reach element 0. */
    t = replace(refined_text(), "{0, 1, 2, 5, 6, 7}", "{0, 1, 2, 4, 5, 6, 7}");
    expect_refused("element not covered by a listed basis", t, SL_ERR_FORMAT, "does not cover it");
    free(t);
    t = replace(refined_text(), "{0, 1, 2, 5, 6, 7}", "{}");
    expect_refused("element without basis", t, SL_ERR_FORMAT, "basis id is not an integer");
    free(t);
    t = replace(refined_text(), "{0, 1, 2, 5, 6, 7}", "{0, 1, 2, 5, 6, 13}");
    expect_refused("basis id out of range", t, SL_ERR_FORMAT, "basis id 13 out of range");
    free(t);
    t = replace(refined_text(), "{0, 1, 2, 5, 6, 7}", "{0, 1, 2, 5, 6, 6}");
    expect_refused("basis id twice", t, SL_ERR_FORMAT, "lists basis function 6 twice");
    free(t);
    t = replace(refined_text(), "[0 0 0.5 1 ]", "[0 0.5 0 1 ]");
    expect_refused("knots out of order", t, SL_ERR_FORMAT, "u knots out of order");
    free(t);
    t = replace(refined_text(), "1: [0 0 0.5", "7: [0 0 0.5");
    expect_refused("basis id not its position", t, SL_ERR_FORMAT, "is numbered 7");
    free(t);
    t = replace(refined_text(), "2 [3] : (1, 0, 0)", "3 [3] : (1, 0, 0)");
    expect_refused("element id not its position", t, SL_ERR_FORMAT, "is numbered 3");
    free(t);
    t = replace(refined_text(), "(0.5, 0, 0) x (1, 1, 1)", "(0.5, 0, 0) x (0.5, 1, 1)");
    expect_refused("empty element", t, SL_ERR_FORMAT, "empty box");
    free(t);
    t = replace(refined_text(), "(0.5, 0, 0) x (1, 1, 1)", "(0.5, 0, 0) x (1.5, 1, 1)");
    expect_refused("overlapping elements", t, SL_ERR_FORMAT, "");
    free(t);
    t = replace(refined_text(), "[0.5, 0.5] x [0, 1]", "[0.5, 0.6] x [0, 1]");
    expect_refused("mesh rectangle with no constant direction", t, SL_ERR_FORMAT, "0 constant directions");
    free(t);
    t = replace(refined_text(), "[0.5, 0.5] x [0, 1] x [0, 1] (1)", "[0.5, 0.5] x [0, 3] x [0, 1] (1)");
    expect_refused("mesh rectangle outside the domain", t, SL_ERR_FORMAT, "line 20: mesh rectangle 1: v extent"
                   " [0, 3] is outside the domain [0, 2]");
    free(t);
    t = replace(refined_text(), "[0.5, 0.5] x [0, 1] x [0, 1] (1)", "[0.5, 0.5] x [1, 1] x [0, 1] (1)");
    {
        sl_err e = {0};
        sl_status s = SL_OK;
        sl_dataset *seg = load_text(t, &s, &e);
        SL_CHECK_MSG(s == SL_OK && seg && seg->lr->meshrects[1].lo[1] == 1 && seg->lr->meshrects[1].hi[1] == 1,
                     "a segment (two constant directions) refused: %s", e.message);
        sl_dataset_destroy(seg);
    }
    free(t);
    t = replace(refined_text(), "[0.5, 0.5] x [0, 1] x [0, 1] (1)", "[0.5, 0.5] x [1, 1] x [1, 1] (1)");
    expect_refused("a point", t, SL_ERR_FORMAT, "line 20: mesh rectangle 1 has 3 constant directions");
    free(t);
    t = replace(refined_text(), "[0.5, 0.5] x [0, 1] x [0, 1] (1)", "[0.5, 0.5] x [0, 1] x [0, 1] (4)");
    expect_refused("multiplicity above the order", t, SL_ERR_FORMAT, "multiplicity 4 exceeds the order 3");
    free(t);
    t = replace(refined_text(), "(1)\n1:", "(-0.5)\n1:");
    expect_refused("negative scaling weight", t, SL_ERR_FORMAT, "not positive");
    free(t);
    t = replace(refined_text(), "[0 0 0 0.5 ]", "[0 0 0 nan ]");
    expect_refused("nan knot", t, SL_ERR_FORMAT, "not a number");
    free(t);
    t = replace(refined_text(), "[0 0 0 0.5 ]", "[0 0 0 1e999 ]");
    expect_refused("infinite knot", t, SL_ERR_FORMAT, "not a finite double");
    free(t);
    t = replace(refined_text(), "0: [0 0 0 0.5 ] x", "0: [0 0 0 0.5 ] y");
    expect_refused("garbage separator", t, SL_ERR_FORMAT, "expected 'x', found 'y'");
    free(t);
}

/* ---- lying counts, header refusals, truncation, garbage ---- */

static void test_counts_and_header(void)
{
    const char *good = refined_text();
    char *t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t14\t9\t5\t1\t0");
    expect_refused("one basis function more announced", t, SL_ERR_FORMAT,
                   "a mesh rectangle where basis function 14 of 14 was expected");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t12\t9\t5\t1\t0");
    expect_refused("one basis function fewer announced", t, SL_ERR_FORMAT,
                   "a basis function where mesh rectangle 1 of 9 was expected");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t13\t10\t5\t1\t0");
    expect_refused("one mesh rectangle more announced", t, SL_ERR_FORMAT,
                   "an element where mesh rectangle 10 of 10 was expected");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t13\t9\t6\t1\t0");
    expect_refused("one element more announced", t, SL_ERR_FORMAT, "ends after 5 of the 6 elements");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t13\t9\t4\t1\t0");
    expect_refused("one element fewer announced", t, SL_ERR_FORMAT, "an element after the 4 elements");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t13\t9\t5\t1\t1");
    expect_refused("rational", t, SL_ERR_UNSUPPORTED, "rat = 1");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t5\t2\t1\t13\t9\t5\t1\t0");
    expect_refused("order 5", t, SL_ERR_UNSUPPORTED, "degree 4");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t13\t9\t5\t2\t0");
    expect_refused("dim 2", t, SL_ERR_UNSUPPORTED, "dim = 2");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t8388608\t9\t5\t1\t0");
    expect_refused("huge count in a tiny file", t, SL_ERR_FORMAT, "need at least");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t8388609\t9\t5\t1\t0");
    expect_refused("count above the limit", t, SL_ERR_LIMIT, "exceed the limit");
    free(t);
    t = replace(good, "\t3\t2\t1\t13\t9\t5\t1\t0", "\t3\t2\t1\t99999999999999999999\t9\t5\t1\t0");
    expect_refused("count beyond long long", t, SL_ERR_FORMAT, "not an integer");
    free(t);
    t = replace(good, "# LRSPLINE VOLUME", "# LRSPLINE SURFACE");
    expect_refused("surface", t, SL_ERR_UNSUPPORTED, "only LR-spline volumes");
    free(t);
    expect_refused("empty", "", SL_ERR_FORMAT, "not an LR-spline file");
    expect_refused("garbage", "\x7f" "ELF\x01\x02", SL_ERR_FORMAT, "not an LR-spline file");
    expect_refused("header only", "# LRSPLINE VOLUME\n", SL_ERR_FORMAT, "ends inside the header line");
    expect_refused("text header", "# LRSPLINE VOLUME\n3 3 3 a b c\n", SL_ERR_FORMAT, "Nbasis is not an integer");
    /* A second patch, as multi-patch files carry them. */
    size_t n = strlen(good);
    char *two = malloc(2 * n + 1);
    memcpy(two, good, n);
    memcpy(two + n, good, n + 1);
    expect_refused("second patch", two, SL_ERR_UNSUPPORTED, "second LR-spline patch");
    free(two);
    t = malloc(n + 16);
    memcpy(t, good, n);
    memcpy(t + n, "  # trailing\n\n", 15);
    sl_err err = {0};
    sl_status st;
    sl_dataset *ds = load_text(t, &st, &err);
    SL_CHECK_MSG(st == SL_OK, "trailing comment: %s", err.message);
    sl_dataset_destroy(ds);
    memcpy(t + n, "junk\n", 6);
    expect_refused("trailing junk", t, SL_ERR_FORMAT, "unexpected 'j' after the last element");
    free(t);

    /* Every proper prefix is refused (cut inside a record or between records). */
    int refused = 0, total = 0;
    for (size_t len = 0; len < n; len++) {
        sl_dataset *p = NULL;
        sl_err e = {0};
        sl_status s = sl_load_lr((const uint8_t *)good, len, NULL, &p, &e);
        /* A cut in the last element's closing "}\n" keeps ... nothing: '}' is required. */
        int trailing_ws = len >= n - 1; /* only the final newline missing */
        total++;
        if (trailing_ws) {
            SL_CHECK_MSG(s == SL_OK, "prefix %zu (only the final newline cut): %s", len, e.message);
        } else if (s != SL_OK && p == NULL && e.message[0]) {
            refused++;
        } else {
            SL_CHECK_MSG(0, "prefix of %zu/%zu bytes loaded (status %d)", len, n, (int)s);
        }
        sl_dataset_destroy(p);
    }
    SL_CHECK_MSG(refused == total - 1, "%d of %d prefixes refused", refused, total);
}

/* ---- tensor product file against sl_lr_tensor_product ---- */

static void tensor_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)g;
    int dim = *(const int *)user;
    for (int c = 0; c < dim; c++)
        coef[c] = sin(1.0 + ijk[0] + 2.1 * ijk[1] - 0.7 * ijk[2] + c) + 0.1 * c;
}

static void test_tensor(int dim)
{
    const double ku[] = {-1, -1, -1, -1, -0.2, 0.5, 2, 2, 2, 2}; /* cubic */
    const double kv[] = {0, 0, 0, 0.25, 0.25, 1, 1, 1};          /* quadratic, a double knot */
    const double kw[] = {3, 3, 3.5, 4, 4};                      /* linear */
    const double *knots[3] = {ku, kv, kw};
    const int order[3] = {4, 3, 2}, count[3] = {10, 8, 5};
    char *text = lr_text_tensor(order, dim, knots, count, tensor_coef, &dim);
    SL_CHECK(text != NULL);
    if (!text)
        return;
    sl_err err = {0};
    sl_status st;
    sl_dataset *ds = load_text(text, &st, &err);
    SL_CHECK_MSG(st == SL_OK, "tensor dim %d: %s", dim, err.message);
    sl_lr_volume ref;
    sl_status st2 = sl_lr_tensor_product(&ref, order, dim, knots, count, tensor_coef, &dim, &err);
    SL_CHECK_MSG(st2 == SL_OK, "sl_lr_tensor_product: %s", err.message);
    if (ds && st2 == SL_OK) {
        const sl_lr_volume *lr = ds->lr;
        SL_CHECK(lr->basis_count == ref.basis_count && lr->element_count == ref.element_count &&
                 lr->meshrect_count == ref.meshrect_count && lr->dim == dim);
        SL_CHECK(ds->bounds_min.x == -1 && ds->bounds_max.x == 2 && ds->bounds_min.z == 3 && ds->bounds_max.z == 4);
        SL_CHECK_NEAR(lr->value_min, ref.value_min, 1e-12);
        SL_CHECK_NEAR(lr->value_max, ref.value_max, 1e-12);
        double worst = 0;
        for (int s = 0; s < 3000; s++) {
            double p[3] = {-1 + 3 * frand(), frand(), 3 + frand()};
            if (s % 100 == 0)
                p[1] = 0.25; /* the double knot plane */
            double a[3], b[3], ga[9], gb[9];
            SL_CHECK(sl_lr_eval(lr, p, -1, a, ga, &err) == SL_OK && sl_lr_eval(&ref, p, -1, b, gb, &err) == SL_OK);
            for (int c = 0; c < dim; c++) {
                worst = fmax(worst, fabs(a[c] - b[c]));
                for (int j = 0; j < 3; j++)
                    worst = fmax(worst, fabs(ga[c * 3 + j] - gb[c * 3 + j]) / 10);
            }
        }
        SL_CHECK_MSG(worst <= 1e-12, "tensor dim %d: file vs in-memory differ by %.3g", dim, worst);
    }
    if (st2 == SL_OK)
        sl_lr_free(&ref);
    sl_dataset_destroy(ds);

    /* The same text through sl_load_file: .lr, .lr.gz, and an unknown extension by its header. */
    if (dim == 1) {
        size_t n = strlen(text);
        const char *plain = write_tmp("tensor.lr", text, n);
        sl_dataset *f = NULL;
        SL_CHECK_MSG(sl_load_file(plain, &f, &err) == SL_OK && f && f->kind == SL_DATASET_LR, "%s", err.message);
        SL_CHECK(f && strcmp(f->name, "tensor") == 0);
        sl_dataset_destroy(f);
        const char *odd = write_tmp("tensor.spline", text, n);
        f = NULL;
        SL_CHECK_MSG(sl_load_file(odd, &f, &err) == SL_OK && f && f->kind == SL_DATASET_LR, "by header: %s",
                     err.message);
        sl_dataset_destroy(f);
        uLongf zn = compressBound((uLong)n) + 32;
        uint8_t *z = malloc(zn + 32);
        /* gzip framing around raw deflate via deflateInit2 with the gzip wrapper. */
        z_stream zs;
        memset(&zs, 0, sizeof zs);
        SL_CHECK(deflateInit2(&zs, 9, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) == Z_OK);
        zs.next_in = (Bytef *)text;
        zs.avail_in = (uInt)n;
        zs.next_out = z;
        zs.avail_out = (uInt)(zn + 32);
        SL_CHECK(deflate(&zs, Z_FINISH) == Z_STREAM_END);
        size_t gz = zs.total_out;
        deflateEnd(&zs);
        const char *gzp = write_tmp("tensor.lr.gz", z, gz);
        f = NULL;
        SL_CHECK_MSG(sl_load_file(gzp, &f, &err) == SL_OK && f && f->lr && f->lr->element_count == 12,
                     ".lr.gz: %s", err.message);
        SL_CHECK(f && strcmp(f->name, "tensor") == 0);
        sl_dataset_destroy(f);
        const char *cut = write_tmp("cut.lr.gz", z, gz / 2);
        f = NULL;
        sl_status cs = sl_load_file(cut, &f, &err);
        SL_CHECK_MSG(cs == SL_ERR_FORMAT && f == NULL, "truncated gzip: status %d: %s", (int)cs, err.message);
        free(z);
    }
    free(text);
}

/* ---- two partial mesh lines: scaling weights 7/16 (tests/data/lr/make_two_lines.py) ---- */

static void two_lines_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)user;
    (void)g;
    int i = ijk[0], j = ijk[1];
    coef[0] = 1.0 + 0.5 * i - 0.25 * j + 0.125 * i * j + (i == 2 && j == 1 ? 0.3 : 0.0);
}

static void test_two_lines(void)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file("tests/data/lr/two_lines.lr", &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "two_lines.lr: %s", err.message);
    if (!ds)
        return;
    const sl_lr_volume *lr = ds->lr;
    SL_CHECK(lr->basis_count == 30 && lr->element_count == 14);
    int weighted = 0;
    for (size_t i = 0; i < lr->basis_count; i++)
        weighted += lr->basis[i].gamma == 0.4375;
    SL_CHECK_MSG(weighted > 0, "no scaling weight 7/16");
    const double k[] = {0, 0, 0, 1, 2, 3, 3, 3}, kw[] = {0, 1};
    const double *knots[3] = {k, k, kw};
    const int order[3] = {3, 3, 1}, count[3] = {8, 8, 2};
    sl_lr_volume ref;
    st = sl_lr_tensor_product(&ref, order, 1, knots, count, two_lines_coef, NULL, &err);
    SL_CHECK_MSG(st == SL_OK, "tensor: %s", err.message);
    double worst = 0;
    for (int s = 0; s < 4000 && st == SL_OK; s++) {
        double p[3] = {3 * frand(), 3 * frand(), frand()}, a = 0, b = 0, ga[3] = {0}, gb[3] = {0};
        if (s % 50 == 0)
            p[s % 100 ? 0 : 1] = 1.5; /* on a new mesh line */
        SL_CHECK(sl_lr_eval(lr, p, -1, &a, ga, &err) == SL_OK && sl_lr_eval(&ref, p, -1, &b, gb, &err) == SL_OK);
        worst = fmax(worst, fabs(a - b));
        for (int j = 0; j < 3; j++)
            worst = fmax(worst, fabs(ga[j] - gb[j]));
    }
    SL_CHECK_MSG(worst <= 1e-12, "two_lines vs its tensor spline: %.3g", worst);
    if (st == SL_OK)
        sl_lr_free(&ref);
    sl_dataset_destroy(ds);
}

/* ---- the reference library's file ---- */

static void test_reference_fixture(void)
{
    const char *path = "tests/data/lr/refined_quadratic.lr.gz";
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file(path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", path, err.message);
    if (!ds)
        return;
    const sl_lr_volume *lr = ds->lr;
    SL_CHECK(strcmp(ds->name, "refined_quadratic") == 0);
    SL_CHECK(lr->order[0] == 3 && lr->order[1] == 3 && lr->order[2] == 3 && lr->dim == 3);
    SL_CHECK(lr->basis_count == 1176 && lr->meshrect_count == 189 && lr->element_count == 1240);
    SL_CHECK(ds->bounds_min.x == 0 && ds->bounds_max.x == 1 && ds->bounds_max.z == 1);
    int weighted = 0;
    for (size_t i = 0; i < lr->basis_count; i++)
        weighted += lr->basis[i].gamma != 1.0;
    SL_CHECK_MSG(weighted > 0, "no scaling weight other than 1 in the fixture");
    SL_CHECK_NEAR(sl_lr_level_ratio(lr), 4.0, 0); /* element sides 1/16 .. 1/4 (read off the file with awk) */
    /* Refined from the identity map: f(p) = p, Jacobian = I. */
    double worst = 0;
    for (int s = 0; s < 4000; s++) {
        double p[3] = {frand(), frand(), frand()}, v[3], g[9];
        SL_CHECK(sl_lr_eval(lr, p, -1, v, g, &err) == SL_OK);
        for (int c = 0; c < 3; c++) {
            worst = fmax(worst, fabs(v[c] - p[c]));
            for (int j = 0; j < 3; j++)
                worst = fmax(worst, fabs(g[c * 3 + j] - (c == j)));
        }
    }
    SL_CHECK_MSG(worst <= 1e-12, "fixture is not the identity: %.3g", worst);
    sl_dataset_destroy(ds);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/sl_test_lr_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    srand(15);
    test_refined();
    test_counts_and_header();
    test_tensor(1);
    test_tensor(3);
    test_two_lines();
    test_reference_fixture();
    const char *names[] = {"tensor.lr", "tensor.spline", "tensor.lr.gz", "cut.lr.gz"};
    for (int i = 0; i < 4; i++) {
        char p[600];
        snprintf(p, sizeof p, "%s/%s", tmpdir, names[i]);
        unlink(p);
    }
    rmdir(tmpdir);
    SL_TEST_END();
}
