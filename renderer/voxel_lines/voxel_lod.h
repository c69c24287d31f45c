/* voxel_lod.h — representative average lines per voxel and per coarser level
 * (Kanzler et al., Sec. 3.4, Fig. 7); see density_lod.c. Level L has
 * ceil(dims / 2^L) cells; a cell's representative is a line between two
 * points on its boundary, in cell-local coordinates [0,1]^3, snapped to face
 * bin centres; NaN when the cell has none. CPU, any thread, no GL.
 */
#ifndef SL_VOXEL_LOD_H
#define SL_VOXEL_LOD_H

#include "voxel_grid.h"

#define SL_VOXEL_LOD_MAX_LEVELS 5

typedef struct sl_voxel_lod_level {
    int dims[3];
    float *lines;   /* 6 floats per cell (a xyz, b xyz), x fastest */
} sl_voxel_lod_level;

typedef struct sl_voxel_lod {
    int levels;
    sl_voxel_lod_level level[SL_VOXEL_LOD_MAX_LEVELS];
} sl_voxel_lod;

/* Builds levels 0..levels-1 (1..SL_VOXEL_LOD_MAX_LEVELS) from a built grid. */
sl_status sl_voxel_lod_build(const sl_voxel_grid *grid, int levels, sl_voxel_lod *lod, sl_err *err);
void sl_voxel_lod_deinit(sl_voxel_lod *lod); /* NULL or zeroed is fine */

#endif
