/* sl_lr_fit_dataset.h — LR fits of datasets: a regular scalar volume or vector field is
 * sampled (every `stride`-th voxel per axis, the last one always) and handed to the fit of
 * lrspline/sl_lr_fit.h, which knows samples, not datasets; and analytic vector fields sampled
 * to such volumes. Any thread; no GL; single-threaded.
 */
#ifndef SL_LR_FIT_DATASET_H
#define SL_LR_FIT_DATASET_H

#include "../lrspline/sl_lr_fit.h"
#include "sl_dataset.h"

/* Fits ds (SL_DATASET_VOLUME or SL_DATASET_VECTORS, at least 2 voxels per
 * axis) into out (allocated here; sl_lr_free frees). SL_ERR_INVALID for bad
 * parameters or another kind of dataset. */
sl_status sl_lr_fit(const sl_dataset *ds, const sl_lr_fit_params *p, sl_lr_volume *out,
                    sl_lr_fit_stats *stats, sl_err *err);

/* A regular vector field sampled from an analytic formula, for fitting
 * tests and samples: "abc" (Arnold-Beltrami-Childress, A = sqrt 3,
 * B = sqrt 2, C = 1, on [0, 2 pi]^3) or "tornado" (Crawfis' tornado, the
 * formula of the tornado generator, phase 0, on [0, 1]^3), n^3 voxels
 * (2..512). */
sl_status sl_lr_sample_field(const char *name, int n, sl_dataset **out, sl_err *err);

#endif
