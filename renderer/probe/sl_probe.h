/* sl_probe.h — the value (and gradient) of a dataset's field at world
 * points, evaluated on the CPU in double: what `sightline-probe` answers and
 * the reference a GPU evaluation is compared against.
 *
 * Regular scalar volumes and vector fields: the trilinear interpolant of
 * the voxel values, voxel (i,j,k) at origin + spacing·(i,j,k) (the
 * convention of renderer/volume/sl_volume.h); the domain is the box of the
 * voxel centres, closed, except that an axis of one voxel is a slab one
 * spacing thick on which the value is constant. The gradient is the
 * interpolant's own (per world unit; in a cell's interior exact, on a cell
 * face the cell above, at the last voxel the cell below; 0 along a
 * one-voxel axis). Taps of zero weight are not read, so a point on a voxel
 * gives that voxel's value even beside a NaN voxel.
 * LR-spline volumes: sl_lr_eval on the element the element rule of
 * lrspline/sl_lr.h picks (linear search); the domain is the closed
 * parameter box.
 * Line sets have no field: SL_ERR_UNSUPPORTED. Does not do GPU evaluation
 * (another backend with the same shape, see tools/sightline_probe.c).
 * Any thread; the dataset is only read.
 */
#ifndef SL_PROBE_H
#define SL_PROBE_H

#include "../core/sl_status.h"
#include "../data/sl_dataset.h"

#define SL_PROBE_MAX_COMPONENTS 3

/* Value components of the dataset's field: 1 (scalar) or 3 (vector); 0 for
 * datasets without a field (line sets). */
int sl_probe_components(const sl_dataset *ds);

/* Evaluates the field at the world point p. Inside the domain: *inside = 1,
 * value[components] and, when gradient is not NULL, gradient[c*3 + j] =
 * d value_c / d x_j (the Jacobian for vectors). Outside (or p not finite):
 * *inside = 0 and value/gradient are left untouched; that is not an error.
 * SL_ERR_UNSUPPORTED for a dataset without a field. */
sl_status sl_probe_eval(const sl_dataset *ds, const double p[3], double *value, double *gradient, int *inside,
                        sl_err *err);

#endif
