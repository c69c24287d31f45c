/* lr_lookup_texture.c — the regular look-up texture of sl_lr_lookup.h: when
 * every knot of direction d lies on lo + k * side / n[d] (within 1e-9 of a
 * cell, the knot itself then being the plane, so queries stay exact), one
 * element index per cell. n[d] is the smallest such count up to
 * SL_LR_TEXTURE_MAX_AXIS; the cells in all at most SL_LR_TEXTURE_MAX_CELLS.
 * Any thread; no GL.
 */
#include "lr_lookup_internal.h"

#include <math.h>
#include <stdlib.h>

/* The smallest n with every value on the grid, 0 if none up to the limit. */
static int grid_count(const double *v, size_t m, double lo, double side, double *bad)
{
    for (int n = 1; n <= (int)SL_LR_TEXTURE_MAX_AXIS; n++) {
        int ok = 1;
        long last = -1;
        for (size_t i = 0; i < m && ok; i++) {
            double t = (v[i] - lo) / side * n;
            long k = lround(t);
            if (fabs(t - (double)k) > 1e-9 || k <= last) {
                ok = 0;
                *bad = v[i];
            }
            last = k;
        }
        if (ok)
            return n;
    }
    return 0;
}

sl_status sl_lr_lookup_build_texture(sl_lr_lookup *lk, const sl_lr_volume *lr, sl_err *err)
{
    static const char axis[3] = {'x', 'y', 'z'};
    lk->kind = SL_LR_LOOKUP_TEXTURE;
    size_t cells = 1;
    for (int d = 0; d < 3; d++) {
        size_t m;
        double *v = sl_lr_lookup_distinct_faces(lr, d, &m);
        if (!v)
            return sl_err_set(err, SL_ERR_NOMEM, "texture: out of memory");
        double side = lk->hi[d] - lk->lo[d], bad = 0.0;
        int n = grid_count(v, m, lk->lo[d], side, &bad);
        if (n == 0) {
            free(v);
            return sl_err_set(err, SL_ERR_UNSUPPORTED, "texture: the %zu knots of %c lie on no regular grid of at "
                              "most %u cells (knot %.17g is off the finest one tried); use octree, kdtree or kdforest",
                              m, axis[d], SL_LR_TEXTURE_MAX_AXIS, bad);
        }
        lk->n[d] = n;
        lk->planes[d] = malloc((size_t)(n + 1) * sizeof(double));
        if (!lk->planes[d]) {
            free(v);
            return sl_err_set(err, SL_ERR_NOMEM, "texture: out of memory");
        }
        for (int k = 0; k <= n; k++)
            lk->planes[d][k] = lk->lo[d] + side * k / n;
        for (size_t i = 0; i < m; i++)
            lk->planes[d][lround((v[i] - lk->lo[d]) / side * n)] = v[i];
        free(v);
        cells *= (size_t)n;
    }
    if (cells > SL_LR_TEXTURE_MAX_CELLS)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "texture: the knots need a %d x %d x %d grid, %zu cells above the "
                          "limit of %u; use octree, kdtree or kdforest", lk->n[0], lk->n[1], lk->n[2], cells,
                          SL_LR_TEXTURE_MAX_CELLS);
    lk->heads = malloc(cells * sizeof *lk->heads);
    if (!lk->heads)
        return sl_err_set(err, SL_ERR_NOMEM, "texture: out of memory for %zu cells", cells);
    for (size_t c = 0; c < cells; c++)
        lk->heads[c] = UINT32_MAX;
    for (size_t e = 0; e < lr->element_count; e++) {
        const sl_lr_element *el = &lr->elements[e];
        long c0[3], c1[3];
        for (int d = 0; d < 3; d++) {
            double side = lk->hi[d] - lk->lo[d];
            c0[d] = lround((el->lo[d] - lk->lo[d]) / side * lk->n[d]);
            c1[d] = lround((el->hi[d] - lk->lo[d]) / side * lk->n[d]);
        }
        for (long k = c0[2]; k < c1[2]; k++)
            for (long j = c0[1]; j < c1[1]; j++)
                for (long i = c0[0]; i < c1[0]; i++)
                    lk->heads[(size_t)i + (size_t)lk->n[0] * ((size_t)j + (size_t)lk->n[1] * (size_t)k)] = (uint32_t)e;
    }
    for (size_t c = 0; c < cells; c++)
        if (lk->heads[c] == UINT32_MAX)
            return sl_err_set(err, SL_ERR_INVALID, "texture: cell %zu is in no element (the elements do not tile "
                              "the domain)", c);
    int zero = 0;
    sl_lr_lookup_depth_stats(&lk->stats, &zero, 1);
    lk->stats.trees = cells;
    return SL_OK;
}
