/* lr_lookup_kdtree.c — depth-balanced k-d trees and the k-d forest (paper
 * 003, section 3.2.1) of sl_lr_lookup.h; kdtree is the forest of one block.
 *
 * Blocks: the domain cut into n[d] slabs per direction at planes that are
 * float values (lo + side * j / n rounded to float; the ends are the domain
 * itself), so the GPU finds a block exactly. A block's tree holds the
 * elements whose open box meets the block's box; the one element meeting a
 * cell is the one the element rule gives for every point of that cell
 * (elements tile the domain), so leaves answer exactly.
 * Split rule: per direction the median of the element faces strictly inside
 * the node's cell; keep the plane whose larger side has fewest elements
 * (ties: fewer cut elements, then the lower direction). Each split removes
 * its face from the inside of both children, so the recursion ends.
 * Layout (Algorithm 1): right child right after its parent, left child at
 * the parent's index. Any thread; no GL.
 */
#include "lr_lookup_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct kd_builder {
    const sl_lr_volume *lr;
    sl_lr_kdnode *nodes;
    size_t count, capacity;
    double *faces;        /* scratch, 2 * element_count */
    int failed;
} kd_builder;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static size_t kd_alloc(kd_builder *b)
{
    if (b->count == b->capacity) {
        size_t cap = b->capacity ? 2 * b->capacity : 1024;
        sl_lr_kdnode *n = cap < (size_t)SL_LR_REF_NONE ? realloc(b->nodes, cap * sizeof *n) : NULL;
        if (!n) {
            b->failed = 1;
            return SIZE_MAX;
        }
        b->nodes = n;
        b->capacity = cap;
    }
    return b->count++;
}

/* Builds the subtree of `elems` (count >= 1) in the cell [lo, hi]; returns
 * the depth of the subtree (-1 on failure). The node goes to index `at`. */
static int kd_build(kd_builder *b, size_t at, uint32_t *elems, size_t count, const double lo[3], const double hi[3])
{
    if (count == 1) {
        b->nodes[at] = (sl_lr_kdnode){.split = 0.0, .index = elems[0], .axis = 3};
        return 0;
    }
    const sl_lr_element *el = b->lr->elements;
    int best_axis = -1;
    double best_split = 0.0;
    size_t best_max = SIZE_MAX, best_cut = SIZE_MAX;
    for (int d = 0; d < 3; d++) {
        size_t m = 0;
        for (size_t i = 0; i < count; i++) {
            double f0 = el[elems[i]].lo[d], f1 = el[elems[i]].hi[d];
            if (f0 > lo[d] && f0 < hi[d])
                b->faces[m++] = f0;
            if (f1 > lo[d] && f1 < hi[d])
                b->faces[m++] = f1;
        }
        if (m == 0)
            continue;
        qsort(b->faces, m, sizeof *b->faces, cmp_double);
        double s = b->faces[m / 2];
        size_t left = 0, right = 0;
        for (size_t i = 0; i < count; i++) {
            left += el[elems[i]].lo[d] < s;
            right += el[elems[i]].hi[d] > s;
        }
        size_t mx = left > right ? left : right, cut = left + right - count;
        if (mx < best_max || (mx == best_max && cut < best_cut)) {
            best_axis = d;
            best_split = s;
            best_max = mx;
            best_cut = cut;
        }
    }
    if (best_axis < 0) {
        b->failed = 2; /* two elements meet one cell with no face inside: overlap */
        return -1;
    }
    int d = best_axis;
    uint32_t *right = malloc(count * sizeof *right), *left = malloc(count * sizeof *left);
    if (!right || !left) {
        free(right);
        free(left);
        b->failed = 1;
        return -1;
    }
    size_t nl = 0, nr = 0;
    for (size_t i = 0; i < count; i++) {
        if (el[elems[i]].lo[d] < best_split)
            left[nl++] = elems[i];
        if (el[elems[i]].hi[d] > best_split)
            right[nr++] = elems[i];
    }
    double clo[3], chi[3];
    memcpy(clo, lo, sizeof clo);
    memcpy(chi, hi, sizeof chi);
    b->nodes[at] = (sl_lr_kdnode){.split = best_split, .index = 0, .axis = (uint32_t)d};
    int depth = -1;
    size_t r = kd_alloc(b);
    if (r != SIZE_MAX) {
        clo[d] = best_split;
        int dr = kd_build(b, r, right, nr, clo, hi);
        size_t l = dr >= 0 ? kd_alloc(b) : SIZE_MAX;
        if (l != SIZE_MAX) {
            b->nodes[at].index = (uint32_t)l;
            chi[d] = best_split;
            int dl = kd_build(b, l, left, nl, lo, chi);
            if (dl >= 0)
                depth = 1 + (dl > dr ? dl : dr);
        }
    }
    free(right);
    free(left);
    return depth;
}

static int first_block(const double *planes, int n, double v) /* last c with planes[c] <= v */
{
    int a = 0, z = n - 1;
    while (a < z) {
        int m = (a + z + 1) / 2;
        if (planes[m] <= v)
            a = m;
        else
            z = m - 1;
    }
    return a;
}

static int last_block(const double *planes, int n, double v) /* last c with planes[c] < v */
{
    int a = 0, z = n - 1;
    while (a < z) {
        int m = (a + z + 1) / 2;
        if (planes[m] < v)
            a = m;
        else
            z = m - 1;
    }
    return a;
}

sl_status sl_lr_lookup_build_forest(sl_lr_lookup *lk, const sl_lr_volume *lr, int axis_blocks, sl_err *err)
{
    if (axis_blocks < 1 || axis_blocks > 128)
        return sl_err_set(err, SL_ERR_INVALID, "kdforest: %d blocks per direction is outside 1..128", axis_blocks);
    lk->kind = SL_LR_LOOKUP_KDFOREST;
    for (int d = 0; d < 3; d++) {
        int n = axis_blocks;
        lk->n[d] = n;
        lk->planes[d] = malloc((size_t)(n + 1) * sizeof(double));
        if (!lk->planes[d])
            return sl_err_set(err, SL_ERR_NOMEM, "kdforest: out of memory for the block planes");
        lk->planes[d][0] = lk->lo[d];
        lk->planes[d][n] = lk->hi[d];
        for (int j = 1; j < n; j++) {
            double v = (double)(float)(lk->lo[d] + (lk->hi[d] - lk->lo[d]) * j / n);
            if (!(v > lk->planes[d][j - 1] && v < lk->hi[d]))
                return sl_err_set(err, SL_ERR_UNSUPPORTED, "kdforest: the domain [%g, %g] of direction %d is too "
                                  "narrow for %d blocks at float precision", lk->lo[d], lk->hi[d], d, n);
            lk->planes[d][j] = v;
        }
    }
    size_t blocks = (size_t)lk->n[0] * (size_t)lk->n[1] * (size_t)lk->n[2];
    size_t *start = calloc(blocks + 1, sizeof *start);
    lk->heads = malloc(blocks * sizeof *lk->heads);
    int *depth = malloc(blocks * sizeof *depth);
    if (!start || !lk->heads || !depth) {
        free(start);
        free(depth);
        return sl_err_set(err, SL_ERR_NOMEM, "kdforest: out of memory for %zu blocks", blocks);
    }
    /* Two passes over the elements: count per block, then fill. */
    uint32_t *list = NULL;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t e = 0; e < lr->element_count; e++) {
            const sl_lr_element *el = &lr->elements[e];
            int c0[3], c1[3];
            for (int d = 0; d < 3; d++) {
                c0[d] = first_block(lk->planes[d], lk->n[d], el->lo[d]);
                c1[d] = last_block(lk->planes[d], lk->n[d], el->hi[d]);
            }
            for (int k = c0[2]; k <= c1[2]; k++)
                for (int j = c0[1]; j <= c1[1]; j++)
                    for (int i = c0[0]; i <= c1[0]; i++) {
                        size_t bl = (size_t)i + (size_t)lk->n[0] * ((size_t)j + (size_t)lk->n[1] * (size_t)k);
                        if (pass == 0)
                            start[bl + 1]++;
                        else
                            list[start[bl]++] = (uint32_t)e;
                    }
        }
        if (pass == 0) {
            for (size_t bl = 0; bl < blocks; bl++)
                start[bl + 1] += start[bl];
            if (start[blocks] > (size_t)64 * 1024 * 1024) {
                size_t pairs = start[blocks];
                free(start);
                free(depth);
                return sl_err_set(err, SL_ERR_LIMIT, "kdforest: %zu element-block pairs for %zu blocks exceed "
                                  "the limit of 64 Mi; use fewer blocks", pairs, blocks);
            }
            list = malloc((start[blocks] + 1) * sizeof *list);
            if (!list) {
                free(start);
                free(depth);
                return sl_err_set(err, SL_ERR_NOMEM, "kdforest: out of memory for the block lists");
            }
        }
    }
    /* start[bl] is now the end of block bl; its begin is start[bl - 1]. */
    kd_builder b = {.lr = lr};
    b.faces = malloc(2 * lr->element_count * sizeof *b.faces + sizeof *b.faces);
    if (!b.faces)
        b.failed = 1;
    size_t direct = 0;
    for (size_t bl = 0; bl < blocks && !b.failed; bl++) {
        size_t begin = bl ? start[bl - 1] : 0, count = start[bl] - begin;
        depth[bl] = 0;
        if (count <= 1) {
            lk->heads[bl] = SL_LR_REF_LEAF | (count ? list[begin] : SL_LR_REF_NONE);
            direct += count;
            continue;
        }
        int i = (int)(bl % (size_t)lk->n[0]), j = (int)(bl / (size_t)lk->n[0] % (size_t)lk->n[1]);
        int k = (int)(bl / ((size_t)lk->n[0] * (size_t)lk->n[1]));
        double lo[3] = {lk->planes[0][i], lk->planes[1][j], lk->planes[2][k]};
        double hi[3] = {lk->planes[0][i + 1], lk->planes[1][j + 1], lk->planes[2][k + 1]};
        size_t root = kd_alloc(&b);
        if (root == SIZE_MAX)
            break;
        lk->heads[bl] = (uint32_t)root;
        depth[bl] = kd_build(&b, root, list + begin, count, lo, hi);
    }
    free(b.faces);
    free(start);
    free(list);
    lk->nodes = b.nodes;
    lk->node_count = b.count;
    if (b.failed) {
        free(depth);
        if (b.failed == 2)
            return sl_err_set(err, SL_ERR_INVALID, "kdforest: two elements overlap (no element face separates them)");
        return sl_err_set(err, SL_ERR_NOMEM, "kdforest: out of memory for the k-d nodes");
    }
    sl_lr_lookup_depth_stats(&lk->stats, depth, blocks);
    lk->stats.nodes = b.count;
    lk->stats.direct_blocks = direct;
    free(depth);
    return SL_OK;
}
