/* lr_lookup_octree.c — the octree of sl_lr_lookup.h (paper 003, 3.2.2).
 *
 * Every knot must be domain_lo + k * side / 2^i, i <= SL_LR_OCTREE_MAX_LEVEL
 * (within 1e-12 * side; the knot value itself becomes the split plane, so
 * queries are exact). Knots become integers K on the finest grid of
 * 2^SL_LR_OCTREE_MAX_LEVEL cells per direction; the tree is built on those
 * integers: a cell met by more than one element is split into 8 at its
 * middle (the middle plane is the knot there, else the dyadic value). A
 * fine knot plane across big elements splits every cell along it, so the
 * split cells are capped (SL_ERR_LIMIT past the cap).
 * Any thread; no GL.
 */
#include "lr_lookup_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEVEL SL_LR_OCTREE_MAX_LEVEL

typedef struct oct_builder {
    const sl_lr_volume *lr;
    uint32_t (*klo)[3], (*khi)[3];       /* per element, fine-grid integers */
    double *values[3];                   /* distinct knots per direction */
    uint32_t *keys[3];                   /* their K */
    size_t count[3];
    double lo[3], side[3];
    sl_lr_octnode *nodes;
    size_t n, cap, max_cells;
    int max_depth, failed;
} oct_builder;

static long key_index(const uint32_t *keys, size_t n, uint32_t k)
{
    size_t a = 0, z = n;
    while (a < z) {
        size_t m = (a + z) / 2;
        if (keys[m] < k)
            a = m + 1;
        else
            z = m;
    }
    return a < n && keys[a] == k ? (long)a : -1;
}

static long value_index(const double *v, size_t n, double x)
{
    size_t a = 0, z = n;
    while (a < z) {
        size_t m = (a + z) / 2;
        if (v[m] < x)
            a = m + 1;
        else
            z = m;
    }
    return (long)a;
}

static uint32_t oct_build(oct_builder *b, const uint32_t c0[3], uint32_t size, const uint32_t *elems, size_t count,
                          int depth)
{
    if (depth > b->max_depth)
        b->max_depth = depth;
    if (count <= 1)
        return SL_LR_REF_LEAF | (count ? elems[0] : SL_LR_REF_NONE);
    if (size < 2 || b->failed) {
        b->failed = b->failed ? b->failed : 2;
        return SL_LR_REF_LEAF | SL_LR_REF_NONE;
    }
    if (b->n >= b->max_cells) {
        b->failed = 3;
        return SL_LR_REF_LEAF | SL_LR_REF_NONE;
    }
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 256;
        sl_lr_octnode *nn = realloc(b->nodes, cap * sizeof *nn);
        if (!nn) {
            b->failed = 1;
            return SL_LR_REF_LEAF | SL_LR_REF_NONE;
        }
        b->nodes = nn;
        b->cap = cap;
    }
    size_t at = b->n++;
    uint32_t half = size / 2, mid[3];
    for (int d = 0; d < 3; d++) {
        mid[d] = c0[d] + half;
        long i = key_index(b->keys[d], b->count[d], mid[d]);
        b->nodes[at].mid[d] = i >= 0 ? b->values[d][i] : b->lo[d] + b->side[d] * ldexp((double)mid[d], -LEVEL);
    }
    uint32_t *sub = malloc(count * sizeof *sub);
    if (!sub) {
        b->failed = 1;
        return SL_LR_REF_LEAF | SL_LR_REF_NONE;
    }
    for (int c = 0; c < 8; c++) {
        uint32_t a[3], z[3];
        for (int d = 0; d < 3; d++) {
            a[d] = (c >> d & 1) ? mid[d] : c0[d];
            z[d] = a[d] + half;
        }
        size_t m = 0;
        for (size_t i = 0; i < count; i++) {
            uint32_t e = elems[i];
            if (b->klo[e][0] < z[0] && b->khi[e][0] > a[0] && b->klo[e][1] < z[1] && b->khi[e][1] > a[1] &&
                b->klo[e][2] < z[2] && b->khi[e][2] > a[2])
                sub[m++] = e;
        }
        uint32_t ref = oct_build(b, a, half, sub, m, depth + 1);
        b->nodes[at].child[c] = ref;
    }
    free(sub);
    return (uint32_t)at;
}

sl_status sl_lr_lookup_build_octree(sl_lr_lookup *lk, const sl_lr_volume *lr, size_t max_cells, sl_err *err)
{
    static const char axis[3] = {'x', 'y', 'z'};
    lk->kind = SL_LR_LOOKUP_OCTREE;
    oct_builder b = {.lr = lr, .max_cells = max_cells};
    sl_status st = SL_OK;
    uint32_t *all = NULL;
    b.klo = malloc(lr->element_count * sizeof *b.klo);
    b.khi = malloc(lr->element_count * sizeof *b.khi);
    if (!b.klo || !b.khi) {
        st = sl_err_set(err, SL_ERR_NOMEM, "octree: out of memory");
        goto done;
    }
    for (int d = 0; d < 3 && st == SL_OK; d++) {
        b.lo[d] = lk->lo[d];
        b.side[d] = lk->hi[d] - lk->lo[d];
        b.values[d] = sl_lr_lookup_distinct_faces(lr, d, &b.count[d]);
        b.keys[d] = b.values[d] ? malloc(b.count[d] * sizeof *b.keys[d]) : NULL;
        if (!b.keys[d]) {
            st = sl_err_set(err, SL_ERR_NOMEM, "octree: out of memory");
            break;
        }
        for (size_t i = 0; i < b.count[d]; i++) {
            double x = b.values[d][i], t = (x - b.lo[d]) / b.side[d];
            double k = nearbyint(ldexp(t, LEVEL));
            if (!(fabs(b.lo[d] + b.side[d] * ldexp(k, -LEVEL) - x) <= 1e-12 * b.side[d])) {
                /* Name the first element with this knot. */
                size_t e = 0;
                while (e < lr->element_count && lr->elements[e].lo[d] != x && lr->elements[e].hi[d] != x)
                    e++;
                st = sl_err_set(err, SL_ERR_UNSUPPORTED, "octree: knot %.17g in %c (element %zu) is not domain_lo + "
                                "k * side / 2^i for any i <= %d (not dyadic); use texture, kdtree or kdforest",
                                x, axis[d], e, LEVEL);
                break;
            }
            b.keys[d][i] = (uint32_t)k;
            if (i > 0 && b.keys[d][i] == b.keys[d][i - 1]) {
                st = sl_err_set(err, SL_ERR_UNSUPPORTED, "octree: knots %.17g and %.17g in %c are closer than the "
                                "finest octree level 2^-%d", b.values[d][i - 1], x, axis[d], LEVEL);
                break;
            }
        }
    }
    if (st != SL_OK)
        goto done;
    for (size_t e = 0; e < lr->element_count; e++)
        for (int d = 0; d < 3; d++) {
            b.klo[e][d] = b.keys[d][value_index(b.values[d], b.count[d], lr->elements[e].lo[d])];
            b.khi[e][d] = b.keys[d][value_index(b.values[d], b.count[d], lr->elements[e].hi[d])];
        }
    all = malloc(lr->element_count * sizeof *all);
    if (!all) {
        st = sl_err_set(err, SL_ERR_NOMEM, "octree: out of memory");
        goto done;
    }
    for (size_t e = 0; e < lr->element_count; e++)
        all[e] = (uint32_t)e;
    uint32_t origin[3] = {0, 0, 0};
    lk->oct_root = oct_build(&b, origin, 1u << LEVEL, all, lr->element_count, 0);
    lk->oct = b.nodes;
    lk->oct_count = b.n;
    b.nodes = NULL;
    if (b.failed) {
        st = b.failed == 1   ? sl_err_set(err, SL_ERR_NOMEM, "octree: out of memory for the cells")
             : b.failed == 3 ? sl_err_set(err, SL_ERR_LIMIT, "octree: more than %zu split cells would be needed "
                                          "(element faces on fine dyadic planes across large elements); use kdforest",
                                          max_cells)
                             : sl_err_set(err, SL_ERR_INVALID, "octree: elements overlap at the finest level");
        goto done;
    }
    int depth = b.max_depth;
    sl_lr_lookup_depth_stats(&lk->stats, &depth, 1);
    lk->stats.nodes = b.n;
done:
    free(all);
    free(b.klo);
    free(b.khi);
    free(b.nodes);
    for (int d = 0; d < 3; d++) {
        free(b.values[d]);
        free(b.keys[d]);
    }
    return st;
}
