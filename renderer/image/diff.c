/* diff.c — colour and depth image comparison (see sl_diff.h); the engine of sightline-diff.
 *
 * Colour: d = max over R, G, B of |a - b| (alpha ignored); mean/max of d over
 * the compared pixels: all, or with a background colour the covered ones (RGB
 * of a or of b differs from it); PSNR = 10 log10(255^2 / MSE) with MSE over
 * their R, G, B samples (INFINITY when MSE = 0); bad = compared pixels with
 * d > bad_threshold. An uncovered pixel equals the background in both images,
 * so d = 0 there: the whole-frame mean is reported too (frame_mean_abs).
 * Depth: a pixel is hit when its value is finite and > 0. mean, max and PSNR
 * are over pixels hit in both (a difference is only defined there); bad
 * pixels are those hit in both with d > bad_threshold plus every coverage
 * mismatch (hit in exactly one), and bad_pct is over the pixels hit in either,
 * so two maps that share no hit are 100 % bad, never a silent pass. Coverage
 * mismatch is also reported on its own, as a count and as a percentage of the
 * pixels hit in either (0 when none is hit). Depth PSNR uses peak = the
 * largest depth among pixels hit in both; INFINITY when MSE = 0 or no pixel
 * is hit in both. All sums in double, so the result does not depend on
 * image size beyond double rounding. Any thread; no GL.
 * Heat map (RGBA8): black = equal; otherwise t = d / max(max_abs, bad_threshold)
 * ramps dark red -> red -> yellow -> white (any non-zero difference is visibly
 * red); depth coverage mismatches are magenta.
 */
#include "sl_diff.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static sl_status check_pair(int aw, int ah, const void *ap, int bw, int bh, const void *bp,
                            const char *what, sl_err *err)
{
    if (!ap || !bp || aw <= 0 || ah <= 0 || bw <= 0 || bh <= 0)
        return sl_err_set(err, SL_ERR_INVALID, "%s: both images must be non-empty", what);
    if (aw != bw || ah != bh)
        return sl_err_set(err, SL_ERR_INVALID, "%s: sizes differ (%dx%d vs %dx%d)", what, aw, ah, bw, bh);
    return SL_OK;
}

/* Maps t in [0, 1] to the heat ramp; t <= 0 is reserved for "equal" (black). */
static void heat_colour(double t, uint8_t *px)
{
    if (!(t > 0.0)) {
        px[0] = px[1] = px[2] = 0;
    } else {
        t = 0.15 + 0.85 * (t > 1.0 ? 1.0 : t);      /* a non-zero difference is never near-black */
        double r = t * 3.0, g = t * 3.0 - 1.0, b = t * 3.0 - 2.0;
        px[0] = (uint8_t)lround(255.0 * (r > 1.0 ? 1.0 : r));
        px[1] = (uint8_t)lround(255.0 * (g < 0.0 ? 0.0 : g > 1.0 ? 1.0 : g));
        px[2] = (uint8_t)lround(255.0 * (b < 0.0 ? 0.0 : b > 1.0 ? 1.0 : b));
    }
    px[3] = 255;
}

static double heat_scale(double max_abs, double bad_threshold)
{
    double s = max_abs > bad_threshold ? max_abs : bad_threshold;
    return s > 0.0 ? s : 1.0;
}

static int is_background(const uint8_t *px, const uint8_t *background)
{
    return px[0] == background[0] && px[1] == background[1] && px[2] == background[2];
}

sl_status sl_diff_images(const sl_image *a, const sl_image *b, double bad_threshold,
                         sl_diff_result *out, uint8_t **heat, sl_err *err)
{
    return sl_diff_images_covered(a, b, bad_threshold, NULL, out, heat, err);
}

sl_status sl_diff_images_covered(const sl_image *a, const sl_image *b, double bad_threshold,
                                 const uint8_t *background, sl_diff_result *out, uint8_t **heat, sl_err *err)
{
    if (heat)
        *heat = NULL;
    if (!a || !b || !out)
        return sl_err_set(err, SL_ERR_INVALID, "sl_diff_images: images and result must not be NULL");
    sl_status st = check_pair(a->width, a->height, a->rgba, b->width, b->height, b->rgba, "sl_diff_images", err);
    if (st != SL_OK)
        return st;
    if (!isfinite(bad_threshold) || bad_threshold < 0.0)
        return sl_err_set(err, SL_ERR_INVALID, "sl_diff_images: bad_threshold %g must be finite and >= 0", bad_threshold);

    size_t n = (size_t)a->width * (size_t)a->height;
    double sum = 0.0, sq = 0.0;
    int max_d = 0;
    long bad = 0, covered = 0, histogram[256] = {0};
    for (size_t i = 0; i < n; i++) {
        const uint8_t *pa = a->rgba + i * 4, *pb = b->rgba + i * 4;
        if (background && is_background(pa, background) && is_background(pb, background))
            continue;
        covered++;
        int d = 0;
        for (int c = 0; c < 3; c++) {
            int e = abs((int)pa[c] - (int)pb[c]);
            sq += (double)e * e;
            if (e > d)
                d = e;
        }
        sum += d;
        histogram[d]++;
        if (d > max_d)
            max_d = d;
        if (d > bad_threshold)
            bad++;
    }
    memset(out, 0, sizeof *out);
    out->width = a->width;
    out->height = a->height;
    out->pixels = (long)n;
    out->compared = out->both_hit = covered;
    out->mean_abs = covered ? sum / (double)covered : 0.0;
    out->max_abs = max_d;
    /* The value at rank floor(0.99 (covered - 1)) of the sorted differences. */
    long rank = covered ? (long)(0.99 * (double)(covered - 1)) : 0, below = 0;
    for (int d = 0; d < 256 && covered; d++) {
        below += histogram[d];
        if (below > rank) {
            out->p99_abs = d;
            break;
        }
    }
    double mse = covered ? sq / (3.0 * (double)covered) : 0.0;
    out->psnr_db = mse > 0.0 ? 10.0 * log10(255.0 * 255.0 / mse) : INFINITY;
    out->bad_count = bad;
    out->bad_pct = covered ? 100.0 * (double)bad / (double)covered : 0.0;
    out->frame_mean_abs = sum / (double)n;
    out->frame_bad_pct = 100.0 * (double)bad / (double)n;

    if (heat) {
        uint8_t *h = malloc(n * 4);
        if (!h)
            return sl_err_set(err, SL_ERR_NOMEM, "sl_diff_images: out of memory for a %dx%d heat map",
                              a->width, a->height);
        double scale = heat_scale(out->max_abs, bad_threshold);
        for (size_t i = 0; i < n; i++) {
            const uint8_t *pa = a->rgba + i * 4, *pb = b->rgba + i * 4;
            int d = 0;
            for (int c = 0; c < 3; c++) {
                int e = abs((int)pa[c] - (int)pb[c]);
                if (e > d)
                    d = e;
            }
            heat_colour(d / scale, h + i * 4);
        }
        *heat = h;
    }
    return SL_OK;
}

static int is_hit(float v)
{
    return isfinite(v) && v > 0.0f;
}

sl_status sl_diff_depths(const sl_depth_image *a, const sl_depth_image *b, double bad_threshold,
                         sl_diff_result *out, uint8_t **heat, sl_err *err)
{
    if (heat)
        *heat = NULL;
    if (!a || !b || !out)
        return sl_err_set(err, SL_ERR_INVALID, "sl_diff_depths: images and result must not be NULL");
    sl_status st = check_pair(a->width, a->height, a->values, b->width, b->height, b->values, "sl_diff_depths", err);
    if (st != SL_OK)
        return st;
    if (!isfinite(bad_threshold) || bad_threshold < 0.0)
        return sl_err_set(err, SL_ERR_INVALID, "sl_diff_depths: bad_threshold %g must be finite and >= 0", bad_threshold);

    size_t n = (size_t)a->width * (size_t)a->height;
    double sum = 0.0, sq = 0.0, max_d = 0.0, peak = 0.0;
    long bad = 0, both = 0, mismatch = 0, either = 0;
    for (size_t i = 0; i < n; i++) {
        int ha = is_hit(a->values[i]), hb = is_hit(b->values[i]);
        if (ha || hb)
            either++;
        if (ha != hb) {
            mismatch++;
            continue;
        }
        if (!ha)
            continue;
        double va = a->values[i], vb = b->values[i];
        double d = fabs(va - vb);
        both++;
        sum += d;
        sq += d * d;
        if (d > max_d)
            max_d = d;
        if (va > peak)
            peak = va;
        if (vb > peak)
            peak = vb;
        if (d > bad_threshold)
            bad++;
    }
    memset(out, 0, sizeof *out);
    out->width = a->width;
    out->height = a->height;
    out->pixels = (long)n;
    out->compared = either;
    out->both_hit = both;
    out->mean_abs = both ? sum / (double)both : 0.0;
    out->max_abs = max_d;
    double mse = both ? sq / (double)both : 0.0;
    out->psnr_db = mse > 0.0 ? 10.0 * log10(peak * peak / mse) : INFINITY;
    out->bad_count = bad + mismatch;
    out->bad_pct = either ? 100.0 * (double)(bad + mismatch) / (double)either : 0.0;
    out->coverage_mismatch = mismatch;
    out->coverage_mismatch_pct = either ? 100.0 * (double)mismatch / (double)either : 0.0;

    if (heat) {
        uint8_t *h = malloc(n * 4);
        if (!h)
            return sl_err_set(err, SL_ERR_NOMEM, "sl_diff_depths: out of memory for a %dx%d heat map",
                              a->width, a->height);
        double scale = heat_scale(max_d, bad_threshold);
        for (size_t i = 0; i < n; i++) {
            int ha = is_hit(a->values[i]), hb = is_hit(b->values[i]);
            uint8_t *px = h + i * 4;
            if (ha != hb) {
                static const uint8_t magenta[4] = {255, 0, 255, 255};
                memcpy(px, magenta, sizeof magenta);
            } else if (!ha) {
                heat_colour(0.0, px);
            } else {
                heat_colour(fabs((double)a->values[i] - (double)b->values[i]) / scale, px);
            }
        }
        *heat = h;
    }
    return SL_OK;
}
