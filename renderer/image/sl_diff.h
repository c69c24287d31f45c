/* sl_diff.h — image and depth-map comparison metrics, the engine of sightline-diff.
 *
 * Colour: per-pixel difference is the max over R, G, B of |a - b| in 0..255;
 * mean and max of that, PSNR over RGB (dB; INFINITY when identical), and the
 * percentage of pixels whose difference exceeds bad_threshold.
 * Depth (0 = nothing hit): the same statistics over pixels both hit, plus the
 * coverage mismatch: pixels hit in exactly one of the two, as a count and
 * as a percentage of the pixels hit in either. Any thread.
 */
#ifndef SL_DIFF_H
#define SL_DIFF_H

#include "sl_image.h"

typedef struct sl_diff_result {
    int width, height;
    double mean_abs, max_abs;   /* colour: 0..255 units; depth: world units */
    double psnr_db;             /* colour only (depth: over pixels both hit, peak = max depth) */
    double bad_pct;             /* % of compared pixels with difference > threshold */
    long bad_count, compared;   /* compared = all pixels (colour) or pixels both hit (depth) */
    long coverage_mismatch;     /* depth only */
    double coverage_mismatch_pct;
} sl_diff_result;

/* Fails with SL_ERR_INVALID when the sizes differ. heat (optional, may be
 * NULL) receives a malloc'd RGBA8 heat map of the same size. */
sl_status sl_diff_images(const sl_image *a, const sl_image *b, double bad_threshold,
                         sl_diff_result *out, uint8_t **heat, sl_err *err);
sl_status sl_diff_depths(const sl_depth_image *a, const sl_depth_image *b, double bad_threshold,
                         sl_diff_result *out, uint8_t **heat, sl_err *err);

#endif
