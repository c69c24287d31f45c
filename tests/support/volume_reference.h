/* volume_reference.h — CPU double-precision reference ray marcher for scalar volumes.
 *
 * The model of renderer/volume_dvr/README.md, brute force, sharing no code
 * with the shader or renderer/volume/ (only the camera's pixel-ray formula,
 * sl_view_ray_dir). Voxel (i,j,k) holds its value at origin + spacing·(i,j,k);
 * the box spans the voxel centres, [0, dims-1] in voxel coordinates (an axis
 * of one voxel: [-0.5, 0.5]), intersected with the clip box given in 0..1 of
 * it; nothing outside. The ray eye + t·d (d the unit centre ray of the pixel)
 * runs from max(t_enter, 0) to t_exit; dt = step · min(spacing); samples at
 * the midpoints of the n = floor(L / dt) whole segments, opacity exponent
 * step, then one at the midpoint of the remainder r = L - n·dt (if r > 0),
 * exponent r / min(spacing). Value: trilinear over the 8 voxels around the
 * point (coordinates clamped into the grid), NaN when any of them is NaN;
 * nearest: voxel floor(p + 0.5). Transfer function: piecewise linear through
 * the points, constant beyond the ends; NaN samples are transparent.
 * composite: α′ = 1 − (1 − α)^exponent, C += (1 − A)·α′·c, A += (1 − A)·α′,
 * stop once A >= alpha_stop; distance where A first exceeds 0.5.
 * mip: m = max of the finite samples; pixel = α(m)·c(m) + (1 − α(m))·bg.
 * iso: samples preceded by one at the entry; the first sign change of
 * value − iso between two consecutive finite samples, bisected in double to
 * 1e-12 of the segment; distance of the crossing; colour not modelled (the
 * pixel is the transfer function's colour at iso, unshaded).
 * Pixel = C + (1 − A)·background in 0..1, ×255 rounded, no gamma; no jitter,
 * no shading. Limits: test-sized frames; single thread.
 */
#ifndef VOLUME_REFERENCE_H
#define VOLUME_REFERENCE_H

#include <stdint.h>

#include "core/sl_camera.h"
#include "data/sl_dataset.h"

typedef enum volume_ref_mode { VOLUME_REF_COMPOSITE, VOLUME_REF_MIP, VOLUME_REF_ISO } volume_ref_mode;

typedef struct volume_ref_desc {
    const sl_view *view;          /* initialised; background used */
    const sl_dataset *volume;     /* SL_DATASET_VOLUME (1 component) */
    int tf_count;                 /* >= 1 */
    const double (*tf)[5];        /* value, r, g, b, a; values non-decreasing */
    volume_ref_mode mode;
    double step;                  /* units of the smallest spacing, > 0 */
    double alpha_stop;            /* composite: stop once A >= this */
    double iso;                   /* iso: the surface value */
    int nearest;                  /* 1: nearest voxel instead of trilinear */
    double clip_min[3], clip_max[3]; /* 0..1 of the box; zero both = no clip */
    int uncorrected;              /* negative tests only: α′ = α (no opacity correction), to
                                     show that a check catches a renderer without it */
} volume_ref_desc;

/* Renders desc into rgba (width × height × 4, rows top-down, alpha 255) and,
 * when distance is not NULL, the distance per pixel (0 = none). Returns 0,
 * or -1 on bad input or no memory. */
int volume_ref_render(const volume_ref_desc *desc, uint8_t *rgba, float *distance);

#endif
