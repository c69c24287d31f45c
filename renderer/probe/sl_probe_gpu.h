/* sl_probe_gpu.h — a dataset's field at world points through the shaders
 * the renderers sample it with (`sightline-probe --gpu`); the CPU double
 * reference is sl_probe.h, and tests compare the two.
 *
 * LR-spline volumes: the Bézier blocks and element look-up of
 * lrspline/sl_lr_bezier.h through lrspline/lr_probe.comp.glsl, in single
 * precision as lr_volume renders: value and gradient (vectors: the vector
 * and its Jacobian). Scalar volumes: volume_dvr's sample, the texture of
 * renderer/volume (every voxel type) through the texture unit's trilinear
 * filter (volume/volume_sample.glsl, probe_volume.comp.glsl). Vector fields:
 * the streamline field, flow's RGBA32F texture interpolated by texelFetch in
 * float (flow/flow_field_regular.glsl, probe_vectors.comp.glsl).
 * Not here: gradients of regular volumes — no shader computes the
 * interpolant's own (volume_dvr shades with central differences), so
 * create refuses them rather than answer another quantity.
 * Points: "outside" is the CPU's decision in double (sl_probe_inside), so
 * both paths leave the same fields empty; a point inside is rounded to float
 * (the renderers' positions) and clamped into the domain's float box
 * (rounded inwards) before the shader sees it. NaN voxels: the filter
 * spreads them to every tap (the CPU skips taps of weight 0).
 * Render thread only (GL context current); the dataset must outlive it.
 */
#ifndef SL_PROBE_GPU_H
#define SL_PROBE_GPU_H

#include <stddef.h>

#include "../core/sl_status.h"
#include "../data/sl_dataset.h"

typedef struct sl_probe_gpu sl_probe_gpu;

/* Uploads what the shader path reads (LR: builds the blocks, reusing the
 * model's look-up) and compiles its program. gradient: the caller wants
 * gradients (SL_ERR_UNSUPPORTED for regular volumes, see above). Also
 * SL_ERR_UNSUPPORTED for datasets without a field, SL_ERR_NOMEM,
 * SL_ERR_LIMIT (the blocks'), SL_ERR_GPU (compile, upload). On failure
 * *out is NULL and nothing is held. */
sl_status sl_probe_gpu_create(const sl_dataset *ds, int gradient, sl_probe_gpu **out, sl_err *err);
void sl_probe_gpu_destroy(sl_probe_gpu *g); /* NULL is fine */

/* Evaluates n points (3n doubles) as sl_probe_eval would, one dispatch:
 * values[n * components], gradients[n * 3 * components] (NULL: none; must be
 * NULL unless created with gradient), inside[n] (0: fields untouched).
 * SL_ERR_NOMEM, SL_ERR_GPU (a GL error, or the look-up finding no element
 * for a point inside: a bug, named by its index). */
sl_status sl_probe_gpu_eval(sl_probe_gpu *g, size_t n, const double *points, double *values, double *gradients,
                            unsigned char *inside, sl_err *err);

#endif
