/* voxel_gpu.h — the voxel model built on the GPU with compute shaders
 * (voxelize_gpu.c; Kanzler et al., Sec. 3.3). Same result as
 * sl_voxel_grid_build (voxel_grid.h) for the same desc, colour attribute
 * included: equal headers, equal bit-packed lines (attribute bytes too) in
 * the same order, densities within float rounding. Not counted:
 * grid->degenerate. Render thread only (GL context).
 */
#ifndef SL_VOXEL_GPU_H
#define SL_VOXEL_GPU_H

#include "voxel_grid.h"

/* Builds *grid on the GPU and reads it back. Errors as sl_voxel_grid_build,
 * plus SL_ERR_GPU when a compute program fails to build. */
sl_status sl_voxel_grid_build_gpu(sl_voxel_grid *grid, const sl_dataset *ds, const sl_voxel_grid_desc *desc,
                                  sl_err *err);

#endif
