/* sl_diff.h — image and depth-map comparison metrics, the engine of sightline-diff.
 *
 * Colour: per-pixel difference is the max over R, G, B of |a - b| in 0..255;
 * mean and max of that, PSNR over RGB (dB; INFINITY when identical), and the
 * percentage of pixels whose difference exceeds bad_threshold. With a
 * background colour those are over the covered pixels only: pixels whose RGB
 * differs from the background in either image (a frame that is mostly
 * background would otherwise dilute an error on every drawn pixel).
 * Depth (0 = nothing hit): mean, max and PSNR over pixels hit in both; bad
 * pixels are the pixels hit in both whose difference exceeds bad_threshold
 * plus every coverage mismatch (hit in exactly one), as a percentage of the
 * pixels hit in either; and the coverage mismatch on its own, as a count and
 * as a percentage of the pixels hit in either. Any thread.
 */
#ifndef SL_DIFF_H
#define SL_DIFF_H

#include "sl_image.h"

typedef struct sl_diff_result {
    int width, height;
    double mean_abs, max_abs;   /* colour: 0..255 units; depth: world units */
    double p99_abs;             /* colour only: 99th percentile (rank floor(0.99 (n - 1))) of the compared pixels */
    double psnr_db;             /* colour only (depth: over pixels both hit, peak = max depth) */
    double bad_pct;             /* 100 * bad_count / compared (0 when compared == 0) */
    long bad_count;             /* difference > threshold; depth: + coverage mismatches */
    long compared;              /* colour: all pixels, or the covered ones with a background;
                                   depth: pixels hit in either */
    long both_hit;              /* pixels mean/max/PSNR are over: = compared (colour) or hit in both (depth) */
    long pixels;                /* width x height */
    double frame_mean_abs;      /* colour: mean over all pixels, whatever compared is */
    double frame_bad_pct;       /* colour: 100 * bad_count / pixels */
    long coverage_mismatch;     /* depth only */
    double coverage_mismatch_pct;
} sl_diff_result;

/* Fails with SL_ERR_INVALID when the sizes differ. heat (optional, may be
 * NULL) receives a malloc'd RGBA8 heat map of the same size. Compares every
 * pixel: sl_diff_images_covered with no background. */
sl_status sl_diff_images(const sl_image *a, const sl_image *b, double bad_threshold,
                         sl_diff_result *out, uint8_t **heat, sl_err *err);
/* background (3 bytes R, G, B, or NULL = every pixel is covered): mean,
 * max, PSNR and bad_pct are over the pixels where a or b differs from it in
 * any of R, G, B (exact match; alpha ignored); compared = their count, 0
 * when both images are all background (then mean 0, bad_pct 0, PSNR
 * INFINITY). The heat map is the same either way. Errors as sl_diff_images. */
sl_status sl_diff_images_covered(const sl_image *a, const sl_image *b, double bad_threshold,
                                 const uint8_t *background, sl_diff_result *out, uint8_t **heat, sl_err *err);
sl_status sl_diff_depths(const sl_depth_image *a, const sl_depth_image *b, double bad_threshold,
                         sl_diff_result *out, uint8_t **heat, sl_err *err);

#endif
