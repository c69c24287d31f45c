/* flow_seeds.c — seed points for streamlines: a CSV of x,y,z, a box with a
 * count (Halton points, deterministic) and a plane lattice (sl_flow.h gives
 * the exact specs). Parses bytes in memory; checks the count limit before
 * allocating. Any thread; no GL.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sl_flow.h"

/* Parses exactly n comma-separated finite numbers from s (whole string up
 * to end, spaces allowed). Returns the count parsed when all is well, else -1. */
static int parse_numbers(const char *s, const char *end, double *out, int n)
{
    int k = 0;
    const char *p = s;
    for (;;) {
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\r'))
            p++;
        if (k == n)
            return p == end ? k : -1;
        char buf[64];
        size_t len = 0;
        while (p + len < end && p[len] != ',' && len < sizeof buf - 1)
            len++;
        if (len == 0 || len == sizeof buf - 1)
            return -1;
        memcpy(buf, p, len);
        buf[len] = 0;
        char *q;
        errno = 0;
        double v = strtod(buf, &q);
        while (*q == ' ' || *q == '\t' || *q == '\r')
            q++;
        if (*q || q == buf || !isfinite(v))
            return -1;
        out[k++] = v;
        p += len;
        if (k < n) {
            if (p >= end || *p != ',')
                return -1;
            p++;
        }
    }
}

sl_status sl_flow_seeds_csv(const char *text, size_t size, double **seeds, size_t *count, sl_err *err)
{
    *seeds = NULL;
    *count = 0;
    size_t cap = 0, n = 0, line_no = 0;
    double *s = NULL;
    const char *p = text, *end = text + size;
    while (p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol)
            eol = end;
        line_no++;
        const char *q = p;
        while (q < eol && isspace((unsigned char)*q))
            q++;
        if (q < eol && *q != '#') {
            double v[3];
            if (parse_numbers(q, eol, v, 3) != 3) {
                if (line_no == 1 && n == 0) {
                    p = eol + (eol < end);
                    continue;              /* a header line */
                }
                free(s);
                return sl_err_set(err, SL_ERR_FORMAT, "seed line %zu is not three numbers x,y,z", line_no);
            }
            if (n == SL_FLOW_MAX_SEEDS) {
                free(s);
                return sl_err_set(err, SL_ERR_LIMIT, "more than %u seeds", (unsigned)SL_FLOW_MAX_SEEDS);
            }
            if (n == cap) {
                cap = cap ? 2 * cap : 64;
                double *ns = realloc(s, 3 * cap * sizeof *ns);
                if (!ns) {
                    free(s);
                    return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu seeds", cap);
                }
                s = ns;
            }
            memcpy(s + 3 * n, v, sizeof v);
            n++;
        }
        p = eol + (eol < end);
    }
    if (n == 0) {
        free(s);
        return sl_err_set(err, SL_ERR_FORMAT, "the seed file holds no x,y,z line");
    }
    *seeds = s;
    *count = n;
    return SL_OK;
}

static double halton(size_t i, unsigned base)
{
    double f = 1.0, r = 0.0;
    while (i > 0) {
        f /= base;
        r += f * (double)(i % base);
        i /= base;
    }
    return r;
}

static sl_status count_of(double v, const char *what, size_t *n, sl_err *err)
{
    if (!(v >= 1.0 && v <= (double)SL_FLOW_MAX_SEEDS && v == floor(v)))
        return sl_err_set(err, SL_ERR_INVALID, "%s must be an integer in 1..%u (got %g)", what,
                          (unsigned)SL_FLOW_MAX_SEEDS, v);
    *n = (size_t)v;
    return SL_OK;
}

sl_status sl_flow_seeds_box(const char *spec, double **seeds, size_t *count, sl_err *err)
{
    double v[7];
    *seeds = NULL;
    *count = 0;
    if (parse_numbers(spec, spec + strlen(spec), v, 7) != 7)
        return sl_err_set(err, SL_ERR_INVALID, "seed box '%s' is not x0,y0,z0,x1,y1,z1,count", spec);
    size_t n = 0;
    sl_status st = count_of(v[6], "the seed box count", &n, err);
    if (st != SL_OK)
        return st;
    double *s = malloc(3 * n * sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu seeds", n);
    static const unsigned base[3] = {2, 3, 5};
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            s[3 * i + a] = v[a] + (v[3 + a] - v[a]) * halton(i + 1, base[a]);
    *seeds = s;
    *count = n;
    return SL_OK;
}

sl_status sl_flow_seeds_plane(const char *spec, double **seeds, size_t *count, sl_err *err)
{
    double v[11];
    *seeds = NULL;
    *count = 0;
    if (parse_numbers(spec, spec + strlen(spec), v, 11) != 11)
        return sl_err_set(err, SL_ERR_INVALID,
                          "seed plane '%s' is not ox,oy,oz,ux,uy,uz,vx,vy,vz,nu,nv", spec);
    size_t nu = 0, nv = 0;
    sl_status st = count_of(v[9], "the seed plane nu", &nu, err);
    if (st == SL_OK)
        st = count_of(v[10], "the seed plane nv", &nv, err);
    if (st != SL_OK)
        return st;
    if (nu * nv > SL_FLOW_MAX_SEEDS)
        return sl_err_set(err, SL_ERR_LIMIT, "seed plane of %zu x %zu seeds exceeds %u", nu, nv,
                          (unsigned)SL_FLOW_MAX_SEEDS);
    double *s = malloc(3 * nu * nv * sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu seeds", nu * nv);
    for (size_t j = 0; j < nv; j++)
        for (size_t i = 0; i < nu; i++) {
            double a = ((double)i + 0.5) / (double)nu, b = ((double)j + 0.5) / (double)nv;
            for (int c = 0; c < 3; c++)
                s[3 * (j * nu + i) + c] = v[c] + a * v[3 + c] + b * v[6 + c];
        }
    *seeds = s;
    *count = nu * nv;
    return SL_OK;
}
