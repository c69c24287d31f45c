/* sl_probe.h — a dataset's field (value, gradient) at world points, on the
 * CPU in double: what `sightline-probe` answers, and the reference a GPU
 * evaluation is compared against.
 *
 * Regular volumes and vector fields: the trilinear interpolant, voxel
 * (i,j,k) at origin + spacing·(i,j,k) (renderer/volume/sl_volume.h); the
 * domain is the closed box of the voxel centres, a one-voxel axis a slab one
 * spacing thick with a constant value. The gradient is the interpolant's own
 * (on a cell face the cell above, at the last voxel the cell below; 0 along a
 * one-voxel axis); taps of zero weight are not read (a NaN neighbour does not
 * reach a probe on a voxel). LR-spline volumes: sl_lr_eval on the element the
 * rule of lrspline/sl_lr.h picks (sl_lr_find_element: the model's look-up). Line sets have no field.
 * The shader path is sl_probe_gpu.h. Any thread; the dataset is only read.
 */
#ifndef SL_PROBE_H
#define SL_PROBE_H

#include "../core/sl_status.h"
#include "../data/sl_dataset.h"

#define SL_PROBE_MAX_COMPONENTS 3

/* Value components of the dataset's field: 1 (scalar) or 3 (vector); 0 for
 * datasets without a field (line sets). */
int sl_probe_components(const sl_dataset *ds);

/* 1 when p is finite and inside the dataset's domain (the rule above:
 * the voxel centres' closed box, the LR element rule), else 0 (also for
 * datasets without a field). What decides "outside" for sl_probe_eval and
 * for the GPU path (sl_probe_gpu.h) alike. */
int sl_probe_inside(const sl_dataset *ds, const double p[3]);

/* Evaluates the field at the world point p. Inside the domain: *inside = 1,
 * value[components] and, when gradient is not NULL, gradient[c*3 + j] =
 * d value_c / d x_j (the Jacobian for vectors). Outside (or p not finite):
 * *inside = 0 and value/gradient are left untouched; that is not an error.
 * SL_ERR_UNSUPPORTED for a dataset without a field. */
sl_status sl_probe_eval(const sl_dataset *ds, const double p[3], double *value, double *gradient, int *inside,
                        sl_err *err);

#endif
