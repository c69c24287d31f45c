/* voxel_quality.h — accuracy of the voxel model (Kanzler et al., Sec. 5.1, Fig. 16).
 *
 * For one grid resolution and several face quantizations N, compares each
 * curve with its voxelized approximation (the dequantized per-voxel lines of
 * that curve, caps not applied):
 *  - Hausdorff distance, symmetric, evaluated at the vertices and segment
 *    midpoints of both polylines (a lower bound of the continuous one, exact
 *    for straight pieces at the vertices), over the part of the curve between
 *    its first and last face crossing (the dropped end pieces are excluded);
 *    reported in units of the voxel of a 64-voxel grid (as in Fig. 16a);
 *  - tangent deviation: angle between the curve's tangent at each covered
 *    vertex (central difference) and the direction of the nearest
 *    approximating line, degrees in [0, 180];
 *  - duplicate share: lines in a voxel equal to another line of that voxel
 *    (same endpoints, either orientation) / all encoded lines.
 * Means are over curves (Hausdorff) and vertices (tangent). CPU, any thread.
 */
#ifndef SL_VOXEL_QUALITY_H
#define SL_VOXEL_QUALITY_H

#include <stddef.h>

#include "voxel_grid.h"

#define SL_VOXEL_QUALITY_MAX_QUANT 8

typedef struct sl_voxel_quality {
    int resolution, quant;
    double hausdorff_mean;     /* in 64-grid voxels */
    double tangent_deg_mean;
    double duplicate_share;    /* 0..1 */
    size_t lines;              /* encoded (non-degenerate) lines */
    size_t duplicates;
    size_t curves;             /* curves measured (with at least one piece) */
} sl_voxel_quality;

/* Measures `curves` curves (0 = all; else evenly spaced ones) at grid
 * `resolution` (no padding) for each of quant[0..nquant-1] (powers of two
 * 2..256, nquant <= SL_VOXEL_QUALITY_MAX_QUANT); out[i] belongs to quant[i]. */
sl_status sl_voxel_quality_measure(const sl_dataset *ds, int resolution, const int *quant, int nquant,
                                   size_t curves, sl_voxel_quality *out, sl_err *err);

#endif
