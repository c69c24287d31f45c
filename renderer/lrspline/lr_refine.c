/* lr_refine.c — mesh rectangle insertion into an LR-spline volume (see
 * sl_lr_refine.h for the method and its limits).
 *
 * The mesh is held as its elements (a box partition): a plane x_d = v
 * traverses a basis function's support exactly when no element inside the
 * support straddles v (lo[d] < v < hi[d]). Supports are unions of elements,
 * so the elements a rectangle crosses are split whole. Elements are found
 * through a uniform bucket grid (buckets overlapping a box, by a monotone
 * map, so no overlap is missed); identical basis functions through a hash of
 * their knot vectors. Any thread; no GL; all memory freed before returning.
 */
#include "sl_lr_refine.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct box {
    double lo[3], hi[3];
} box;

/* ---- growable arrays ---------------------------------------------------- */

static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    void *q = realloc(*p, c * size);
    if (!q)
        return 0;
    *p = q;
    *cap = c;
    return 1;
}

typedef struct u32vec {
    uint32_t *v;
    size_t n, cap;
} u32vec;

static int u32_push(u32vec *a, uint32_t x)
{
    if (!grow((void **)&a->v, &a->cap, a->n + 1, sizeof *a->v))
        return 0;
    a->v[a->n++] = x;
    return 1;
}

/* ---- bucket grid over element boxes -------------------------------------- */

typedef struct grid {
    double lo[3], scale[3];
    int n[3];
    uint32_t *start; /* n0*n1*n2 + 1 */
    uint32_t *items;
    uint32_t *stamp; /* per element */
    uint32_t stamp_value;
} grid;

static int grid_index(const grid *g, int d, double x)
{
    double t = (x - g->lo[d]) * g->scale[d];
    if (!(t > 0.0))
        return 0;
    if (t >= g->n[d])
        return g->n[d] - 1;
    return (int)t;
}

static void grid_free(grid *g)
{
    free(g->start);
    free(g->items);
    free(g->stamp);
    memset(g, 0, sizeof *g);
}

static int grid_build(grid *g, const box *b, size_t n, const double dlo[3], const double dhi[3])
{
    memset(g, 0, sizeof *g);
    double min_side[3] = {INFINITY, INFINITY, INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < 3; d++)
            min_side[d] = fmin(min_side[d], b[i].hi[d] - b[i].lo[d]);
    double per_axis = cbrt(2.0 * (double)n) + 1.0;
    size_t cells = 1;
    for (int d = 0; d < 3; d++) {
        double ext = dhi[d] - dlo[d];
        double want = fmin(per_axis, ext / min_side[d]);
        g->n[d] = (int)fmax(1.0, fmin(want, 1024.0));
        g->lo[d] = dlo[d];
        g->scale[d] = g->n[d] / ext;
        cells *= (size_t)g->n[d];
    }
    g->start = calloc(cells + 1, sizeof *g->start);
    g->stamp = calloc(n ? n : 1, sizeof *g->stamp);
    if (!g->start || !g->stamp)
        goto fail;
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            uint32_t acc = 0;
            for (size_t c = 0; c <= cells; c++) {
                uint32_t k = g->start[c];
                g->start[c] = acc;
                acc += k;
            }
            total = acc;
            g->items = malloc((total ? total : 1) * sizeof *g->items);
            if (!g->items)
                goto fail;
        }
        for (size_t i = 0; i < n; i++) {
            int a[3], z[3];
            for (int d = 0; d < 3; d++) {
                a[d] = grid_index(g, d, b[i].lo[d]);
                z[d] = grid_index(g, d, b[i].hi[d]);
            }
            for (int k = a[2]; k <= z[2]; k++)
                for (int j = a[1]; j <= z[1]; j++)
                    for (int q = a[0]; q <= z[0]; q++) {
                        size_t c = ((size_t)k * g->n[1] + j) * g->n[0] + q;
                        if (pass == 0)
                            g->start[c]++;
                        else
                            g->items[g->start[c]++] = (uint32_t)i;
                    }
        }
    }
    /* start[c] now holds the end of bucket c: shift back. */
    for (size_t c = cells; c > 0; c--)
        g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    (void)total;
    return 1;
fail:
    grid_free(g);
    return 0;
}

/* Elements whose box overlaps q (lo < q.hi and hi > q.lo per direction; for a
 * flat direction that is lo < v < hi). out is cleared first. */
static int grid_query(grid *g, const box *b, const box *q, u32vec *out)
{
    out->n = 0;
    if (++g->stamp_value == 0) {
        g->stamp_value = 1;
        /* stamps wrapped: callers never get here in practice (2^32 queries) */
    }
    int a[3], z[3];
    for (int d = 0; d < 3; d++) {
        a[d] = grid_index(g, d, q->lo[d]);
        z[d] = grid_index(g, d, q->hi[d]);
    }
    for (int k = a[2]; k <= z[2]; k++)
        for (int j = a[1]; j <= z[1]; j++)
            for (int i = a[0]; i <= z[0]; i++) {
                size_t c = ((size_t)k * g->n[1] + j) * g->n[0] + i;
                for (uint32_t s = g->start[c]; s < g->start[c + 1]; s++) {
                    uint32_t e = g->items[s];
                    if (g->stamp[e] == g->stamp_value)
                        continue;
                    g->stamp[e] = g->stamp_value;
                    const box *x = &b[e];
                    int hit = 1;
                    for (int d = 0; d < 3 && hit; d++)
                        hit = x->lo[d] < q->hi[d] && x->hi[d] > q->lo[d];
                    if (hit && !u32_push(out, e))
                        return 0;
                }
            }
    return 1;
}

/* ---- basis functions with a knot hash ------------------------------------ */

typedef struct bset {
    int order[3], dim;
    sl_lr_basis *b;
    unsigned char *alive;
    size_t n, cap, cap_alive;
    uint32_t *head; /* hash buckets, UINT32_MAX = empty */
    uint32_t *next;
    size_t hcap, cap_next, alive_count;
} bset;

static uint64_t knot_hash(const bset *s, const sl_lr_basis *b)
{
    uint64_t h = 1469598103934665603ull;
    for (int d = 0; d < 3; d++)
        for (int k = 0; k <= s->order[d]; k++) {
            double x = b->knots[d][k] + 0.0; /* -0 as 0 */
            uint64_t bits;
            memcpy(&bits, &x, sizeof bits);
            h = (h ^ bits) * 1099511628211ull;
            h ^= h >> 29;
        }
    return h;
}

static int same_knots(const bset *s, const sl_lr_basis *a, const sl_lr_basis *b)
{
    for (int d = 0; d < 3; d++)
        for (int k = 0; k <= s->order[d]; k++)
            if (a->knots[d][k] != b->knots[d][k])
                return 0;
    return 1;
}

static int bset_rehash(bset *s, size_t hcap)
{
    uint32_t *head = malloc(hcap * sizeof *head);
    if (!head)
        return 0;
    for (size_t i = 0; i < hcap; i++)
        head[i] = UINT32_MAX;
    free(s->head);
    s->head = head;
    s->hcap = hcap;
    for (size_t i = 0; i < s->n; i++)
        if (s->alive[i]) {
            size_t h = (size_t)(knot_hash(s, &s->b[i]) & (hcap - 1));
            s->next[i] = head[h];
            head[h] = (uint32_t)i;
        }
    return 1;
}

static long bset_find(const bset *s, const sl_lr_basis *b)
{
    size_t h = (size_t)(knot_hash(s, b) & (s->hcap - 1));
    for (uint32_t i = s->head[h]; i != UINT32_MAX; i = s->next[i])
        if (same_knots(s, &s->b[i], b))
            return (long)i;
    return -1;
}

static void bset_unlink(bset *s, uint32_t id)
{
    size_t h = (size_t)(knot_hash(s, &s->b[id]) & (s->hcap - 1));
    uint32_t *p = &s->head[h];
    while (*p != UINT32_MAX && *p != id)
        p = &s->next[*p];
    if (*p == id)
        *p = s->next[id];
    s->alive[id] = 0;
    s->alive_count--;
}

/* Adds gamma * c * B (B of knots nb) to the set: a new function or merged. */
static long bset_add(bset *s, const sl_lr_basis *nb)
{
    long found = bset_find(s, nb);
    if (found >= 0) {
        sl_lr_basis *x = &s->b[found];
        double g = x->gamma + nb->gamma;
        for (int c = 0; c < s->dim; c++)
            x->coef[c] = (x->gamma * x->coef[c] + nb->gamma * nb->coef[c]) / g;
        x->gamma = g;
        return found;
    }
    if (s->n + 1 > SL_LR_MAX_BASIS)
        return -2;
    if (!grow((void **)&s->b, &s->cap, s->n + 1, sizeof *s->b) ||
        !grow((void **)&s->alive, &s->cap_alive, s->n + 1, 1) ||
        !grow((void **)&s->next, &s->cap_next, s->n + 1, sizeof *s->next))
        return -1;
    uint32_t id = (uint32_t)s->n++;
    s->b[id] = *nb;
    s->alive[id] = 1;
    s->alive_count++;
    if (s->alive_count * 2 > s->hcap) {
        if (!bset_rehash(s, s->hcap * 2))
            return -1;
    } else {
        size_t h = (size_t)(knot_hash(s, nb) & (s->hcap - 1));
        s->next[id] = s->head[h];
        s->head[h] = id;
    }
    return id;
}

static void bset_free(bset *s)
{
    free(s->b);
    free(s->alive);
    free(s->head);
    free(s->next);
    memset(s, 0, sizeof *s);
}

static box support_box(const bset *s, const sl_lr_basis *b)
{
    box q;
    for (int d = 0; d < 3; d++) {
        q.lo[d] = b->knots[d][0];
        q.hi[d] = b->knots[d][s->order[d]];
    }
    return q;
}

/* The first mesh plane (d, v) traversing b's support that is not a knot of
 * b; 0 when there is none. elems: the elements overlapping the support. */
static int find_split(const bset *s, const sl_lr_basis *b, const box *eb, const u32vec *elems,
                      double **cand, size_t *cand_cap, int *out_d, double *out_v)
{
    for (int d = 0; d < 3; d++) {
        const double *t = b->knots[d];
        int p = s->order[d];
        size_t nc = 0;
        for (size_t i = 0; i < elems->n; i++) {
            const box *e = &eb[elems->v[i]];
            for (int side = 0; side < 2; side++) {
                double x = side ? e->hi[d] : e->lo[d];
                if (!(x > t[0] && x < t[p]))
                    continue;
                int known = 0;
                for (int k = 1; k < p && !known; k++)
                    known = t[k] == x;
                for (size_t c = 0; c < nc && !known; c++)
                    known = (*cand)[c] == x;
                if (known)
                    continue;
                if (!grow((void **)cand, cand_cap, nc + 1, sizeof **cand))
                    return -1;
                (*cand)[nc++] = x;
            }
        }
        for (size_t c = 0; c < nc; c++) {
            double v = (*cand)[c];
            int traverses = 1;
            for (size_t i = 0; i < elems->n && traverses; i++) {
                const box *e = &eb[elems->v[i]];
                traverses = !(e->lo[d] < v && v < e->hi[d]);
            }
            if (traverses) {
                *out_d = d;
                *out_v = v;
                return 1;
            }
        }
    }
    return 0;
}

/* B = a1 B1 + a2 B2 after inserting v into the knots t[0..p] (t0 < v < tp). */
static void split_knots(const double *t, int p, double v, double *t1, double *t2, double *a1, double *a2)
{
    double tau[SL_LR_MAX_ORDER + 2];
    int m = 0, put = 0;
    for (int k = 0; k <= p; k++) {
        if (!put && v < t[k]) {
            tau[m++] = v;
            put = 1;
        }
        tau[m++] = t[k];
    }
    if (!put)
        tau[m++] = v;
    for (int k = 0; k <= p; k++) {
        t1[k] = tau[k];
        t2[k] = tau[k + 1];
    }
    *a1 = v >= t[p - 1] ? 1.0 : (v - t[0]) / (t[p - 1] - t[0]);
    *a2 = v <= t[1] ? 1.0 : (t[p] - v) / (t[p] - t[1]);
}

/* ---- mesh rectangles ----------------------------------------------------- */

static int flat_dir(const sl_lr_meshrect *m)
{
    for (int d = 0; d < 3; d++)
        if (m->lo[d] == m->hi[d])
            return d;
    return -1;
}

static int rect_cmp(const void *pa, const void *pb)
{
    const sl_lr_meshrect *a = pa, *b = pb;
    int da = flat_dir(a), db = flat_dir(b);
    if (da != db)
        return da < db ? -1 : 1;
    if (a->lo[da] != b->lo[db])
        return a->lo[da] < b->lo[db] ? -1 : 1;
    return 0;
}

/* Within one plane: drops rectangles contained in another of at least their
 * multiplicity and joins pairs of one multiplicity whose union is a
 * rectangle, until nothing changes. Returns the new count of the group. */
static int contains(const sl_lr_meshrect *a, const sl_lr_meshrect *b, int e1, int e2)
{
    return b->lo[e1] >= a->lo[e1] && b->hi[e1] <= a->hi[e1] && b->lo[e2] >= a->lo[e2] && b->hi[e2] <= a->hi[e2] &&
           b->multiplicity <= a->multiplicity;
}

/* Joins b into a when both have one multiplicity and their union is a
 * rectangle (same extent in one free direction, touching in the other). */
static int join(sl_lr_meshrect *a, const sl_lr_meshrect *b, int e1, int e2)
{
    if (a->multiplicity != b->multiplicity)
        return 0;
    for (int k = 0; k < 2; k++) {
        int same = k ? e2 : e1, along = k ? e1 : e2;
        if (a->lo[same] == b->lo[same] && a->hi[same] == b->hi[same] && a->lo[along] <= b->hi[along] &&
            b->lo[along] <= a->hi[along]) {
            a->lo[along] = fmin(a->lo[along], b->lo[along]);
            a->hi[along] = fmax(a->hi[along], b->hi[along]);
            return 1;
        }
    }
    return 0;
}

/* Within one plane: drops rectangles contained in another of at least their
 * multiplicity and joins pairs whose union is a rectangle, until nothing
 * changes. Returns the new count of the group. */
static size_t merge_plane(sl_lr_meshrect *r, size_t n, int d)
{
    int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
    int changed = 1;
    while (changed) {
        changed = 0;
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 1; j < n;) {
                if (contains(&r[i], &r[j], e1, e2)) {
                    r[j] = r[--n];
                    changed = 1;
                } else if (contains(&r[j], &r[i], e1, e2)) {
                    r[i] = r[j];
                    r[j] = r[--n];
                    changed = 1;
                    j = i + 1;
                } else if (join(&r[i], &r[j], e1, e2)) {
                    r[j] = r[--n];
                    changed = 1;
                    j = i + 1;
                } else {
                    j++;
                }
            }
    }
    return n;
}

static size_t merge_rects(sl_lr_meshrect *r, size_t n)
{
    if (n > 1)
        qsort(r, n, sizeof *r, rect_cmp);
    size_t out = 0;
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        while (j < n && rect_cmp(&r[i], &r[j]) == 0)
            j++;
        int d = flat_dir(&r[i]);
        size_t kept = merge_plane(r + i, j - i, d);
        memmove(r + out, r + i, kept * sizeof *r);
        out += kept;
        i = j;
    }
    return out;
}

/* ---- element cutting ------------------------------------------------------ */

typedef struct cut {
    uint32_t elem;
    int d;
    double v;
} cut;

static int cut_cmp(const void *pa, const void *pb)
{
    const cut *a = pa, *b = pb;
    if (a->elem != b->elem)
        return a->elem < b->elem ? -1 : 1;
    if (a->d != b->d)
        return a->d < b->d ? -1 : 1;
    return (a->v > b->v) - (a->v < b->v);
}

/* ---- the insertion --------------------------------------------------------- */

typedef struct work {
    box *el, *nel;
    size_t nel_n, nel_cap;
    cut *cuts;
    size_t cuts_n, cuts_cap;
    sl_lr_meshrect *rects;
    size_t rects_n, rects_cap;
    grid g;
    bset bs;
    u32vec q, queue;
    double *cand;
    size_t cand_cap;
    uint32_t *pairs; /* (element, basis) */
    size_t pairs_n, pairs_cap;
} work;

static void work_free(work *w)
{
    free(w->el);
    free(w->nel);
    free(w->cuts);
    free(w->rects);
    grid_free(&w->g);
    bset_free(&w->bs);
    free(w->q.v);
    free(w->queue.v);
    free(w->cand);
    free(w->pairs);
}

static sl_status nomem(sl_err *err)
{
    return sl_err_set(err, SL_ERR_NOMEM, "out of memory while refining the LR-spline");
}

static sl_status check_rect(const sl_lr_volume *lr, const sl_lr_meshrect *m, size_t i, sl_err *err)
{
    int flat = 0, d = -1;
    for (int k = 0; k < 3; k++) {
        if (!isfinite(m->lo[k]) || !isfinite(m->hi[k]) || m->lo[k] > m->hi[k] || m->lo[k] < lr->domain_lo[k] ||
            m->hi[k] > lr->domain_hi[k])
            return sl_err_set(err, SL_ERR_INVALID, "refinement rectangle %zu is not finite, reversed or"
                              " outside the domain", i);
        if (m->lo[k] == m->hi[k]) {
            flat++;
            d = k;
        }
    }
    if (flat != 1)
        return sl_err_set(err, SL_ERR_INVALID, "refinement rectangle %zu must be flat in exactly one"
                          " direction (it is in %d)", i, flat);
    if (!(m->lo[d] > lr->domain_lo[d] && m->lo[d] < lr->domain_hi[d]))
        return sl_err_set(err, SL_ERR_INVALID, "refinement rectangle %zu lies on the domain boundary", i);
    return SL_OK;
}

static sl_status refine(sl_lr_volume *lr, const sl_lr_meshrect *rects, size_t n, int check, sl_err *err)
{
    work w;
    memset(&w, 0, sizeof w);
    sl_status st = SL_OK;
    for (size_t i = 0; i < n; i++)
        if ((st = check_rect(lr, &rects[i], i, err)) != SL_OK)
            return st;
    size_t ne = lr->element_count;
    w.el = malloc(ne * sizeof *w.el);
    if (!w.el)
        goto oom;
    for (size_t i = 0; i < ne; i++)
        for (int d = 0; d < 3; d++) {
            w.el[i].lo[d] = lr->elements[i].lo[d];
            w.el[i].hi[d] = lr->elements[i].hi[d];
        }
    if (!grid_build(&w.g, w.el, ne, lr->domain_lo, lr->domain_hi))
        goto oom;
    if (!grow((void **)&w.rects, &w.rects_cap, lr->meshrect_count + n, sizeof *w.rects))
        goto oom;
    memcpy(w.rects, lr->meshrects, lr->meshrect_count * sizeof *w.rects);
    w.rects_n = lr->meshrect_count;

    /* 1. Extend each rectangle to the elements it crosses; record the cuts. */
    for (size_t i = 0; i < n; i++) {
        sl_lr_meshrect r = rects[i];
        r.multiplicity = 1;
        int d = flat_dir(&r);
        box q;
        int changed = 1;
        while (changed) {
            changed = 0;
            memcpy(q.lo, r.lo, sizeof q.lo);
            memcpy(q.hi, r.hi, sizeof q.hi);
            if (!grid_query(&w.g, w.el, &q, &w.q))
                goto oom;
            for (size_t k = 0; k < w.q.n; k++) {
                const box *e = &w.el[w.q.v[k]];
                for (int a = 0; a < 3; a++) {
                    if (a == d)
                        continue;
                    if (e->lo[a] < r.lo[a]) {
                        r.lo[a] = e->lo[a];
                        changed = 1;
                    }
                    if (e->hi[a] > r.hi[a]) {
                        r.hi[a] = e->hi[a];
                        changed = 1;
                    }
                }
            }
        }
        if (w.q.n == 0)
            continue; /* the plane is in the mesh already */
        if (!grow((void **)&w.cuts, &w.cuts_cap, w.cuts_n + w.q.n, sizeof *w.cuts))
            goto oom;
        for (size_t k = 0; k < w.q.n; k++)
            w.cuts[w.cuts_n++] = (cut){w.q.v[k], d, r.lo[d]};
        w.rects[w.rects_n++] = r;
    }

    /* 2. Split the cut elements into the tensor grids of their cuts. */
    if (w.cuts_n > 1)
        qsort(w.cuts, w.cuts_n, sizeof *w.cuts, cut_cmp);
    size_t ci = 0;
    for (size_t e = 0; e < ne; e++) {
        double vals[3][66];
        int nv[3];
        for (int d = 0; d < 3; d++) {
            vals[d][0] = w.el[e].lo[d];
            nv[d] = 1;
        }
        while (ci < w.cuts_n && w.cuts[ci].elem == e) {
            const cut *c = &w.cuts[ci++];
            if (c->v == vals[c->d][nv[c->d] - 1])
                continue;
            if (nv[c->d] == 64) {
                st = sl_err_set(err, SL_ERR_LIMIT, "element %zu would be cut by more than 63 planes in one"
                                " refinement step", e);
                goto out;
            }
            vals[c->d][nv[c->d]++] = c->v;
        }
        for (int d = 0; d < 3; d++)
            vals[d][nv[d]] = w.el[e].hi[d];
        size_t count = (size_t)nv[0] * nv[1] * nv[2];
        if (w.nel_n + count > SL_LR_MAX_ELEMENTS) {
            st = sl_err_set(err, SL_ERR_LIMIT, "refinement would exceed %u elements", SL_LR_MAX_ELEMENTS);
            goto out;
        }
        if (!grow((void **)&w.nel, &w.nel_cap, w.nel_n + count, sizeof *w.nel))
            goto oom;
        for (int k = 0; k < nv[2]; k++)
            for (int j = 0; j < nv[1]; j++)
                for (int i = 0; i < nv[0]; i++) {
                    box *b = &w.nel[w.nel_n++];
                    int idx[3] = {i, j, k};
                    for (int d = 0; d < 3; d++) {
                        b->lo[d] = vals[d][idx[d]];
                        b->hi[d] = vals[d][idx[d] + 1];
                    }
                }
    }
    grid_free(&w.g);
    if (!grid_build(&w.g, w.nel, w.nel_n, lr->domain_lo, lr->domain_hi))
        goto oom;

    /* 3. Split basis functions until no mesh plane traverses one. */
    memcpy(w.bs.order, lr->order, sizeof w.bs.order);
    w.bs.dim = lr->dim;
    size_t nb = lr->basis_count;
    if (!grow((void **)&w.bs.b, &w.bs.cap, nb, sizeof *w.bs.b) ||
        !grow((void **)&w.bs.alive, &w.bs.cap_alive, nb, 1) ||
        !grow((void **)&w.bs.next, &w.bs.cap_next, nb, sizeof *w.bs.next))
        goto oom;
    memcpy(w.bs.b, lr->basis, nb * sizeof *w.bs.b);
    memset(w.bs.alive, 1, nb);
    w.bs.n = nb;
    w.bs.alive_count = nb;
    size_t hcap = 64;
    while (hcap < 2 * nb + 2)
        hcap *= 2;
    if (!bset_rehash(&w.bs, hcap))
        goto oom;
    for (size_t i = nb; i > 0; i--)
        if (!u32_push(&w.queue, (uint32_t)(i - 1)))
            goto oom;
    while (w.queue.n > 0) {
        uint32_t id = w.queue.v[--w.queue.n];
        if (!w.bs.alive[id])
            continue;
        box s = support_box(&w.bs, &w.bs.b[id]);
        if (!grid_query(&w.g, w.nel, &s, &w.q))
            goto oom;
        int d;
        double v;
        int found = find_split(&w.bs, &w.bs.b[id], w.nel, &w.q, &w.cand, &w.cand_cap, &d, &v);
        if (found < 0)
            goto oom;
        if (!found)
            continue;
        sl_lr_basis b1 = w.bs.b[id], b2 = w.bs.b[id];
        double a1, a2;
        split_knots(w.bs.b[id].knots[d], lr->order[d], v, b1.knots[d], b2.knots[d], &a1, &a2);
        b1.gamma *= a1;
        b2.gamma *= a2;
        bset_unlink(&w.bs, id);
        long i1 = bset_add(&w.bs, &b1);
        long i2 = i1 >= 0 ? bset_add(&w.bs, &b2) : i1;
        if (i1 == -2 || i2 == -2) {
            st = sl_err_set(err, SL_ERR_LIMIT, "refinement would exceed %u basis functions", SL_LR_MAX_BASIS);
            goto out;
        }
        if (i1 < 0 || i2 < 0 || !u32_push(&w.queue, (uint32_t)i1) || !u32_push(&w.queue, (uint32_t)i2))
            goto oom;
    }

    /* 4. Element basis lists: every element inside each support. */
    size_t alive = w.bs.alive_count;
    uint32_t *newid = malloc((w.bs.n ? w.bs.n : 1) * sizeof *newid);
    if (!newid)
        goto oom;
    {
        uint32_t k = 0;
        for (size_t i = 0; i < w.bs.n; i++)
            newid[i] = w.bs.alive[i] ? k++ : UINT32_MAX;
    }
    for (size_t i = 0; i < w.bs.n; i++) {
        if (!w.bs.alive[i])
            continue;
        box s = support_box(&w.bs, &w.bs.b[i]);
        if (!grid_query(&w.g, w.nel, &s, &w.q)) {
            free(newid);
            goto oom;
        }
        if (w.pairs_n + 2 * w.q.n > 2 * (size_t)SL_LR_MAX_ELEMENT_BASIS) {
            free(newid);
            st = sl_err_set(err, SL_ERR_LIMIT, "refinement would exceed %u element-basis entries",
                            SL_LR_MAX_ELEMENT_BASIS);
            goto out;
        }
        if (!grow((void **)&w.pairs, &w.pairs_cap, w.pairs_n + 2 * w.q.n, sizeof *w.pairs)) {
            free(newid);
            goto oom;
        }
        for (size_t k = 0; k < w.q.n; k++) {
            w.pairs[w.pairs_n++] = w.q.v[k];
            w.pairs[w.pairs_n++] = newid[i];
        }
    }
    size_t rect_count = merge_rects(w.rects, w.rects_n);
    sl_lr_volume out;
    st = sl_lr_alloc(&out, alive, rect_count, w.nel_n, w.pairs_n / 2, err);
    if (st != SL_OK) {
        free(newid);
        goto out;
    }
    memcpy(out.order, lr->order, sizeof out.order);
    out.dim = lr->dim;
    for (size_t i = 0; i < w.bs.n; i++)
        if (w.bs.alive[i])
            out.basis[newid[i]] = w.bs.b[i];
    free(newid);
    memcpy(out.meshrects, w.rects, rect_count * sizeof *w.rects);
    for (size_t p = 0; p < w.pairs_n; p += 2)
        out.elements[w.pairs[p]].basis_count++;
    uint32_t off = 0;
    for (size_t e = 0; e < w.nel_n; e++) {
        sl_lr_element *x = &out.elements[e];
        memcpy(x->lo, w.nel[e].lo, sizeof x->lo);
        memcpy(x->hi, w.nel[e].hi, sizeof x->hi);
        x->basis_offset = off;
        off += x->basis_count;
        x->basis_count = 0;
    }
    for (size_t p = 0; p < w.pairs_n; p += 2) {
        sl_lr_element *x = &out.elements[w.pairs[p]];
        out.element_basis[x->basis_offset + x->basis_count++] = w.pairs[p + 1];
    }
    if (check) {
        st = sl_lr_finish(&out, err);
        if (st != SL_OK) {
            sl_err_prefix(err, "after refinement: ");
            sl_lr_free(&out);
            goto out;
        }
    } else {
        /* The geometry sl_lr_finish would derive; the value range stays stale. */
        memcpy(out.domain_lo, lr->domain_lo, sizeof out.domain_lo);
        memcpy(out.domain_hi, lr->domain_hi, sizeof out.domain_hi);
        out.value_min = lr->value_min;
        out.value_max = lr->value_max;
        for (int d = 0; d < 3; d++) {
            out.min_side[d] = INFINITY;
            out.max_side[d] = 0.0;
            for (size_t e = 0; e < out.element_count; e++) {
                double side = out.elements[e].hi[d] - out.elements[e].lo[d];
                out.min_side[d] = fmin(out.min_side[d], side);
                out.max_side[d] = fmax(out.max_side[d], side);
            }
        }
    }
    sl_lr_free(lr);
    *lr = out;
    goto out;
oom:
    st = nomem(err);
out:
    work_free(&w);
    return st;
}

sl_status sl_lr_refine(sl_lr_volume *lr, const sl_lr_meshrect *rects, size_t n, sl_err *err)
{
    return refine(lr, rects, n, 1, err);
}

/* Appends to r the rectangle flat in d at v spanning b's support in the
 * other two directions (multiplicity 1); 0 when out of memory. */
static int push_support_rect(sl_lr_meshrect **r, size_t *cap, size_t *count, const sl_lr_volume *lr,
                             const sl_lr_basis *b, int d, double v)
{
    if (!grow((void **)r, cap, *count + 1, sizeof **r))
        return 0;
    sl_lr_meshrect *m = &(*r)[(*count)++];
    for (int e = 0; e < 3; e++) {
        m->lo[e] = b->knots[e][0];
        m->hi[e] = b->knots[e][lr->order[e]];
    }
    m->lo[d] = m->hi[d] = v;
    m->multiplicity = 1;
    return 1;
}

/* The basis function on element x with the smallest support in the two
 * directions other than d (the first one on a tie). */
static const sl_lr_basis *smallest_across(const sl_lr_volume *lr, const sl_lr_element *x, int d)
{
    const sl_lr_basis *best = NULL;
    double best_area = 0.0;
    int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
    for (uint32_t k = 0; k < x->basis_count; k++) {
        const sl_lr_basis *b = &lr->basis[lr->element_basis[x->basis_offset + k]];
        double area = (b->knots[d1][lr->order[d1]] - b->knots[d1][0]) * (b->knots[d2][lr->order[d2]] - b->knots[d2][0]);
        if (!best || area < best_area) {
            best = b;
            best_area = area;
        }
    }
    return best;
}

sl_status sl_lr_refine_elements(sl_lr_volume *lr, const uint32_t *elements, size_t n, const double min_span[3],
                                int check, size_t *inserted, sl_err *err)
{
    sl_lr_meshrect *r = NULL;
    size_t count = 0, cap = 0;
    for (size_t i = 0; i < n; i++) {
        if (elements[i] >= lr->element_count)
            return free(r), sl_err_set(err, SL_ERR_INVALID, "element id %u out of range (%zu elements)",
                                       elements[i], lr->element_count);
        const sl_lr_element *x = &lr->elements[elements[i]];
        for (int d = 0; d < 3; d++) {
            if (min_span && x->hi[d] - x->lo[d] < 2.0 * min_span[d] * (1.0 - 1e-9))
                continue;
            const sl_lr_basis *b = smallest_across(lr, x, d);
            if (!b)
                continue;
            if (!push_support_rect(&r, &cap, &count, lr, b, d, 0.5 * (x->lo[d] + x->hi[d])))
                return free(r), nomem(err);
        }
    }
    sl_status st = count ? refine(lr, r, count, check, err) : SL_OK;
    free(r);
    if (inserted)
        *inserted = st == SL_OK ? count : 0;
    return st;
}

sl_status sl_lr_refine_basis(sl_lr_volume *lr, const uint32_t *ids, size_t n, const double min_span[3], int check,
                             size_t *inserted, sl_err *err)
{
    sl_lr_meshrect *r = NULL;
    size_t count = 0, cap = 0;
    for (size_t i = 0; i < n; i++) {
        if (ids[i] >= lr->basis_count)
            return free(r), sl_err_set(err, SL_ERR_INVALID, "basis id %u out of range (%zu basis functions)",
                                       ids[i], lr->basis_count);
        const sl_lr_basis *b = &lr->basis[ids[i]];
        for (int d = 0; d < 3; d++)
            for (int k = 0; k < lr->order[d]; k++) {
                double a = b->knots[d][k], z = b->knots[d][k + 1];
                if (!(z > a) || (min_span && z - a < 2.0 * min_span[d] * (1.0 - 1e-9)))
                    continue;
                if (!push_support_rect(&r, &cap, &count, lr, b, d, 0.5 * (a + z)))
                    return free(r), nomem(err);
            }
    }
    sl_status st = count ? refine(lr, r, count, check, err) : SL_OK;
    free(r);
    if (inserted)
        *inserted = st == SL_OK ? count : 0;
    return st;
}
