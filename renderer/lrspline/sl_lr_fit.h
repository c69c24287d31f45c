/* sl_lr_fit.h — fits an adaptive LR-spline volume to samples of a regular scalar
 * volume or vector field (issue 15; the tool is sightline-lrfit; datasets come in
 * through data/sl_lr_fit_dataset.h).
 *
 * Method: the parameter domain is the world box of the voxel centres. Start
 * from a coarse tensor-product spline of the given degree (cells_longest
 * cells along the longest axis, the others in proportion, at least 1), then
 * repeat: fit the coefficients by global least squares over the voxel
 * centres (samples taken every `stride` voxels), solved by CGLS with column
 * scaling (Jacobi), warm-started from the previous coefficients (refinement
 * keeps f, so the warm start is the previous fit); measure the error at the
 * samples per element; refine, by one of the two strategies of Johannessen,
 * Kvamsdal, Dokken 2014, section 5: "structured" (the default): the basis
 * functions whose support holds an error > tol, largest first, a `fraction`
 * of them per iteration, have every knot span halved over their support
 * (sl_lr_refine_basis); "minimal span": the elements with an error > tol,
 * largest first, a `fraction` of them, are halved in each direction by the
 * shortest mesh rectangle that splits a basis function
 * (sl_lr_refine_elements). Spans never go below the finest level
 * h0 / 2^max_levels nor below two sample spacings (finer spans are not
 * determined by the samples). Stops at max error <= tol, when
 * nothing may be refined (max levels reached), at max_basis functions (the
 * cap, reported) or after max_iterations.
 * Error behaviour: least squares reproduces splines of the space exactly (a
 * polynomial of the degree to rounding); for smooth data the error falls as
 * h^(degree+1); where a basis function's support holds fewer samples than
 * the space needs the system is singular there and CGLS keeps the warm start
 * in the null directions (so refining below the voxel spacing buys nothing).
 * Vector fields: each component is fitted alone; the error is the length of
 * the error vector. Any thread; no GL; single-threaded.
 */
#ifndef SL_LR_FIT_H
#define SL_LR_FIT_H

#include <stdio.h>

#include "sl_lr.h"

typedef enum {
    SL_LR_FIT_STRUCTURED = 0,   /* halve every span of the offending basis functions */
    SL_LR_FIT_MINIMAL_SPAN = 1, /* halve the offending elements by minimal-span rectangles */
} sl_lr_fit_strategy;

typedef struct sl_lr_fit_params {
    int degree;          /* 1..SL_LR_MAX_ORDER-1, all three directions */
    sl_lr_fit_strategy strategy;
    double tol;          /* >= 0, absolute, in the data's units */
    int max_levels;      /* 0..16 refinement levels below the initial mesh */
    size_t max_basis;    /* cap on basis functions (>= the initial count) */
    int cells_longest;   /* initial cells along the longest axis, 1..1024 */
    double fraction;     /* share of the offending basis functions refined per iteration, (0, 1] */
    int stride;          /* sample every stride-th voxel per axis, >= 1 (the last voxel always) */
    int max_iterations;  /* refinement iterations, >= 0 */
    int cg_iterations;   /* CGLS iterations per fit, >= 1 */
    double cg_tol;       /* CGLS stop: scaled normal residual / that of the data, (0, 1) */
    FILE *log;           /* one line per iteration, or NULL */
} sl_lr_fit_params;

/* Defaults: degree 2, structured, tol 0, 4 levels, 200000 basis, 4 cells, fraction 0.5,
 * stride 1, 64 iterations, 200 CGLS iterations to 1e-8, no log. */
void sl_lr_fit_defaults(sl_lr_fit_params *p);

typedef struct sl_lr_fit_stats {
    int iterations;      /* refinement iterations done */
    int levels;          /* finest level reached: log2(initial side / smallest side), max over axes */
    size_t elements, basis, samples;
    double max_error, mean_error; /* at the samples, final model */
    int cap_hit;         /* stopped at max_basis */
    int levels_exhausted;/* stopped because nothing above tol could be refined */
    double seconds;
} sl_lr_fit_stats;

/* What a fit sees: values on a rectilinear grid of sample points. Datasets become one through
 * data/sl_lr_fit_dataset.h (sl_lr_fit), which keeps this folder from knowing datasets. */
typedef struct sl_lr_fit_samples {
    int n[3];          /* points per axis, >= 2 */
    double *x[3];      /* their coordinates per axis, ascending */
    double *y;         /* n0*n1*n2*dim values, x fastest, the components of a point together */
    int dim;           /* 1 (scalar) or 3 (vector) */
    double lo[3], hi[3]; /* x[d][0] and x[d][n[d] - 1] */
} sl_lr_fit_samples;

/* SL_ERR_INVALID naming the first parameter out of its range. */
sl_status sl_lr_fit_check_params(const sl_lr_fit_params *p, sl_err *err);

/* Fits the samples (p->stride is the caller's: the samples are taken) into out (allocated
 * here; sl_lr_free frees). SL_ERR_INVALID for bad parameters or samples. */
sl_status sl_lr_fit_grid(const sl_lr_fit_samples *samples, const sl_lr_fit_params *p, sl_lr_volume *out,
                         sl_lr_fit_stats *stats, sl_err *err);

#endif
