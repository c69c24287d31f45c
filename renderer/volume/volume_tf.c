/* volume_tf.c — a transfer-function parameter resolved for a dataset, baked, uploaded (see sl_volume.h).
 *
 * Resolution is exact (the colormap form's colormap and opacity ramp are both
 * piecewise linear in t, so their union of breakpoints reproduces them); the
 * bake samples the result at SL_VOLUME_TF_TEXELS evenly spaced values, so
 * only texels holding a breakpoint differ from the exact function (by at most
 * a slope change × 1/4 texel). CPU parts: any thread; GL parts: render thread.
 */
#include "sl_volume.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_colormap.h"
#include "../gpu/sl_gpu.h"

extern sl_volume_counters sl_volume_counters_now; /* volume_bricks.c */

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Opacity of a [t, alpha] ramp at t (constant beyond the ends). */
static double ramp_alpha(const sl_transfer_function *tf, double t)
{
    if (t <= tf->point[0][0])
        return tf->point[0][1];
    for (int k = 1; k < tf->count; k++)
        if (t <= tf->point[k][0]) {
            double t0 = tf->point[k - 1][0], t1 = tf->point[k][0];
            double f = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
            return tf->point[k - 1][1] + f * (tf->point[k][1] - tf->point[k - 1][1]);
        }
    return tf->point[tf->count - 1][1];
}

/* Smoothed bin k: the mean of bins k-2 .. k+2 that exist. */
static double smoothed(const uint64_t *h, int k)
{
    double sum = 0.0;
    int n = 0;
    for (int j = k - 2; j <= k + 2; j++)
        if (j >= 0 && j < SL_VOLUME_HISTOGRAM_BINS) {
            sum += (double)h[j];
            n++;
        }
    return sum / n;
}

int sl_volume_tf_auto_opacity(const sl_volume *vol, int emission_absorption, double ramp[4][2])
{
    const int bins = SL_VOLUME_HISTOGRAM_BINS;
    const uint64_t *h = vol->histogram;
    double total = (double)vol->finite_count;
    if (!(total > 0.0)) {
        ramp[0][0] = 0.0, ramp[0][1] = 0.0;
        ramp[1][0] = 1.0, ramp[1][1] = SL_VOLUME_AUTO_ALPHA;
        return 2;
    }
    int peak = 0;
    for (int k = 1; k < bins; k++)
        if (h[k] > h[peak])
            peak = k;
    /* start: the first bin of the ramp (0 without a background peak). */
    int start = 0;
    if (peak < bins / 2 && (double)h[peak] >= SL_VOLUME_AUTO_PEAK * total) {
        /* Past the smoothing window of the spike first (zeros beside a
         * one-bin spike make the smoothed curve rise for two bins). */
        start = peak;
        while (start < bins - 1 && (start < peak + 2 || smoothed(h, start + 1) < smoothed(h, start)))
            start++;
    }
    /* end: the bin holding the 99.5th percentile of the values from start on. */
    double above = 0.0;
    for (int k = start; k < bins; k++)
        above += (double)h[k];
    int end = bins - 1;
    double seen = 0.0;
    for (int k = start; k < bins && above > 0.0; k++) {
        seen += (double)h[k];
        if (seen >= 0.995 * above) {
            end = k;
            break;
        }
    }
    double t0 = (double)start / bins, t1 = (double)(end + 1) / bins;
    if (t1 <= t0)
        t1 = fmin(1.0, t0 + 1.0 / bins);
    if (t1 <= t0) /* start is the last bin */
        t0 = t1 - 1.0 / bins;
    int n = 0;
    ramp[n][0] = t0, ramp[n++][1] = 0.0;
    ramp[n][0] = 0.5 * (t0 + t1), ramp[n++][1] = SL_VOLUME_AUTO_ALPHA * SL_VOLUME_AUTO_MID;
    ramp[n][0] = t1, ramp[n++][1] = SL_VOLUME_AUTO_ALPHA;
    /* Bound the optical depth (see sl_volume.h): scale every extinction
     * -ln(1 - alpha) by one factor, which scales the estimate exactly. */
    double depth = emission_absorption ? sl_volume_tf_ramp_depth(vol, ramp, n) : 0.0;
    if (depth > SL_VOLUME_AUTO_DEPTH) {
        double scale = SL_VOLUME_AUTO_DEPTH / depth;
        for (int k = 0; k < n; k++)
            ramp[k][1] = -expm1(scale * log1p(-ramp[k][1]));
    }
    return n;
}

double sl_volume_tf_ramp_depth(const sl_volume *vol, const double ramp[][2], int n)
{
    const uint64_t *h = vol->histogram;
    sl_transfer_function tf = {.colormap = -1, .count = n};
    for (int k = 0; k < n; k++)
        tf.point[k][0] = ramp[k][0], tf.point[k][1] = ramp[k][1];
    double seen = 0.0, extinction = 0.0; /* over the voxels the ramp makes visible */
    for (int k = 0; k < SL_VOLUME_HISTOGRAM_BINS; k++) {
        double alpha = ramp_alpha(&tf, (k + 0.5) / SL_VOLUME_HISTOGRAM_BINS);
        if (alpha <= 0.0 || h[k] == 0)
            continue;
        seen += (double)h[k];
        extinction += (double)h[k] * -log1p(-fmin(alpha, 0.999999));
    }
    if (!(seen > 0.0))
        return 0.0;
    /* The visible share of the box (in cells of the volume's spacing), in
     * cubes of the smallest spacing (the unit of alpha), as a ball. */
    double unit = fmin(fmin(vol->spacing[0], vol->spacing[1]), vol->spacing[2]);
    double cubes = seen / (double)vol->finite_count;
    for (int a = 0; a < 3; a++)
        cubes *= vol->dims[a] * (unit > 0.0 ? vol->spacing[a] / unit : 1.0);
    double chord = cbrt(6.0 * cubes / M_PI); /* the diameter of that ball */
    return chord * extinction / seen;
}

double sl_volume_auto_isovalue(const sl_volume *vol)
{
    double ramp[4][2];
    sl_volume_tf_auto_opacity(vol, 1, ramp);
    double t = ramp[0][0] > 0.0 && ramp[0][0] < 1.0 ? ramp[0][0] : 0.5;
    return vol->value_min + t * (vol->value_max - vol->value_min);
}

void sl_volume_tf_resolve(const sl_transfer_function *given, const sl_volume *vol, int emission_absorption,
                          sl_volume_tf_points *out)
{
    memset(out, 0, sizeof *out);
    double value_min = vol->value_min, value_max = vol->value_max;
    sl_transfer_function with_ramp;
    const sl_transfer_function *tf = given;
    if (given->auto_opacity) {
        double ramp[4][2] = {{0}};
        with_ramp = *given;
        with_ramp.count = sl_volume_tf_auto_opacity(vol, emission_absorption, ramp);
        /* The ramp's t spans the value range; a given range re-maps it. */
        double span = value_max > value_min ? value_max - value_min : 1.0;
        for (int k = 0; k < with_ramp.count; k++) {
            double t = ramp[k][0];
            if (given->has_range)
                t = (value_min + t * span - given->range[0]) / (given->range[1] - given->range[0]);
            with_ramp.point[k][0] = t, with_ramp.point[k][1] = ramp[k][1];
        }
        tf = &with_ramp;
    }
    if (tf->colormap < 0) {
        out->count = tf->count;
        for (int k = 0; k < tf->count; k++) {
            out->value[k] = tf->point[k][0];
            for (int c = 0; c < 4; c++)
                out->rgba[k][c] = tf->point[k][1 + c];
        }
        return;
    }
    double lo = tf->has_range ? tf->range[0] : value_min, hi = tf->has_range ? tf->range[1] : value_max;
    if (!(hi > lo)) {
        lo -= 0.5;
        hi = lo + 1.0;
    }
    /* Breakpoints in t: the colormap's 9 control points and the ramp's. */
    double ts[SL_VOLUME_TF_MAX];
    int n = 0;
    for (int k = 0; k <= 8; k++)
        ts[n++] = k / 8.0;
    for (int k = 0; k < tf->count; k++)
        ts[n++] = fmin(fmax(tf->point[k][0], 0.0), 1.0);
    qsort(ts, (size_t)n, sizeof ts[0], compare_doubles);
    for (int k = 0; k < n; k++) {
        if (out->count > 0 && ts[k] == ts[k - 1])
            continue;
        float rgb[3];
        sl_colormap_sample(tf->colormap, ts[k], rgb);
        int i = out->count++;
        out->value[i] = lo + ts[k] * (hi - lo);
        out->rgba[i][0] = rgb[0];
        out->rgba[i][1] = rgb[1];
        out->rgba[i][2] = rgb[2];
        out->rgba[i][3] = ramp_alpha(tf, ts[k]);
    }
}

void sl_volume_tf_eval(const sl_volume_tf_points *pts, double v, double rgba[4])
{
    if (isnan(v)) {
        rgba[0] = rgba[1] = rgba[2] = rgba[3] = 0.0;
        return;
    }
    int n = pts->count;
    const double *a = pts->rgba[0], *b = pts->rgba[n - 1];
    double f = 0.0;
    if (v > pts->value[0] && v < pts->value[n - 1]) {
        for (int k = 1; k < n; k++)
            if (v <= pts->value[k]) {
                double v0 = pts->value[k - 1], v1 = pts->value[k];
                a = pts->rgba[k - 1];
                b = pts->rgba[k];
                f = v1 > v0 ? (v - v0) / (v1 - v0) : 1.0;
                break;
            }
    } else if (v >= pts->value[n - 1]) {
        a = b;
    }
    for (int c = 0; c < 4; c++)
        rgba[c] = a[c] + f * (b[c] - a[c]);
}

void sl_volume_tf_bake(const sl_volume_tf_points *pts, sl_volume_tf_table *table)
{
    table->lo = pts->value[0];
    table->hi = pts->value[pts->count - 1];
    if (!(table->hi > table->lo))
        table->hi = table->lo + 1.0;
    uint32_t nonzero = 0;
    for (int k = 0; k < SL_VOLUME_TF_TEXELS; k++) {
        double v = table->lo + (table->hi - table->lo) * k / (SL_VOLUME_TF_TEXELS - 1);
        double rgba[4];
        sl_volume_tf_eval(pts, v, rgba);
        for (int c = 0; c < 4; c++)
            table->rgba[k][c] = (float)rgba[c];
        table->nonzero_before[k] = nonzero;
        nonzero += table->rgba[k][3] > 0.0f;
    }
    table->nonzero_before[SL_VOLUME_TF_TEXELS] = nonzero;
}

/* Texel coordinate of value v, clamped to [0, TEXELS - 1]. */
static double texel_of(const sl_volume_tf_table *t, double v)
{
    double u = (v - t->lo) / (t->hi - t->lo) * (SL_VOLUME_TF_TEXELS - 1);
    return u < 0.0 ? 0.0 : (u > SL_VOLUME_TF_TEXELS - 1 ? SL_VOLUME_TF_TEXELS - 1 : u);
}

int sl_volume_tf_table_visible(const sl_volume_tf_table *table, double lo, double hi)
{
    if (!(lo <= hi))
        return 0;
    /* A texel of index < floor(u(lo)) or > ceil(u(hi)) never enters an
     * interpolation of a value in [lo, hi]. One texel of margin either way
     * covers the float rounding of the shader's u. */
    int i0 = (int)floor(texel_of(table, lo)) - 1, i1 = (int)ceil(texel_of(table, hi)) + 1;
    i0 = i0 < 0 ? 0 : i0;
    i1 = i1 > SL_VOLUME_TF_TEXELS - 1 ? SL_VOLUME_TF_TEXELS - 1 : i1;
    return table->nonzero_before[i1 + 1] - table->nonzero_before[i0] > 0;
}

sl_status sl_volume_tf_texture_create(GLuint *tex, sl_err *err)
{
    glCreateTextures(GL_TEXTURE_1D, 1, tex);
    glTextureStorage1D(*tex, 1, GL_RGBA32F, SL_VOLUME_TF_TEXELS);
    glTextureParameteri(*tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(*tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    return sl_gl_check_errors("volume: creating the transfer-function texture", err);
}

void sl_volume_tf_texture_upload(GLuint tex, const sl_volume_tf_table *table)
{
    glTextureSubImage1D(tex, 0, 0, SL_VOLUME_TF_TEXELS, GL_RGBA, GL_FLOAT, table->rgba);
    sl_volume_counters_now.tf_uploads++;
}
