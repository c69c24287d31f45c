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
 * plus SL_ERR_GPU when a compute program fails to build or any GL call of
 * the build fails (checked with glGetError after the last pass; the grid is
 * then not returned). Every dispatch is split into chunks of at most
 * GL_MAX_COMPUTE_WORK_GROUP_COUNT[0] groups, so any grid within the voxel
 * limits builds on a driver at the GL minimum (65535, llvmpipe). */
sl_status sl_voxel_grid_build_gpu(sl_voxel_grid *grid, const sl_dataset *ds, const sl_voxel_grid_desc *desc,
                                  sl_err *err);

/* The same with at most max_groups work groups per dispatch chunk (0 or
 * above the driver's limit = the limit). Tests use a small value to exercise
 * the chunking on small, fast grids. */
sl_status sl_voxel_grid_build_gpu_chunked(sl_voxel_grid *grid, const sl_dataset *ds, const sl_voxel_grid_desc *desc,
                                          unsigned max_groups, sl_err *err);

#endif
