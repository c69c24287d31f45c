/* test_load_lr_degenerate.c — files written by the LRsplines reference
 * library itself, with the degenerate mesh rectangles it keeps (issue 31,
 * part 1): entries flat in two directions, segments such as
 * "[0.3125, 0.3125] x [0.125, 0.125] x [0, 0.5] (1)", which its merging of
 * overlapping rectangles leaves behind (tests/data/lr/README.md).
 *
 * Fixtures (generated with the library, make_lrsplines_fixtures.cpp): a
 * scalar volume refined three times by minimal-span splits (8 segments) and a
 * vector volume refined twice (3 segments), both from blossoms of known
 * polynomials of degree <= 2 per direction, so the spline is the polynomial.
 * Checked: they load, the segments are kept as read, values and gradients
 * equal the polynomials to 1e-12 / 1e-11 (random points, element corners,
 * points on the segments), our writer gives back the mesh-rectangle lines
 * byte for byte, a further refinement (of the scalar one) stays exact; and what is truly broken
 * is still refused with the reason and the line (a point, a rectangle
 * outside the domain, a multiplicity above the order), by the loader and by
 * sl_lr_finish. Runs from the source root.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "data/sl_load.h"
#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_refine.h"
#include "lrspline/sl_lr_write.h"
#include "sl_test.h"

#define SCALAR_PATH "tests/data/lr/lrsplines_minspan3_scalar.lr.gz"
#define VECTOR_PATH "tests/data/lr/lrsplines_minspan2_vector.lr.gz"

static double frand(void) { return rand() / (double)RAND_MAX; }

/* The fields the generator blossomed (make_lrsplines_fixtures.cpp). */
static void field(int dim, const double p[3], double *v, double *g)
{
    double u = p[0], s = p[1], w = p[2];
    if (dim == 1) {
        v[0] = 0.5 + u * u - 2 * u * s * w + 3 * s * s * w + 0.25 * w;
        g[0] = 2 * u - 2 * s * w;
        g[1] = -2 * u * w + 6 * s * w;
        g[2] = -2 * u * s + 3 * s * s + 0.25;
        return;
    }
    v[0] = u * s - 0.5 * w * w + 0.2;
    v[1] = s * s - w + 0.75 * u * u * s * w * w;
    v[2] = u + 1.5 * u * s * w - 0.3 * s;
    const double j[9] = {s, u, -w,
                         1.5 * u * s * w * w, 2 * s + 0.75 * u * u * w * w, -1 + 1.5 * u * u * s * w,
                         1 + 1.5 * s * w, 1.5 * u * w - 0.3, 1.5 * u * s};
    memcpy(g, j, sizeof j);
}

static char *read_gz(const char *path, size_t *len)
{
    gzFile f = gzopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 1 << 20, n = 0;
    char *buf = malloc(cap + 1);
    int got;
    while (buf && (got = gzread(f, buf + n, (unsigned)(cap - n))) > 0) {
        n += (size_t)got;
        if (n == cap) {
            char *more = realloc(buf, 2 * cap + 1);
            if (!more) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = more;
            cap *= 2;
        }
    }
    gzclose(f);
    if (buf)
        buf[n] = '\0';
    *len = n;
    return buf;
}

static int flats(const sl_lr_meshrect *m)
{
    return (m->lo[0] == m->hi[0]) + (m->lo[1] == m->hi[1]) + (m->lo[2] == m->hi[2]);
}

/* The "# Mesh rectangles:" section of a file's text, up to "# Elements:". */
static char *rect_section(const char *text)
{
    const char *a = strstr(text, "# Mesh rectangles:\n"), *b = a ? strstr(a, "# Elements:") : NULL;
    if (!b)
        return NULL;
    size_t n = (size_t)(b - a);
    char *s = malloc(n + 1);
    memcpy(s, a, n);
    s[n] = '\0';
    return s;
}

/* Max deviation from the field: value, and gradient (relative to 1). */
static void deviation(const sl_lr_volume *lr, const double p[3], double *worst_v, double *worst_g)
{
    double v[3], g[9], fv[3], fg[9];
    sl_err err = {0};
    if (sl_lr_eval(lr, p, -1, v, g, &err) != SL_OK) {
        *worst_v = INFINITY;
        return;
    }
    field(lr->dim, p, fv, fg);
    for (int c = 0; c < lr->dim; c++) {
        *worst_v = fmax(*worst_v, fabs(v[c] - fv[c]));
        for (int k = 0; k < 3; k++)
            *worst_g = fmax(*worst_g, fabs(g[c * 3 + k] - fg[c * 3 + k]));
    }
}

static void check_exact(const sl_lr_volume *lr, const char *label)
{
    double wv = 0, wg = 0;
    for (int s = 0; s < 1500; s++) {
        double p[3] = {frand(), frand(), frand()};
        deviation(lr, p, &wv, &wg);
    }
    for (int s = 0; s < 500; s++) { /* element corners: on knot planes and lines */
        const sl_lr_element *e = &lr->elements[(size_t)rand() % lr->element_count];
        double p[3];
        for (int d = 0; d < 3; d++)
            p[d] = (rand() & 1) ? e->hi[d] : e->lo[d];
        deviation(lr, p, &wv, &wg);
    }
    for (size_t i = 0; i < lr->meshrect_count; i++) { /* along the segments */
        const sl_lr_meshrect *m = &lr->meshrects[i];
        if (flats(m) != 2)
            continue;
        for (int k = 0; k <= 8; k++) {
            double p[3];
            for (int d = 0; d < 3; d++)
                p[d] = m->lo[d] + k / 8.0 * (m->hi[d] - m->lo[d]);
            deviation(lr, p, &wv, &wg);
        }
    }
    SL_CHECK_MSG(wv <= 1e-12 && wg <= 1e-11, "%s: value off the field by %.3g, gradient by %.3g", label, wv, wg);
}

typedef struct fixture {
    const char *path, *name;
    int dim;
    size_t basis, rects, elements, segments;
    double level_ratio;
    sl_lr_meshrect segment; /* one of them, as the file has it */
    int refine;             /* refine it further (one fixture is enough: the cost is ASan's) */
} fixture;

/* Field by field: the struct has padding after multiplicity, which memcmp would compare too. */
static int same_meshrect(const sl_lr_meshrect *a, const sl_lr_meshrect *b)
{
    for (int d = 0; d < 3; d++)
        if (a->lo[d] != b->lo[d] || a->hi[d] != b->hi[d])
            return 0;
    return a->multiplicity == b->multiplicity;
}

static void test_fixture(const fixture *fx)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_file(fx->path, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", fx->path, err.message);
    if (!ds)
        return;
    sl_lr_volume *lr = ds->lr;
    SL_CHECK(strcmp(ds->name, fx->name) == 0);
    SL_CHECK(lr->order[0] == 3 && lr->order[1] == 3 && lr->order[2] == 3 && lr->dim == fx->dim);
    SL_CHECK_MSG(lr->basis_count == fx->basis && lr->meshrect_count == fx->rects && lr->element_count == fx->elements,
                 "%s: %zu basis, %zu rectangles, %zu elements", fx->path, lr->basis_count, lr->meshrect_count,
                 lr->element_count);
    SL_CHECK_NEAR(sl_lr_level_ratio(lr), fx->level_ratio, 0);
    size_t segments = 0, found = 0;
    for (size_t i = 0; i < lr->meshrect_count; i++) {
        segments += flats(&lr->meshrects[i]) == 2;
        found += same_meshrect(&lr->meshrects[i], &fx->segment);
    }
    SL_CHECK_MSG(segments == fx->segments, "%s: %zu segments kept, the file has %zu", fx->path, segments,
                 fx->segments);
    SL_CHECK_MSG(found == 1, "%s: the segment [%g, %g] x [%g, %g] x [%g, %g] (%d) kept %zu times", fx->path,
                 fx->segment.lo[0], fx->segment.hi[0], fx->segment.lo[1], fx->segment.hi[1], fx->segment.lo[2],
                 fx->segment.hi[2], fx->segment.multiplicity, found);
    check_exact(lr, fx->path);

    /* Written back: the mesh-rectangle lines are the reference's, byte for byte. */
    size_t len = 0;
    char *orig = read_gz(fx->path, &len);
    char tmp[] = "/tmp/sl_test_lrdeg_XXXXXX";
    int fd = mkstemp(tmp);
    FILE *f = fd >= 0 ? fdopen(fd, "w+b") : NULL;
    SL_CHECK(orig != NULL && f != NULL);
    if (orig && f) {
        SL_CHECK_MSG(sl_lr_write(lr, f, &err) == SL_OK, "write: %s", err.message);
        fflush(f);
        fseek(f, 0, SEEK_END);
        long n = ftell(f);
        rewind(f);
        char *ours = malloc((size_t)n + 1);
        ours[fread(ours, 1, (size_t)n, f)] = '\0';
        char *a = rect_section(orig), *b = rect_section(ours);
        SL_CHECK_MSG(a && b && strcmp(a, b) == 0, "%s: the mesh rectangles written back differ", fx->path);
        free(a);
        free(b);
        sl_dataset *back = NULL;
        st = sl_load_lr((const uint8_t *)ours, (size_t)n, NULL, &back, &err);
        SL_CHECK_MSG(st == SL_OK, "%s written back: %s", fx->path, err.message);
        if (back) {
            size_t same = 0;
            SL_CHECK(back->lr->meshrect_count == lr->meshrect_count);
            for (size_t i = 0; i < lr->meshrect_count && i < back->lr->meshrect_count; i++)
                same += same_meshrect(&back->lr->meshrects[i], &lr->meshrects[i]);
            SL_CHECK_MSG(same == lr->meshrect_count, "%s written back: %zu of %zu mesh rectangles as read", fx->path,
                         same, lr->meshrect_count);
        }
        sl_dataset_destroy(back);
        free(ours);
    }
    if (f)
        fclose(f);
    if (fd >= 0)
        unlink(tmp);
    free(orig);

    /* A further refinement across the segments stays exact. */
    if (!fx->refine) {
        sl_dataset_destroy(ds);
        return;
    }
    const sl_lr_meshrect cut = {{0.40625, 0, 0}, {0.40625, 1, 0.5}, 1};
    size_t before = lr->basis_count;
    st = sl_lr_refine(lr, &cut, 1, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: refine: %s", fx->path, err.message);
    SL_CHECK_MSG(lr->basis_count > before, "%s: the refinement added nothing", fx->path);
    if (st == SL_OK)
        check_exact(lr, "refined further");
    sl_dataset_destroy(ds);
}

/* ---- what stays refused ---- */

static size_t line_of(const char *text, const char *at)
{
    size_t line = 1;
    for (const char *p = text; p < at; p++)
        line += *p == '\n';
    return line;
}

/* Replaces the first occurrence of `from` (a whole mesh-rectangle line) and
 * expects a refusal naming `needle` and that line. */
static void expect_refused(const char *text, const char *from, const char *to, const char *needle)
{
    const char *at = strstr(text, from);
    SL_CHECK_MSG(at != NULL, "\"%s\" not in the fixture", from);
    if (!at)
        return;
    size_t a = (size_t)(at - text), fl = strlen(from), tl = strlen(to), n = strlen(text);
    char *t = malloc(n - fl + tl + 1);
    memcpy(t, text, a);
    memcpy(t + a, to, tl);
    memcpy(t + a + tl, at + fl, n - a - fl + 1);
    char want[64];
    snprintf(want, sizeof want, "line %zu: mesh rectangle", line_of(text, at));
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_lr((const uint8_t *)t, strlen(t), "t.lr", &ds, &err);
    SL_CHECK_MSG(st == SL_ERR_FORMAT && !ds && strstr(err.message, needle) && strstr(err.message, want),
                 "%s: status %d, message \"%s\" (want \"%s\" and \"%s\")", to, (int)st, err.message, want, needle);
    sl_dataset_destroy(ds);
    free(t);
}

static void test_refusals(void)
{
    size_t len = 0;
    char *text = read_gz(SCALAR_PATH, &len);
    SL_CHECK(text != NULL);
    if (!text)
        return;
    const char *seg = "[0, 1] x [0.5, 0.5] x [0.125, 0.125] (1)";
    expect_refused(text, seg, "[0.5, 0.5] x [0.5, 0.5] x [0.125, 0.125] (1)", "3 constant directions");
    expect_refused(text, seg, "[0, 1] x [0.5, 0.5] x [1.125, 1.125] (1)", "outside the domain");
    expect_refused(text, seg, "[0, 1.5] x [0.5, 0.5] x [0.125, 0.125] (1)", "outside the domain");
    expect_refused(text, seg, "[-0.25, 1] x [0.5, 0.5] x [0.125, 0.125] (1)", "outside the domain");
    expect_refused(text, seg, "[0, 1] x [0.5, 0.5] x [0.125, 0.125] (4)", "multiplicity 4 exceeds the order 3");
    expect_refused(text, "[0.25, 0.25] x [0, 1] x [0, 1] (1)", "[0.25, 0.25] x [0, 1] x [0, 2] (1)",
                   "outside the domain");
    expect_refused(text, seg, "[0, 1] x [0.5, 0.75] x [0.125, 0.25] (1)", "0 constant directions");

    /* The model's own check, for models built in memory. */
    sl_dataset *ds = NULL;
    sl_err err = {0};
    sl_status st = sl_load_lr((const uint8_t *)text, len, NULL, &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", SCALAR_PATH, err.message);
    if (ds) {
        sl_lr_volume *lr = ds->lr;
        size_t k = 0;
        while (k < lr->meshrect_count && flats(&lr->meshrects[k]) != 2)
            k++;
        SL_CHECK(k < lr->meshrect_count);
        sl_lr_meshrect keep = lr->meshrects[k];
        static const struct {
            double lo[3], hi[3];
            int mult;
            const char *needle;
        } bad[] = {
            {{0.5, 0.5, 0.125}, {0.5, 0.5, 0.125}, 1, "a point"},
            {{0, 0.5, 1.125}, {1, 0.5, 1.125}, 1, "outside the domain"},
            {{0, 0.5, 0.125}, {1, 0.5, 0.125}, 4, "multiplicity 4"},
            {{0, 0.5, 0.125}, {1, 0.5, 0.125}, 0, "multiplicity 0"},
        };
        for (size_t b = 0; b < sizeof bad / sizeof bad[0] && k < lr->meshrect_count; b++) {
            sl_lr_meshrect *m = &lr->meshrects[k];
            memcpy(m->lo, bad[b].lo, sizeof m->lo);
            memcpy(m->hi, bad[b].hi, sizeof m->hi);
            m->multiplicity = bad[b].mult;
            char want[48];
            snprintf(want, sizeof want, "mesh rectangle %zu", k);
            err.message[0] = '\0';
            st = sl_lr_finish(lr, &err);
            SL_CHECK_MSG(st == SL_ERR_FORMAT && strstr(err.message, bad[b].needle) && strstr(err.message, want),
                         "sl_lr_finish, case %zu: status %d: %s", b, (int)st, err.message);
        }
        if (k < lr->meshrect_count) {
            lr->meshrects[k] = keep;
            st = sl_lr_finish(lr, &err);
            SL_CHECK_MSG(st == SL_OK, "sl_lr_finish on the restored model: %s", err.message);
        }
    }
    sl_dataset_destroy(ds);
    free(text);
}

int main(void)
{
    srand(31);
    const fixture scalar = {SCALAR_PATH, "lrsplines_minspan3_scalar", 1, 358, 60, 264, 8, 8.0,
                            {{0, 0.5, 0.125}, {1, 0.5, 0.125}, 1}, 1};
    const fixture vector = {VECTOR_PATH, "lrsplines_minspan2_vector", 3, 966, 69, 874, 3, 4.0,
                            {{0.3125, 0.125, 0}, {0.3125, 0.125, 0.5}, 1}, 0};
    test_fixture(&scalar);
    test_fixture(&vector);
    test_refusals();
    SL_TEST_END();
}
