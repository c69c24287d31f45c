/* test_lr_write.c — the LRsplines text writer (renderer/lrspline/lr_write.c).
 *
 * A small tensor-product model (orders 3, 2, 2, uneven knots, scalar and
 * vector) is written and read back line by line against the layout of the
 * reference library (header comments, the counts line, "id: [..] x [..] x
 * [..] c (gamma)", "[a, b] x [c, d] x [e, f] (m)", "id [3] : (..) x (..)
 * {..}"), parsed here with sscanf/strtod independently of the writer; every
 * number must read back bit-equal. The .gz file variant must inflate to the
 * same bytes as the plain stream. (The round trip through the loader is the
 * lead's test: the loader is written elsewhere.)
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_write.h"
#include "sl_test.h"

static void coef(void *user, const int ijk[3], const double g[3], double *c)
{
    (void)g;
    int dim = *(int *)user;
    for (int q = 0; q < dim; q++)
        c[q] = ijk[0] + 10.0 * ijk[1] + 100.0 * ijk[2] + 0.1 + q / 3.0;
}

/* Reads n numbers after a '[' up to ']', returns the pointer after "] ". */
static const char *read_bracket(const char *s, const double *expect, int n, int *ok)
{
    if (*s != '[') {
        *ok = 0;
        return s;
    }
    s++;
    for (int i = 0; i < n; i++) {
        char *end;
        double v = strtod(s, &end);
        if (end == s || v != expect[i] || *end != ' ')
            *ok = 0;
        s = end + 1;
    }
    if (s[0] != ']' || s[1] != ' ')
        *ok = 0;
    return s + 2;
}

static char *slurp(FILE *f, size_t *len)
{
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    char *buf = malloc((size_t)n + 1);
    size_t got = fread(buf, 1, (size_t)n, f);
    buf[got] = 0;
    *len = got;
    return buf;
}

static void check_text(const sl_lr_volume *lr, char *text)
{
    char *save = NULL;
    char *line = strtok_r(text, "\n", &save);
    SL_CHECK(line && strcmp(line, "# LRSPLINE VOLUME") == 0);
    line = strtok_r(NULL, "\n", &save);
    SL_CHECK(line && strcmp(line, "#\tp1\tp2\tp3\tNbasis\tNline\tNel\tdim\trat") == 0);
    line = strtok_r(NULL, "\n", &save);
    char expect[256];
    snprintf(expect, sizeof expect, "\t%d\t%d\t%d\t%zu\t%zu\t%zu\t%d\t0", lr->order[0], lr->order[1],
             lr->order[2], lr->basis_count, lr->meshrect_count, lr->element_count, lr->dim);
    SL_CHECK(line && strcmp(line, expect) == 0);
    line = strtok_r(NULL, "\n", &save);
    SL_CHECK(line && strcmp(line, "# Basis functions:") == 0);
    for (size_t i = 0; i < lr->basis_count; i++) {
        line = strtok_r(NULL, "\n", &save);
        SL_CHECK(line != NULL);
        if (!line)
            return;
        const sl_lr_basis *b = &lr->basis[i];
        int ok = 1, n = 0;
        size_t id = 9999;
        SL_CHECK(sscanf(line, "%zu: %n", &id, &n) == 1 && id == i);
        const char *s = line + n;
        for (int d = 0; d < 3; d++) {
            if (d > 0) {
                ok &= strncmp(s, "x ", 2) == 0;
                s += 2;
            }
            s = read_bracket(s, b->knots[d], lr->order[d] + 1, &ok);
        }
        for (int c = 0; c < lr->dim; c++) {
            char *end;
            double v = strtod(s, &end);
            ok &= end != s && v == b->coef[c] && *end == ' ';
            s = end + 1;
        }
        double g = 0;
        int m = 0;
        ok &= sscanf(s, "(%lf)%n", &g, &m) == 1 && g == b->gamma && s[m] == 0;
        SL_CHECK_MSG(ok, "basis line %zu: \"%s\"", i, line);
    }
    line = strtok_r(NULL, "\n", &save);
    SL_CHECK(line && strcmp(line, "# Mesh rectangles:") == 0);
    for (size_t i = 0; i < lr->meshrect_count; i++) {
        line = strtok_r(NULL, "\n", &save);
        SL_CHECK(line != NULL);
        if (!line)
            return;
        double v[6];
        int mult = 0, n = 0;
        int got = sscanf(line, "[%lf, %lf] x [%lf, %lf] x [%lf, %lf] (%d)%n", &v[0], &v[1], &v[2], &v[3],
                         &v[4], &v[5], &mult, &n);
        const sl_lr_meshrect *r = &lr->meshrects[i];
        SL_CHECK_MSG(got == 7 && line[n] == 0 && v[0] == r->lo[0] && v[1] == r->hi[0] && v[2] == r->lo[1] &&
                         v[3] == r->hi[1] && v[4] == r->lo[2] && v[5] == r->hi[2] && mult == r->multiplicity,
                     "mesh rectangle line %zu: \"%s\"", i, line);
    }
    line = strtok_r(NULL, "\n", &save);
    SL_CHECK(line && strcmp(line, "# Elements:") == 0);
    for (size_t i = 0; i < lr->element_count; i++) {
        line = strtok_r(NULL, "\n", &save);
        SL_CHECK(line != NULL);
        if (!line)
            return;
        const sl_lr_element *e = &lr->elements[i];
        size_t id = 0;
        double v[6];
        int n = 0;
        int got = sscanf(line, "%zu [3] : (%lf, %lf, %lf) x (%lf, %lf, %lf)    {%n", &id, &v[0], &v[1], &v[2],
                         &v[3], &v[4], &v[5], &n);
        int ok = got == 7 && n > 0 && id == i && v[0] == e->lo[0] && v[1] == e->lo[1] && v[2] == e->lo[2] &&
                 v[3] == e->hi[0] && v[4] == e->hi[1] && v[5] == e->hi[2];
        const char *s = line + n;
        for (uint32_t k = 0; ok && k < e->basis_count; k++) {
            char *end;
            unsigned long b = strtoul(s, &end, 10);
            ok &= end != s && b == lr->element_basis[e->basis_offset + k];
            s = end;
            if (k + 1 < e->basis_count) {
                ok &= strncmp(s, ", ", 2) == 0;
                s += 2;
            }
        }
        ok = ok && strcmp(s, "}") == 0;
        SL_CHECK_MSG(ok, "element line %zu: \"%s\"", i, line);
    }
    SL_CHECK(strtok_r(NULL, "\n", &save) == NULL);
}

static void test_layout(int dim)
{
    const double u[] = {0, 0, 0, 0.3, 1.0 / 3.0, 1, 1, 1};
    const double v[] = {-1, -1, 0.5, 2, 2};
    const double w[] = {0, 0, 1e-3, 7, 7};
    const double *k[3] = {u, v, w};
    int order[3] = {3, 2, 2}, count[3] = {8, 5, 5};
    sl_lr_volume lr;
    sl_err err = {0};
    SL_CHECK(sl_lr_tensor_product(&lr, order, dim, k, count, coef, &dim, &err) == SL_OK);
    lr.basis[2].gamma = 0.1; /* any value must survive the writing */
    FILE *f = tmpfile();
    SL_CHECK(f != NULL);
    SL_CHECK(sl_lr_write(&lr, f, &err) == SL_OK);
    size_t len;
    char *text = slurp(f, &len);
    fclose(f);
    char *copy = malloc(len + 1);
    memcpy(copy, text, len + 1);
    check_text(&lr, copy);
    free(copy);

    /* The .gz and plain files hold the same text. */
    char path[64], gzpath[80];
    snprintf(path, sizeof path, "/tmp/test_lr_write_%d_%d.lr", (int)getpid(), dim);
    snprintf(gzpath, sizeof gzpath, "%s.gz", path);
    SL_CHECK(sl_lr_write_file(&lr, path, &err) == SL_OK);
    SL_CHECK(sl_lr_write_file(&lr, gzpath, &err) == SL_OK);
    FILE *pf = fopen(path, "rb");
    SL_CHECK(pf != NULL);
    size_t plen = 0;
    char *plain = pf ? slurp(pf, &plen) : NULL;
    if (pf)
        fclose(pf);
    SL_CHECK(plain && plen == len && memcmp(plain, text, len) == 0);
    gzFile gz = gzopen(gzpath, "rb");
    SL_CHECK(gz != NULL);
    char *inflated = malloc(len + 16);
    int got = gz ? gzread(gz, inflated, (unsigned)(len + 16)) : -1;
    if (gz)
        gzclose(gz);
    SL_CHECK(got == (int)len && memcmp(inflated, text, len) == 0);
    remove(path);
    remove(gzpath);
    free(inflated);
    free(plain);
    free(text);

    /* A path that cannot be created is refused with a sentence. */
    SL_CHECK(sl_lr_write_file(&lr, "/nonexistent-dir/x.lr", &err) == SL_ERR_IO);
    SL_CHECK(strstr(err.message, "/nonexistent-dir/x.lr") != NULL);
    sl_lr_free(&lr);
}

int main(void)
{
    test_layout(1);
    test_layout(3);
    SL_TEST_END();
}
