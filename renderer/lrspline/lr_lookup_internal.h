/* lr_lookup_internal.h — what the look-up builders share (lr_lookup.c,
 * lr_lookup_texture.c, lr_lookup_octree.c, lr_lookup_kdtree.c); not part of
 * the API. Any thread; no GL. */
#ifndef SL_LR_LOOKUP_INTERNAL_H
#define SL_LR_LOOKUP_INTERNAL_H

#include "sl_lr_lookup.h"

/* Sorted distinct values of the element faces in direction d (count in *n;
 * caller frees). NULL on allocation failure. */
double *sl_lr_lookup_distinct_faces(const sl_lr_volume *lr, int d, size_t *n);

/* Cell of p[d] among planes[0..n] (p inside [planes[0], planes[n]]):
 * planes[c] <= p < planes[c+1], the last cell closed above. */
int sl_lr_lookup_cell(const double *planes, int n, double lo, double hi, double p);

sl_status sl_lr_lookup_build_texture(sl_lr_lookup *lk, const sl_lr_volume *lr, sl_err *err);
/* At most max_cells split cells, else SL_ERR_LIMIT. */
sl_status sl_lr_lookup_build_octree(sl_lr_lookup *lk, const sl_lr_volume *lr, size_t max_cells, sl_err *err);
/* kdtree = forest of 1 x 1 x 1 blocks. */
sl_status sl_lr_lookup_build_forest(sl_lr_lookup *lk, const sl_lr_volume *lr, int axis_blocks, sl_err *err);

/* Per-tree depth statistics into lk->stats from an array of depths. */
void sl_lr_lookup_depth_stats(sl_lr_lookup_stats *s, const int *depth, size_t trees);

#endif
