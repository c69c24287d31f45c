/* lr_lookup.c — choosing and querying an element look-up structure (see
 * sl_lr_lookup.h): kind names, the build dispatch and the `auto` rule, the
 * CPU queries of all four kinds. The builders live in lr_lookup_texture.c,
 * lr_lookup_octree.c and lr_lookup_kdtree.c; what they share, in lr_lookup_shared.c.
 * Any thread; no GL; a built structure is read-only.
 */
#include "lr_lookup_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char *const kind_names[] = {"auto", "texture", "octree", "kdtree", "kdforest"};

sl_status sl_lr_lookup_kind_parse(const char *name, sl_lr_lookup_kind *kind, sl_err *err)
{
    for (int k = 0; k < 5; k++)
        if (name && strcmp(name, kind_names[k]) == 0) {
            *kind = (sl_lr_lookup_kind)k;
            return SL_OK;
        }
    return sl_err_set(err, SL_ERR_INVALID, "lookup \"%s\" is not one of auto, texture, octree, kdtree, kdforest",
                      name ? name : "(null)");
}

const char *sl_lr_lookup_kind_name(sl_lr_lookup_kind kind)
{
    return (unsigned)kind < 5 ? kind_names[kind] : "?";
}

int sl_lr_lookup_cell(const double *planes, int n, double lo, double hi, double p)
{
    int c = (int)((p - lo) / (hi - lo) * n);
    if (c < 0)
        c = 0;
    if (c > n - 1)
        c = n - 1;
    while (c > 0 && p < planes[c])
        c--;
    while (c < n - 1 && p >= planes[c + 1])
        c++;
    return c;
}

void sl_lr_lookup_deinit(sl_lr_lookup *lk)
{
    for (int d = 0; d < 3; d++)
        free(lk->planes[d]);
    free(lk->heads);
    free(lk->nodes);
    free(lk->oct);
    memset(lk, 0, sizeof *lk);
}

sl_status sl_lr_lookup_init(sl_lr_lookup *lk, const sl_lr_volume *lr, sl_lr_lookup_kind kind,
                            int forest_axis, sl_err *err)
{
    memset(lk, 0, sizeof *lk);
    if (!lr || lr->element_count == 0)
        return sl_err_set(err, SL_ERR_INVALID, "element look-up: the volume has no elements");
    if (lr->element_count >= SL_LR_REF_NONE || lr->element_count > SL_LR_MAX_ELEMENTS)
        return sl_err_set(err, SL_ERR_LIMIT, "element look-up: %zu elements exceed the limit %u",
                          lr->element_count, SL_LR_MAX_ELEMENTS);
    for (int d = 0; d < 3; d++) {
        if (!(lr->domain_lo[d] < lr->domain_hi[d]))
            return sl_err_set(err, SL_ERR_INVALID, "element look-up: the domain is empty in direction %d "
                              "(was the volume finished?)", d);
        lk->lo[d] = lr->domain_lo[d];
        lk->hi[d] = lr->domain_hi[d];
    }
    struct timespec t0, t1;
    timespec_get(&t0, TIME_UTC);
    sl_status st;
    switch (kind) {
    case SL_LR_LOOKUP_TEXTURE:
        st = sl_lr_lookup_build_texture(lk, lr, err);
        break;
    case SL_LR_LOOKUP_OCTREE:
        st = sl_lr_lookup_build_octree(lk, lr, SL_LR_OCTREE_MAX_CELLS, err);
        break;
    case SL_LR_LOOKUP_KDTREE:
        st = sl_lr_lookup_build_forest(lk, lr, 1, err);
        lk->kind = SL_LR_LOOKUP_KDTREE;
        break;
    case SL_LR_LOOKUP_KDFOREST:
        st = sl_lr_lookup_build_forest(lk, lr, forest_axis ? forest_axis : SL_LR_FOREST_DEFAULT_AXIS, err);
        break;
    case SL_LR_LOOKUP_AUTO: {
        /* The rule of sl_lr_lookup.h (measured by bench-lr-lookup): the
         * texture where it applies, else the default k-d forest. */
        sl_err quiet;
        st = sl_lr_lookup_build_texture(lk, lr, &quiet);
        if (st == SL_ERR_UNSUPPORTED) {
            sl_lr_lookup_deinit(lk);
            for (int d = 0; d < 3; d++) {
                lk->lo[d] = lr->domain_lo[d];
                lk->hi[d] = lr->domain_hi[d];
            }
            st = sl_lr_lookup_build_forest(lk, lr, SL_LR_FOREST_DEFAULT_AXIS, &quiet);
        }
        if (st != SL_OK)
            *err = quiet;
        break;
    }
    default:
        return sl_err_set(err, SL_ERR_INVALID, "element look-up: unknown kind %d", (int)kind);
    }
    if (st != SL_OK) {
        sl_lr_lookup_deinit(lk);
        return st;
    }
    timespec_get(&t1, TIME_UTC);
    lk->stats.build_ms = (double)(t1.tv_sec - t0.tv_sec) * 1e3 + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-6;
    lk->stats.bytes = lk->node_count * sizeof *lk->nodes + lk->oct_count * sizeof *lk->oct;
    if (lk->heads)
        lk->stats.bytes += (size_t)lk->n[0] * (size_t)lk->n[1] * (size_t)lk->n[2] * sizeof *lk->heads;
    for (int d = 0; d < 3; d++)
        if (lk->planes[d])
            lk->stats.bytes += (size_t)(lk->n[d] + 1) * sizeof(double);
    return SL_OK;
}

static long ref_element(uint32_t ref)
{
    uint32_t e = ref & ~SL_LR_REF_LEAF;
    return e == SL_LR_REF_NONE ? -1 : (long)e;
}

long sl_lr_lookup_find(const sl_lr_lookup *lk, const double p[3])
{
    for (int d = 0; d < 3; d++)
        if (!(p[d] >= lk->lo[d] && p[d] <= lk->hi[d]))
            return -1; /* outside, or NaN */
    if (lk->kind == SL_LR_LOOKUP_OCTREE) {
        uint32_t ref = lk->oct_root;
        while (!(ref & SL_LR_REF_LEAF)) {
            const sl_lr_octnode *o = &lk->oct[ref];
            int c = (p[0] >= o->mid[0]) | (p[1] >= o->mid[1]) << 1 | (p[2] >= o->mid[2]) << 2;
            ref = o->child[c];
        }
        return ref_element(ref);
    }
    int c[3];
    for (int d = 0; d < 3; d++)
        c[d] = sl_lr_lookup_cell(lk->planes[d], lk->n[d], lk->lo[d], lk->hi[d], p[d]);
    uint32_t head = lk->heads[(size_t)c[0] + (size_t)lk->n[0] * ((size_t)c[1] + (size_t)lk->n[1] * (size_t)c[2])];
    if (lk->kind == SL_LR_LOOKUP_TEXTURE)
        return (long)head;
    if (head & SL_LR_REF_LEAF)
        return ref_element(head);
    const sl_lr_kdnode *nd = &lk->nodes[head];
    while (nd->axis != 3)
        nd = p[nd->axis] < nd->split ? &lk->nodes[nd->index] : nd + 1;
    return nd->index == UINT32_MAX ? -1 : (long)nd->index;
}
