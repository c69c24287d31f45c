/* lr_fit.c — adaptive LR-spline fitting of a regular volume (see
 * sl_lr_fit.h for the method, its stopping rules and error behaviour).
 *
 * The design matrix is stored per element: the samples inside an element
 * (element rule of sl_lr.h) form a box of the sample grid and share the
 * element's basis list, so a row is the element's basis count of weights
 * gamma_b B_b(x), computed separably (one univariate value per axis and
 * sample line). Any thread; no GL; single-threaded.
 */
#include "sl_lr_fit.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sl_lr_refine.h"

void sl_lr_fit_defaults(sl_lr_fit_params *p)
{
    memset(p, 0, sizeof *p);
    p->degree = 2;
    p->tol = 0.0;
    p->max_levels = 4;
    p->max_basis = 200000;
    p->cells_longest = 4;
    p->fraction = 0.5;
    p->stride = 1;
    p->max_iterations = 64;
    p->cg_iterations = 200;
    p->cg_tol = 1e-8;
}

typedef sl_lr_fit_samples samples;

typedef struct design {
    size_t rows;
    uint32_t *row_sample; /* sample index of each row */
    uint32_t *row_elem;
    size_t *row_off;      /* rows + 1, into val */
    double *val;
} design;

static void design_free(design *a)
{
    free(a->row_sample);
    free(a->row_elem);
    free(a->row_off);
    free(a->val);
    memset(a, 0, sizeof *a);
}

static int lower_bound(const double *x, int n, double v)
{
    int a = 0, b = n;
    while (a < b) {
        int m = (a + b) / 2;
        if (x[m] < v)
            a = m + 1;
        else
            b = m;
    }
    return a;
}

static int upper_bound(const double *x, int n, double v)
{
    int a = 0, b = n;
    while (a < b) {
        int m = (a + b) / 2;
        if (x[m] <= v)
            a = m + 1;
        else
            b = m;
    }
    return a;
}

/* Sample index range [first, end) of element e along axis a. */
static void element_range(const samples *s, const sl_lr_volume *lr, const sl_lr_element *e, int a, int *first,
                          int *end)
{
    *first = lower_bound(s->x[a], s->n[a], e->lo[a]);
    *end = e->hi[a] == lr->domain_hi[a] ? upper_bound(s->x[a], s->n[a], e->hi[a])
                                        : lower_bound(s->x[a], s->n[a], e->hi[a]);
}

static sl_status build_design(const samples *s, const sl_lr_volume *lr, design *a, sl_err *err)
{
    memset(a, 0, sizeof *a);
    size_t rows = 0, vals = 0;
    for (size_t i = 0; i < lr->element_count; i++) {
        const sl_lr_element *e = &lr->elements[i];
        size_t count = 1;
        for (int d = 0; d < 3; d++) {
            int f, z;
            element_range(s, lr, e, d, &f, &z);
            count *= (size_t)(z > f ? z - f : 0);
        }
        rows += count;
        vals += count * e->basis_count;
    }
    a->rows = rows;
    a->row_sample = malloc((rows ? rows : 1) * sizeof *a->row_sample);
    a->row_elem = malloc((rows ? rows : 1) * sizeof *a->row_elem);
    a->row_off = malloc((rows + 1) * sizeof *a->row_off);
    a->val = malloc((vals ? vals : 1) * sizeof *a->val);
    double *uni[3] = {NULL, NULL, NULL};
    size_t uni_cap = 0;
    if (!a->row_sample || !a->row_elem || !a->row_off || !a->val)
        goto oom;
    size_t r = 0, off = 0;
    for (size_t i = 0; i < lr->element_count; i++) {
        const sl_lr_element *e = &lr->elements[i];
        int f[3], z[3];
        for (int d = 0; d < 3; d++)
            element_range(s, lr, e, d, &f[d], &z[d]);
        if (z[0] <= f[0] || z[1] <= f[1] || z[2] <= f[2])
            continue;
        size_t nbe = e->basis_count;
        size_t need = nbe * (size_t)(s->n[0] + s->n[1] + s->n[2]);
        if (need > uni_cap) {
            free(uni[0]);
            uni[0] = malloc(need * sizeof(double));
            if (!uni[0])
                goto oom;
            uni_cap = need;
        }
        uni[1] = uni[0] + nbe * (size_t)s->n[0];
        uni[2] = uni[1] + nbe * (size_t)s->n[1];
        /* uni[d][k * n_d + m]: basis k's univariate value at sample m of axis d. */
        for (size_t k = 0; k < nbe; k++) {
            const sl_lr_basis *b = &lr->basis[lr->element_basis[e->basis_offset + k]];
            for (int d = 0; d < 3; d++)
                for (int m = f[d]; m < z[d]; m++) {
                    double v, dv;
                    sl_lr_bspline_piece(b->knots[d], lr->order[d], e->lo[d], e->hi[d], s->x[d][m], &v, &dv);
                    uni[d][k * (size_t)s->n[d] + (size_t)m] = d == 0 ? v * b->gamma : v;
                }
        }
        for (int kz = f[2]; kz < z[2]; kz++)
            for (int ky = f[1]; ky < z[1]; ky++)
                for (int kx = f[0]; kx < z[0]; kx++) {
                    a->row_sample[r] = (uint32_t)(((size_t)kz * s->n[1] + ky) * s->n[0] + kx);
                    a->row_elem[r] = (uint32_t)i;
                    a->row_off[r] = off;
                    for (size_t k = 0; k < nbe; k++)
                        a->val[off + k] = uni[0][k * s->n[0] + kx] * uni[1][k * s->n[1] + ky] *
                                          uni[2][k * s->n[2] + kz];
                    off += nbe;
                    r++;
                }
    }
    a->row_off[r] = off;
    a->rows = r;
    free(uni[0]);
    return SL_OK;
oom:
    free(uni[0]);
    design_free(a);
    return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the fit's design matrix (%zu rows)", rows);
}

/* out = A x (rows) */
static void mat_vec(const design *a, const sl_lr_volume *lr, const double *x, double *out)
{
    for (size_t r = 0; r < a->rows; r++) {
        const sl_lr_element *e = &lr->elements[a->row_elem[r]];
        const uint32_t *cols = lr->element_basis + e->basis_offset;
        const double *v = a->val + a->row_off[r];
        double sum = 0.0;
        for (uint32_t k = 0; k < e->basis_count; k++)
            sum += v[k] * x[cols[k]];
        out[r] = sum;
    }
}

/* out = A^T y (columns), out zeroed here */
static void mat_tvec(const design *a, const sl_lr_volume *lr, const double *y, double *out)
{
    memset(out, 0, lr->basis_count * sizeof *out);
    for (size_t r = 0; r < a->rows; r++) {
        const sl_lr_element *e = &lr->elements[a->row_elem[r]];
        const uint32_t *cols = lr->element_basis + e->basis_offset;
        const double *v = a->val + a->row_off[r];
        double yr = y[r];
        for (uint32_t k = 0; k < e->basis_count; k++)
            out[cols[k]] += v[k] * yr;
    }
}

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* CGLS with column scaling on component c, warm-started from the model's
 * coefficients; writes them back. */
static sl_status solve(const samples *s, const design *a, sl_lr_volume *lr, int c, int iterations, double cg_tol,
                       sl_err *err)
{
    size_t nb = lr->basis_count, rows = a->rows;
    double *x = malloc(nb * sizeof *x), *scale = malloc(nb * sizeof *scale), *z = calloc(nb, sizeof *z);
    double *p = malloc(nb * sizeof *p), *g = malloc(nb * sizeof *g), *t = malloc(nb * sizeof *t);
    double *r = malloc((rows ? rows : 1) * sizeof *r), *q = malloc((rows ? rows : 1) * sizeof *q);
    sl_status st = SL_OK;
    if (!x || !scale || !z || !p || !g || !t || !r || !q) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the least-squares solve");
        goto done;
    }
    for (size_t b = 0; b < nb; b++) {
        x[b] = lr->basis[b].coef[c];
        scale[b] = 0.0;
    }
    for (size_t i = 0; i < rows; i++) {
        const sl_lr_element *e = &lr->elements[a->row_elem[i]];
        const uint32_t *cols = lr->element_basis + e->basis_offset;
        const double *v = a->val + a->row_off[i];
        for (uint32_t k = 0; k < e->basis_count; k++)
            scale[cols[k]] += v[k] * v[k];
    }
    for (size_t b = 0; b < nb; b++)
        scale[b] = scale[b] > 0.0 ? 1.0 / sqrt(scale[b]) : 0.0;
    mat_vec(a, lr, x, q);
    double ynorm = 0.0;
    for (size_t i = 0; i < rows; i++) {
        double y = s->y[(size_t)a->row_sample[i] * s->dim + c];
        r[i] = y - q[i];
        ynorm += y * y;
    }
    ynorm = sqrt(ynorm);
    mat_tvec(a, lr, r, g);
    for (size_t b = 0; b < nb; b++)
        g[b] *= scale[b];
    memcpy(p, g, nb * sizeof *p);
    /* Stop when the scaled normal-equation residual is cg_tol of the data's
     * (A^T y scaled): relative to the data, not to the warm start's error. */
    double *ty = t;
    for (size_t i = 0; i < rows; i++)
        q[i] = s->y[(size_t)a->row_sample[i] * s->dim + c];
    mat_tvec(a, lr, q, ty);
    double gref = 0.0;
    for (size_t b = 0; b < nb; b++)
        gref += (scale[b] * ty[b]) * (scale[b] * ty[b]);
    double gamma = dot(g, g, nb);
    for (int it = 0; it < iterations && gamma > cg_tol * cg_tol * gref && gamma > 0.0; it++) {
        for (size_t b = 0; b < nb; b++)
            t[b] = scale[b] * p[b];
        mat_vec(a, lr, t, q);
        double qq = dot(q, q, rows);
        if (!(qq > 0.0))
            break;
        double alpha = gamma / qq;
        for (size_t b = 0; b < nb; b++)
            z[b] += alpha * p[b];
        for (size_t i = 0; i < rows; i++)
            r[i] -= alpha * q[i];
        if (sqrt(dot(r, r, rows)) <= 1e-16 * ynorm)
            break;
        mat_tvec(a, lr, r, g);
        for (size_t b = 0; b < nb; b++)
            g[b] *= scale[b];
        double gnew = dot(g, g, nb);
        double beta = gnew / gamma;
        gamma = gnew;
        for (size_t b = 0; b < nb; b++)
            p[b] = g[b] + beta * p[b];
    }
    for (size_t b = 0; b < nb; b++)
        lr->basis[b].coef[c] = x[b] + scale[b] * z[b];
done:
    free(x);
    free(scale);
    free(z);
    free(p);
    free(g);
    free(t);
    free(r);
    free(q);
    return st;
}

/* Error per row (vector length for vectors), element maxima, max and mean. */
static sl_status measure(const samples *s, const design *a, const sl_lr_volume *lr, double *elem_err,
                         double *max_error, double *mean_error, sl_err *err)
{
    double *x = malloc(lr->basis_count * sizeof *x), *q = malloc((a->rows ? a->rows : 1) * sizeof *q);
    double *e2 = calloc(a->rows ? a->rows : 1, sizeof *e2);
    if (!x || !q || !e2) {
        free(x);
        free(q);
        free(e2);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory measuring the fit error");
    }
    for (int c = 0; c < lr->dim; c++) {
        for (size_t b = 0; b < lr->basis_count; b++)
            x[b] = lr->basis[b].coef[c];
        mat_vec(a, lr, x, q);
        for (size_t i = 0; i < a->rows; i++) {
            double d = s->y[(size_t)a->row_sample[i] * s->dim + c] - q[i];
            e2[i] += d * d;
        }
    }
    for (size_t i = 0; i < lr->element_count; i++)
        elem_err[i] = 0.0;
    double mx = 0.0, sum = 0.0;
    for (size_t i = 0; i < a->rows; i++) {
        double e = sqrt(e2[i]);
        mx = fmax(mx, e);
        sum += e;
        elem_err[a->row_elem[i]] = fmax(elem_err[a->row_elem[i]], e);
    }
    *max_error = mx;
    *mean_error = a->rows ? sum / (double)a->rows : 0.0;
    free(x);
    free(q);
    free(e2);
    return SL_OK;
}

static sl_status copy_model(const sl_lr_volume *in, sl_lr_volume *out, sl_err *err)
{
    sl_status st = sl_lr_alloc(out, in->basis_count, in->meshrect_count, in->element_count,
                               in->element_basis_count, err);
    if (st != SL_OK)
        return st;
    sl_lr_basis *b = out->basis;
    sl_lr_meshrect *m = out->meshrects;
    sl_lr_element *e = out->elements;
    uint32_t *eb = out->element_basis;
    *out = *in;
    out->basis = b;
    out->meshrects = m;
    out->elements = e;
    out->element_basis = eb;
    out->index = NULL; /* the copy has no look-up of its own */
    memcpy(b, in->basis, in->basis_count * sizeof *b);
    memcpy(m, in->meshrects, in->meshrect_count * sizeof *m);
    memcpy(e, in->elements, in->element_count * sizeof *e);
    memcpy(eb, in->element_basis, in->element_basis_count * sizeof *eb);
    return SL_OK;
}

typedef struct rank {
    double err;
    uint32_t id;
} rank;

static int rank_cmp(const void *pa, const void *pb)
{
    const rank *a = pa, *b = pb;
    if (a->err != b->err)
        return a->err > b->err ? -1 : 1;
    return (a->id > b->id) - (a->id < b->id);
}

/* 1 when a knot span [a, z] in direction d may still be halved. */
static int halvable(double a, double z, const double min_span[3], int d)
{
    return z - a >= 2.0 * min_span[d] * (1.0 - 1e-9);
}

/* Structured: the basis functions with an error above tol in their support
 * (the largest element error there) and a span that may be halved, into
 * cand (unsorted); basis_err is scratch of basis_count zeros. Returns how many. */
static size_t rank_basis(const sl_lr_volume *lr, const double *elem_err, double tol, const double min_span[3],
                         double *basis_err, rank *cand)
{
    for (size_t e = 0; e < lr->element_count; e++) {
        const sl_lr_element *x = &lr->elements[e];
        for (uint32_t k = 0; k < x->basis_count; k++) {
            uint32_t b = lr->element_basis[x->basis_offset + k];
            basis_err[b] = fmax(basis_err[b], elem_err[e]);
        }
    }
    size_t nc = 0;
    for (size_t b = 0; b < lr->basis_count; b++) {
        if (!(basis_err[b] > tol))
            continue;
        int refinable = 0;
        const sl_lr_basis *bb = &lr->basis[b];
        for (int d = 0; d < 3 && !refinable; d++)
            for (int k = 0; k < lr->order[d] && !refinable; k++)
                refinable = halvable(bb->knots[d][k], bb->knots[d][k + 1], min_span, d);
        if (refinable)
            cand[nc++] = (rank){basis_err[b], (uint32_t)b};
    }
    return nc;
}

/* Minimal span: the elements with an error above tol and a side that may
 * be halved, into cand (unsorted). Returns how many. */
static size_t rank_elements(const sl_lr_volume *lr, const double *elem_err, double tol, const double min_span[3],
                            rank *cand)
{
    size_t nc = 0;
    for (size_t e = 0; e < lr->element_count; e++) {
        const sl_lr_element *x = &lr->elements[e];
        int refinable = 0;
        for (int d = 0; d < 3; d++)
            refinable |= halvable(x->lo[d], x->hi[d], min_span, d);
        if (elem_err[e] > tol && refinable)
            cand[nc++] = (rank){elem_err[e], (uint32_t)e};
    }
    return nc;
}

typedef struct coef_ctx {
    const samples *s;
} coef_ctx;

static void nearest_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)ijk;
    const samples *s = ((coef_ctx *)user)->s;
    int m[3];
    for (int d = 0; d < 3; d++) {
        int k = lower_bound(s->x[d], s->n[d], g[d]);
        if (k >= s->n[d])
            k = s->n[d] - 1;
        if (k > 0 && g[d] - s->x[d][k - 1] < s->x[d][k] - g[d])
            k--;
        m[d] = k;
    }
    size_t idx = ((size_t)m[2] * s->n[1] + m[1]) * s->n[0] + m[0];
    for (int c = 0; c < s->dim; c++)
        coef[c] = s->y[idx * s->dim + c];
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

sl_status sl_lr_fit_check_params(const sl_lr_fit_params *p, sl_err *err)
{
    if (p->degree < 1 || p->degree > SL_LR_MAX_ORDER - 1)
        return sl_err_set(err, SL_ERR_INVALID, "degree %d is outside 1..%d", p->degree, SL_LR_MAX_ORDER - 1);
    if (!(p->tol >= 0.0) || !isfinite(p->tol))
        return sl_err_set(err, SL_ERR_INVALID, "tolerance %g must be finite and >= 0", p->tol);
    if (p->max_levels < 0 || p->max_levels > 16)
        return sl_err_set(err, SL_ERR_INVALID, "max levels %d is outside 0..16", p->max_levels);
    if (p->cells_longest < 1 || p->cells_longest > 1024)
        return sl_err_set(err, SL_ERR_INVALID, "initial cells %d is outside 1..1024", p->cells_longest);
    if (p->strategy != SL_LR_FIT_STRUCTURED && p->strategy != SL_LR_FIT_MINIMAL_SPAN)
        return sl_err_set(err, SL_ERR_INVALID, "unknown refinement strategy %d", (int)p->strategy);
    if (!(p->fraction > 0.0 && p->fraction <= 1.0))
        return sl_err_set(err, SL_ERR_INVALID, "refinement fraction %g is outside (0, 1]", p->fraction);
    if (!(p->cg_tol > 0.0 && p->cg_tol < 1.0))
        return sl_err_set(err, SL_ERR_INVALID, "CG tolerance %g is outside (0, 1)", p->cg_tol);
    if (p->stride < 1 || p->max_iterations < 0 || p->cg_iterations < 1)
        return sl_err_set(err, SL_ERR_INVALID, "stride, iterations and CG iterations must be positive");
    if (p->max_basis < 1 || p->max_basis > SL_LR_MAX_BASIS)
        return sl_err_set(err, SL_ERR_INVALID, "basis cap %zu is outside 1..%u", p->max_basis, SL_LR_MAX_BASIS);
    return SL_OK;
}

sl_status sl_lr_fit_grid(const sl_lr_fit_samples *grid, const sl_lr_fit_params *p, sl_lr_volume *out,
                         sl_lr_fit_stats *stats, sl_err *err)
{
    memset(out, 0, sizeof *out);
    memset(stats, 0, sizeof *stats);
    sl_status st = sl_lr_fit_check_params(p, err);
    if (st != SL_OK)
        return st;
    for (int d = 0; d < 3; d++)
        if (grid->n[d] < 2 || !(grid->hi[d] > grid->lo[d]))
            return sl_err_set(err, SL_ERR_INVALID, "the samples have %d points along axis %d: need at least 2",
                              grid->n[d], d);
    if (grid->dim != 1 && grid->dim != 3)
        return sl_err_set(err, SL_ERR_INVALID, "%d components: the fit takes 1 or 3", grid->dim);
    double t0 = now_seconds();
    const samples s = *grid;
    /* The initial tensor mesh. */
    double longest = 0.0, h0[3], min_span[3];
    for (int d = 0; d < 3; d++)
        longest = fmax(longest, s.hi[d] - s.lo[d]);
    int order[3], count[3];
    double *knots[3] = {NULL, NULL, NULL};
    for (int d = 0; d < 3; d++) {
        double ext = s.hi[d] - s.lo[d];
        int cells = (int)fmax(1.0, round(p->cells_longest * ext / longest));
        order[d] = p->degree + 1;
        count[d] = cells + 1 + 2 * p->degree;
        knots[d] = malloc((size_t)count[d] * sizeof(double));
        if (!knots[d]) {
            st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for knots");
            goto knots_done;
        }
        int m = 0;
        for (int q = 0; q < p->degree; q++)
            knots[d][m++] = s.lo[d];
        for (int c = 0; c <= cells; c++)
            knots[d][m++] = c == cells ? s.hi[d] : s.lo[d] + ext * c / cells;
        for (int q = 0; q < p->degree; q++)
            knots[d][m++] = s.hi[d];
        h0[d] = ext / cells;
        /* No knot span below two sample spacings: finer elements are not
         * determined by the samples and the least-squares spline wiggles
         * between them (seen as element-sized tiles in lr_volume). */
        double spacing = s.n[d] > 1 ? ext / (s.n[d] - 1) : ext;
        min_span[d] = fmax(h0[d] / ldexp(1.0, p->max_levels), 2.0 * spacing);
    }
    coef_ctx cc = {&s};
    st = sl_lr_tensor_product(out, order, s.dim, (const double *const *)knots, count, nearest_coef, &cc, err);
knots_done:
    for (int d = 0; d < 3; d++)
        free(knots[d]);
    if (st != SL_OK) {
        return st;
    }
    if (out->basis_count > p->max_basis) {
        sl_lr_free(out);
        return sl_err_set(err, SL_ERR_INVALID, "the initial mesh already has %zu basis functions, above the"
                          " cap of %zu", out->basis_count, p->max_basis);
    }
    design a = {0};
    double *elem_err = NULL, *basis_err = NULL;
    rank *cand = NULL;
    uint32_t *ids = NULL;
    sl_lr_volume prev = {0};
    double refine_seconds = 0.0;
    for (int iter = 0;; iter++) {
        double tp0 = now_seconds();
        design_free(&a);
        if ((st = build_design(&s, out, &a, err)) != SL_OK)
            break;
        double tp1 = now_seconds();
        for (int c = 0; c < s.dim && st == SL_OK; c++)
            st = solve(&s, &a, out, c, p->cg_iterations, p->cg_tol, err);
        if (st != SL_OK)
            break;
        free(elem_err);
        free(basis_err);
        free(cand);
        free(ids);
        elem_err = malloc(out->element_count * sizeof *elem_err);
        basis_err = calloc(out->basis_count, sizeof *basis_err);
        size_t ranked = out->basis_count > out->element_count ? out->basis_count : out->element_count;
        cand = malloc(ranked * sizeof *cand);
        ids = malloc(ranked * sizeof *ids);
        if (!elem_err || !basis_err || !cand || !ids) {
            st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the error measures");
            break;
        }
        double tp2 = now_seconds();
        double mx = 0.0, mean = 0.0;
        if ((st = measure(&s, &a, out, elem_err, &mx, &mean, err)) != SL_OK)
            break;
        double tp3 = now_seconds();
        double finest = 0.0;
        for (int d = 0; d < 3; d++)
            finest = fmax(finest, log2(h0[d] / out->min_side[d]));
        stats->iterations = iter;
        stats->levels = (int)lround(finest);
        stats->elements = out->element_count;
        stats->basis = out->basis_count;
        stats->samples = a.rows;
        stats->max_error = mx;
        stats->mean_error = mean;
        if (p->log)
            fprintf(p->log, "iteration %d: %zu elements, %zu basis functions, %d levels, max error %.6g,"
                    " mean error %.6g (design %.2f s, solve %.2f s, check %.2f s, refine %.2f s)\n", iter,
                    out->element_count, out->basis_count, stats->levels, mx, mean, tp1 - tp0, tp2 - tp1, tp3 - tp2,
                    refine_seconds);
        if (mx <= p->tol || iter >= p->max_iterations)
            break;
        size_t nc = p->strategy == SL_LR_FIT_MINIMAL_SPAN ? rank_elements(out, elem_err, p->tol, min_span, cand)
                                                           : rank_basis(out, elem_err, p->tol, min_span, basis_err, cand);
        if (nc == 0) {
            stats->levels_exhausted = 1;
            break;
        }
        qsort(cand, nc, sizeof *cand, rank_cmp);
        size_t take = (size_t)ceil(p->fraction * (double)nc);
        for (size_t k = 0; k < take; k++)
            ids[k] = cand[k].id;
        sl_lr_free(&prev);
        if ((st = copy_model(out, &prev, err)) != SL_OK)
            break;
        double tr = now_seconds();
        st = p->strategy == SL_LR_FIT_MINIMAL_SPAN ? sl_lr_refine_elements(out, ids, take, min_span, 0, NULL, err)
                                                    : sl_lr_refine_basis(out, ids, take, min_span, 0, NULL, err);
        if (st != SL_OK)
            break;
        refine_seconds = now_seconds() - tr;
        if (out->basis_count > p->max_basis) {
            /* Keep the last fitted model within the cap. */
            sl_lr_free(out);
            *out = prev;
            memset(&prev, 0, sizeof prev);
            stats->cap_hit = 1;
            break;
        }
    }
    design_free(&a);
    free(elem_err);
    free(basis_err);
    free(cand);
    free(ids);
    sl_lr_free(&prev);
    /* The value range after the last coefficients (and the last check). */
    if (st == SL_OK)
        st = sl_lr_finish(out, err);
    stats->seconds = now_seconds() - t0;
    if (st != SL_OK)
        sl_lr_free(out);
    return st;
}
