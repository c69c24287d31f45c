/* voxel_occupancy.h — the occupancy pyramid of a voxel model, for empty-space
 * skipping in both executions (the GL ray caster samples it as an R8UI 3D
 * texture, the CPU one reads these arrays).
 *
 * Level 0 is 1 where a voxel within `dilate` (Chebyshev; 2 for the ray
 * casters' neighbour search, so tubes of radius <= 2 voxels and the search
 * never reach a 0 voxel; 0 for the CPU walk's reach lists, which hold the
 * neighbours' lines already) has a non-zero count; level L
 * is the max over the 2^3 cells of level L-1. Level sizes follow GL's mip
 * rule, max(1, floor(w / 2)), cells beyond folded in by the max; at most
 * SL_VOXEL_OCCUPANCY_MAX_LEVELS levels (blocks of 8^3) and no more than a
 * texture of that size can have. CPU only, any thread, no GL.
 */
#ifndef SL_VOXEL_OCCUPANCY_H
#define SL_VOXEL_OCCUPANCY_H

#include <stdint.h>

#include "../core/sl_status.h"

#define SL_VOXEL_OCCUPANCY_MAX_LEVELS 4

typedef struct sl_voxel_occupancy {
    int levels;
    int dims[SL_VOXEL_OCCUPANCY_MAX_LEVELS][3];
    uint8_t *level[SL_VOXEL_OCCUPANCY_MAX_LEVELS]; /* owned: x fastest, 0 or 1 */
} sl_voxel_occupancy;

#define SL_VOXEL_OCCUPANCY_DILATE 2 /* the ray casters' level 0: a voxel within 2 holds lines */

/* From the per-voxel counts of a dims[0] x dims[1] x dims[2] grid, grown by
 * dilate (0..2) voxels. */
sl_status sl_voxel_occupancy_build(const int dims[3], const uint8_t *counts, int dilate, sl_voxel_occupancy *out,
                                   sl_err *err);
void sl_voxel_occupancy_deinit(sl_voxel_occupancy *o); /* zeroed is fine */

#endif
