/* voxel_check.c — GPU checks of `voxel_lines` against its baselines, on llvmpipe.
 *
 * usage: voxel-check depth [--data JSON] [--size N] [--quant N] [--grid N]
 *                          [--tol-median F] [--tol-p95 F] [--max-mismatch-pct P]
 *        voxel-check oit   [--data JSON] [--size N] [--opacity A] [--tol-mean F] [--tol-p99 F]
 *        voxel-check tubes [same options as oit]
 *        voxel-check effects|work [--data JSON] [--size N]
 *        voxel-check stress [--size N] [depth tolerances]
 *        voxel-check edge [--size N] [depth tolerances] [--max-mesh-only-pct P]
 * depth: opaque voxel_lines eye distances against tubes_mesh on the same
 *   lines and radius (still frame, neighbour search on): on pixels both hit,
 *   the median and 95th percentile of |difference| in units of the tube
 *   radius must stay below the tolerances; pixels hit by one side only
 *   (silhouettes, the dropped end pieces) below max-mismatch-pct of the
 *   pixels either hits, and those hit by tubes_mesh only below
 *   max-mesh-only-pct.
 * oit: transparent voxel_lines colour against lines_oit (no overflow) at the
 *   same opacity — constant, with alpha termination at 0.5 in both, and with
 *   the opacity ramp: mean and 99th percentile of the per-pixel max channel
 *   difference (0..255) over the pixels either image covers.
 * tubes: tubes_mesh `opacity` (1 = the default opaque frame bit for bit; below
 *   1 fainter, and within the oit tolerances of lines_oit).
 * stress: a lattice of lines exactly on voxel faces, edges and corners
 *   (axis-parallel and through corners, grid 16) passes the depth check, and
 *   the same data 1e6 units from the origin gives the same image (<= 0.5 %
 *   of channels differ by > 2), and seen from 400 bounding radii through a
 *   0.25 degree lens it passes the depth check again. --backend gl|cpu
 *   picks voxel_lines' execution (default: its own rule).
 * edge: tubes of 1.5 voxels along the edges of the data's box pass the depth
 *   check (the grid's padding must hold them).
 * effects: empty-space skipping leaves the image unchanged (<= 0.1 % of
 *   channels, each by <= 2); full-strength shadows and AO darken the mean
 *   luma of covered pixels by more than 2 % and brighten no channel by > 1;
 *   so do hard shadows from representative lines (shadow_mode = lines); then
 *   the per-frame parameters of check_effects_more.
 * work: which preprocessing each change causes (check_effects_more).
 * Exit 0 pass, 1 fail, 2 bad input, 3 GPU failure. Render thread = main.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "image/sl_diff.h"
#include "pipeline/sl_pipeline.h"
#include "voxel_lines/voxel_lines.h"

typedef struct options {
    const char *mode, *data, *backend; /* backend: voxel_lines' choice, NULL = its default */
    int size, quant, grid;
    double opacity, radius_frac;
    double tol_median, tol_p95, max_mismatch_pct, max_mesh_only_pct, tol_mean, tol_p99;
} options;

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : (x > y);
}

static sl_status set_num(sl_params *p, const char *name, double v, sl_err *err)
{
    return sl_params_set_numbers(p, name, &v, 1, err);
}

/* Extra numeric parameters ("name=value"), applied by render_mem to every
 * technique whose schema has them. */
#define EXTRA_MAX 8
static const char *extra_bools[EXTRA_MAX]; /* NULL-terminated */
static sl_frame_stats last_stats;          /* of the last render_mem */

/* Renders one frame of technique `name` with a few parameters; fills rgba
 * and/or distance. fragment_mb > 0 sets lines_oit's list memory cap. */
static sl_status render_mem(sl_pipeline *pipe, const char *name, const options *o, double radius, double opacity,
                            double fragment_mb, const sl_view *view, uint8_t *rgba, float *dist, sl_err *err)
{
    const sl_technique *t = sl_technique_find(name);
    if (!t)
        return sl_err_set(err, SL_ERR_INVALID, "technique %s is not registered", name);
    sl_params p;
    sl_params_init(&p, t->params, t->param_count);
    sl_status st = set_num(&p, "radius", radius, err);
    if (st == SL_OK && sl_params_find(&p, "opacity") >= 0)
        st = set_num(&p, "opacity", opacity, err);
    if (st == SL_OK && sl_params_find(&p, "attribute") >= 0)
        st = set_num(&p, "attribute", -1, err);
    if (st == SL_OK && fragment_mb > 0.0)
        st = set_num(&p, "fragment_memory_mb", fragment_mb, err);
    if (st == SL_OK && sl_params_find(&p, "caps") >= 0)
        st = set_num(&p, "caps", 0, err);
    if (st == SL_OK && sl_params_find(&p, "sides") >= 0)
        st = set_num(&p, "sides", 24, err);
    if (st == SL_OK && strcmp(name, "voxel_lines") == 0) {
        char q[16];
        snprintf(q, sizeof q, "%d", o->quant);
        st = sl_params_set_choice(&p, "quantization", q, err);
        if (st == SL_OK)
            st = set_num(&p, "grid", o->grid, err);
        if (st == SL_OK)
            st = set_num(&p, "alpha_threshold", 1.0, err);
        if (st == SL_OK && o->backend)
            st = sl_params_set_choice(&p, "backend", o->backend, err);
    }
    for (int i = 0; i < EXTRA_MAX && extra_bools[i] && st == SL_OK; i++) {
        char key[64];
        snprintf(key, sizeof key, "%s", extra_bools[i]);
        char *eq = strchr(key, '=');
        if (!eq)
            return sl_err_set(err, SL_ERR_INVALID, "bad extra parameter %s", extra_bools[i]);
        *eq = '\0';
        if (sl_params_find(&p, key) >= 0)
            st = set_num(&p, key, atof(eq + 1), err);
    }
    if (st == SL_OK)
        st = sl_pipeline_set_technique(pipe, t, &p, err);
    sl_frame_stats stats = {0};
    if (st == SL_OK)
        st = sl_pipeline_render(pipe, view, 1, &stats, err);
    last_stats = stats;
    if (st != SL_OK)
        return st;
    if (rgba)
        sl_pipeline_read_rgba(pipe, rgba, 1);
    if (dist)
        sl_pipeline_read_distance(pipe, view, dist);
    fprintf(stderr, "%s: %.1f ms gpu, prepare %.1f ms, %.2f MB\n", name, stats.gpu_ms, stats.prepare_ms,
            stats.gpu_bytes / 1e6);
    return SL_OK;
}

static sl_status render(sl_pipeline *pipe, const char *name, const options *o, double radius, double opacity,
                        const sl_view *view, uint8_t *rgba, float *dist, sl_err *err)
{
    return render_mem(pipe, name, o, radius, opacity, 0.0, view, rgba, dist, err);
}

static int check_depth(sl_pipeline *pipe, const options *o, const sl_view *view, double radius)
{
    size_t n = (size_t)view->width * view->height;
    float *a = calloc(n, sizeof *a), *b = calloc(n, sizeof *b), *diff = calloc(n, sizeof *diff);
    sl_err err = {0};
    int rc = 3;
    if (!a || !b || !diff)
        goto done;
    if (render(pipe, "tubes_mesh", o, radius, 1.0, view, NULL, a, &err) != SL_OK ||
        render(pipe, "voxel_lines", o, radius, 1.0, view, NULL, b, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: %s\n", err.message);
        goto done;
    }
    size_t both = 0, either = 0, only = 0, bad = 0, mesh_only = 0;
    for (size_t i = 0; i < n; i++) {
        int ha = a[i] > 0.0f, hb = b[i] > 0.0f;
        if (!isfinite(a[i]) || !isfinite(b[i]))
            bad++;
        either += ha || hb;
        only += ha != hb;
        mesh_only += ha && !hb;
        if (ha && hb)
            diff[both++] = fabsf(a[i] - b[i]) / (float)radius;
    }
    qsort(diff, both, sizeof *diff, cmp_float);
    double med = both ? diff[both / 2] : INFINITY, p95 = both ? diff[(size_t)(0.95 * (both - 1))] : INFINITY;
    double mismatch = either ? 100.0 * (double)only / (double)either : 100.0;
    double mesh_pct = either ? 100.0 * (double)mesh_only / (double)either : 100.0;
    printf("depth: %zu pixels both hit, |d| / radius median %.4f p95 %.4f max %.4f; one side only %.2f%%, "
           "tubes_mesh only %.2f%% (limits %.4f, %.4f, %.2f%%, %.2f%%)\n",
           both, med, p95, both ? diff[both - 1] : 0.0, mismatch, mesh_pct, o->tol_median, o->tol_p95,
           o->max_mismatch_pct, o->max_mesh_only_pct);
    rc = (both > n / 50 && bad == 0 && med <= o->tol_median && p95 <= o->tol_p95 &&
          mismatch <= o->max_mismatch_pct && mesh_pct <= o->max_mesh_only_pct) ? 0 : 1;
done:
    free(a);
    free(b);
    free(diff);
    return rc;
}

/* Pixels covered by either image (some channel differs from the background). */
static int covered_pixel(const uint8_t *a, const uint8_t *b, size_t i, const float bg[4])
{
    int touched = 0;
    for (int c = 0; c < 3; c++) {
        uint8_t g = (uint8_t)(bg[c] * 255.0f + 0.5f);
        touched |= a[4 * i + c] != g || b[4 * i + c] != g;
    }
    return touched;
}

/* Max-channel |a - b| over the pixels either covers (sl_diff_images_covered):
 * mean, 99th percentile and max; INFINITY when none is covered. Returns the
 * covered count. */
static size_t covered_diff(const uint8_t *a, const uint8_t *b, int w, int h, const float bg[4], double *mean,
                           double *p99, double *max)
{
    uint8_t g[3];
    for (int c = 0; c < 3; c++)
        g[c] = (uint8_t)(bg[c] * 255.0f + 0.5f);
    sl_image ia = {.width = w, .height = h, .rgba = (uint8_t *)a}, ib = {.width = w, .height = h, .rgba = (uint8_t *)b};
    sl_diff_result r;
    sl_err err;
    if (sl_diff_images_covered(&ia, &ib, 8.0, g, &r, NULL, &err) != SL_OK || r.compared == 0) {
        *mean = *p99 = *max = INFINITY;
        return 0;
    }
    *mean = r.mean_abs;
    *p99 = r.p99_abs;
    *max = r.max_abs;
    return (size_t)r.compared;
}

/* voxel_lines vs lines_oit with the extra parameters in extra_bools (set by
 * the caller); prints and returns 0 when within the covered-pixel limits. */
static int oit_pair(sl_pipeline *pipe, const options *o, const sl_view *view, double radius, const char *label,
                    uint8_t *a, uint8_t *b, sl_err *err)
{
    size_t n = (size_t)view->width * view->height;
    if (render(pipe, "lines_oit", o, radius, o->opacity, view, a, NULL, err) != SL_OK ||
        render(pipe, "voxel_lines", o, radius, o->opacity, view, b, NULL, err) != SL_OK) {
        fprintf(stderr, "voxel-check: %s: %s\n", label, err->message);
        return 3;
    }
    double mean, p99, max;
    size_t covered = covered_diff(a, b, view->width, view->height, view->background, &mean, &p99, &max);
    int ok = covered > n / 50 && mean <= o->tol_mean && p99 <= o->tol_p99;
    printf("%s: %zu of %zu pixels covered; over them max-channel |diff| mean %.3f p99 %.1f max %.0f "
           "(limits %.3f, %.1f) %s\n", label, covered, n, mean, p99, max, o->tol_mean, o->tol_p99,
           ok ? "ok" : "FAIL");
    return ok ? 0 : 1;
}

static int check_oit(sl_pipeline *pipe, const options *o, const sl_view *view, double radius)
{
    size_t n = (size_t)view->width * view->height;
    uint8_t *a = calloc(n, 4), *b = calloc(n, 4);
    sl_err err = {0};
    int rc = 3;
    if (!a || !b)
        goto done;
    /* Constant opacity; the same with alpha termination at 0.5 in both (they
     * stop at the same fragment: the first that takes alpha to >= 0.5). */
    rc = oit_pair(pipe, o, view, radius, "oit", a, b, &err);
    if (rc == 3)
        goto done;
    size_t white_full = 0, white_capped = 0;
    for (size_t i = 0; i < n; i++)
        white_full += a[4 * i] == 255 && a[4 * i + 1] == 255 && a[4 * i + 2] == 255;
    const char *half[2] = {"alpha_threshold=0.5", NULL};
    memcpy(extra_bools, half, sizeof half);
    int r2 = oit_pair(pipe, o, view, radius, "oit alpha_threshold 0.5", a, b, &err);
    /* Opacity transfer function (ramp over the colour attribute): both agree too. */
    const char *ramp[3] = {"attribute=0", "opacity_transfer=1", NULL};
    memcpy(extra_bools, ramp, sizeof ramp);
    int r3 = oit_pair(pipe, o, view, radius, "oit ramp", a, b, &err);
    extra_bools[0] = extra_bools[1] = NULL;
    rc = rc ? rc : (r2 ? r2 : r3);
    /* Overflow (Fig. 17): with room for only 2000 fragments the frame still
     * renders, pixels that lost fragments are white; with room, none are. */
    if (render_mem(pipe, "lines_oit", o, radius, o->opacity, 2000.0 * 12.0 / (1024.0 * 1024.0), view, a, NULL,
                   &err) != SL_OK) {
        fprintf(stderr, "voxel-check: capped lines_oit: %s\n", err.message);
        rc = 1;
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        white_capped += a[4 * i] == 255 && a[4 * i + 1] == 255 && a[4 * i + 2] == 255;
    printf("oit overflow: white pixels %zu with memory, %zu with a 2000-fragment pool\n", white_full, white_capped);
    if (white_full != 0 || white_capped < 100)
        rc = 1;
done:
    free(a);
    free(b);
    return rc;
}

static double mean_luma(const uint8_t *img, const uint8_t *mask_img, size_t n, const float bg[4])
{
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; i++) {
        int covered = 0;
        for (int c = 0; c < 3; c++)
            covered |= mask_img[4 * i + c] != (uint8_t)(bg[c] * 255.0f + 0.5f);
        if (!covered)
            continue;
        sum += 0.2126 * img[4 * i] + 0.7152 * img[4 * i + 1] + 0.0722 * img[4 * i + 2];
        count++;
    }
    return count ? sum / (double)count : 0.0;
}

/* Empty-space skipping changes nothing; shadows and AO only darken, and do darken. */
static int check_effects(sl_pipeline *pipe, const options *o, const sl_view *view, double radius)
{
    size_t n = (size_t)view->width * view->height;
    uint8_t *img[5];
    for (int k = 0; k < 5; k++)
        img[k] = calloc(n, 4);
    sl_err err = {0};
    int rc = 3;
    const char *sets[5][3] = {{"empty_space_skipping=0", NULL, NULL}, {"empty_space_skipping=1", NULL, NULL},
                              {"shadows=1", "shadow_strength=1", NULL}, {"ao=1", "ao_strength=1", NULL},
                              {"shadows=1", "shadow_strength=1", "shadow_mode=1"}};
    for (int k = 0; k < 5; k++) {
        if (!img[k])
            goto done;
        extra_bools[0] = sets[k][0];
        extra_bools[1] = sets[k][1];
        extra_bools[2] = sets[k][2];
        if (render(pipe, "voxel_lines", o, radius, 1.0, view, img[k], NULL, &err) != SL_OK) {
            fprintf(stderr, "voxel-check: effects %s: %s\n", sets[k][0], err.message);
            goto done;
        }
    }
    extra_bools[0] = extra_bools[1] = extra_bools[2] = NULL;
    size_t differ = 0, brighter[3] = {0, 0, 0};
    int maxd = 0;
    for (size_t i = 0; i < 4 * n; i++) {
        int d = abs((int)img[0][i] - (int)img[1][i]);
        differ += d != 0;
        maxd = d > maxd ? d : maxd;
        for (int k = 0; k < 3; k++)
            brighter[k] += (i % 4 != 3) && img[2 + k][i] > img[1][i] + 1;
    }
    double base = mean_luma(img[1], img[1], n, view->background);
    double shadow = mean_luma(img[2], img[1], n, view->background), ao = mean_luma(img[3], img[1], n, view->background);
    double hard = mean_luma(img[4], img[1], n, view->background);
    printf("effects: skipping changes %zu channels (max %d); mean luma base %.1f, soft shadows %.1f, AO %.1f, "
           "line shadows %.1f; channels brighter than base: %zu, %zu, %zu\n",
           differ, maxd, base, shadow, ao, hard, brighter[0], brighter[1], brighter[2]);
    rc = (differ <= n / 1000 && maxd <= 2 && base > 10.0 && shadow < 0.98 * base && ao < 0.98 * base &&
          hard < 0.98 * base && brighter[0] == 0 && brighter[1] == 0 && brighter[2] == 0) ? 0 : 1;
done:
    for (int k = 0; k < 5; k++)
        free(img[k]);
    return rc;
}

/* Renders voxel_lines with the NULL-terminated "name=value" list `set`. */
static sl_status render_set(sl_pipeline *pipe, const options *o, const sl_view *view, double radius,
                            double opacity, const char *const *set, uint8_t *rgba, sl_err *err)
{
    int k = 0;
    for (; set && set[k] && k < EXTRA_MAX - 1; k++)
        extra_bools[k] = set[k];
    extra_bools[k] = NULL;
    sl_status st = render(pipe, "voxel_lines", o, radius, opacity, view, rgba, NULL, err);
    extra_bools[0] = NULL;
    return st;
}

/* Channels that differ, and the largest difference. */
static size_t channels_differ(const uint8_t *a, const uint8_t *b, size_t n, int *maxd)
{
    size_t differ = 0;
    *maxd = 0;
    for (size_t i = 0; i < 4 * n; i++) {
        int d = abs((int)a[i] - (int)b[i]);
        differ += d != 0;
        *maxd = d > *maxd ? d : *maxd;
    }
    return differ;
}

/* Mean over covered pixels of the max-channel distance from the background
 * (how visible the lines are). */
static double mean_contrast(const uint8_t *img, size_t n, const float bg[4])
{
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; i++) {
        if (!covered_pixel(img, img, i, bg))
            continue;
        int m = 0;
        for (int c = 0; c < 3; c++) {
            int d = abs((int)img[4 * i + c] - (int)(bg[c] * 255.0f + 0.5f));
            m = d > m ? d : m;
        }
        sum += m;
        count++;
    }
    return count ? sum / (double)count : 0.0;
}

#define CHECK_FX(cond, ...) do { if (!(cond)) { printf("FAIL: " __VA_ARGS__); printf("\n"); rc = 1; } } while (0)

/* More per-frame parameters, each with a check that can fail:
 * - grid 4 (fewer occupancy levels than the default 4): skipping on = off, not empty;
 * - shadow_lod 2 darkens, never brightens, and differs from shadow_lod 0;
 * - opacity_by_distance (25 %) makes the lines fainter (< 95 % of the contrast);
 * - alpha_threshold T at 25 %: the image moves by at most (1 - T) x 255 (+1
 *   rounding) from T = 1, and T = 0.5 does change it;
 * - the ramp at opacity 1 is translucent, so alpha_threshold 0.5 changes the
 *   image there (the ray is not treated as opaque);
 * - neighbors = auto: an interactive frame equals `own`, a still frame
 *   equals `always`, and `own` differs from `always`;
 * - the density follows the opacity transfer function: ramp at t = 0.5 with
 *   opacity 0.5 gives the same per-line opacity (0.25) as constant 0.25, and
 *   with shadows and AO on the two frames must be identical (the density,
 *   shadows and AO weighted by the line's opacity); likewise t = 0.25 at
 *   opacity 1 (a scalar range change: a density pass, no re-voxelization).
 * - work skipped (voxel_lines.h counters, pipeline stats): a camera move
 *   re-prepares nothing, re-voxelizes nothing and recomputes neither density
 *   nor AO; opacity and radius recompute AO only; ao_strength and shadows
 *   nothing; the ramp (new attribute) re-voxelizes once and recomputes
 *   density and AO; a scalar range change recomputes density and AO only;
 *   a radius above 1 voxel re-voxelizes once (2 voxels of padding), and a
 *   smaller one again does not (the padding is kept).
 * `half` is an all-zero attribute (byte 0) whose colormap coordinate is set
 * exactly by the scalar range; `moved` is the view from another angle. */
static int check_effects_more(sl_pipeline *pipe, options *o, sl_view *view, const sl_view *moved, double radius,
                              int half, int work)
{
    size_t n = (size_t)view->width * view->height;
    enum { K = 4 };
    uint8_t *img[K];
    for (int k = 0; k < K; k++)
        img[k] = calloc(n, 4);
    sl_err err = {0};
    int rc = 0, maxd = 0;
    for (int k = 0; k < K; k++)
        if (!img[k])
            rc = 3;
    const float *bg = view->background;
#define R(op, img_, ...) do { const char *set_[] = {__VA_ARGS__, NULL}; \
        if (rc != 3 && render_set(pipe, o, view, radius, op, set_, img_, &err) != SL_OK) { \
            fprintf(stderr, "voxel-check: %s\n", err.message); rc = 3; } } while (0)
    if (work)
        goto work_steps;
    /* Grid 4: 6 voxels with padding, 3 occupancy levels at most. */
    int grid = o->grid;
    o->grid = 4;
    R(1.0, img[0], "empty_space_skipping=1");
    R(1.0, img[1], "empty_space_skipping=0");
    o->grid = grid;
    if (rc == 3)
        goto done;
    size_t d = channels_differ(img[0], img[1], n, &maxd), cov = 0;
    for (size_t i = 0; i < n; i++)
        cov += covered_pixel(img[0], img[0], i, bg);
    printf("grid 4: skipping changes %zu channels; %zu pixels covered\n", d, cov);
    CHECK_FX(d == 0 && cov > n / 50, "grid 4 with skipping");

    /* shadow_lod. */
    R(1.0, img[0], "shadows=0");
    R(1.0, img[1], "shadows=1", "shadow_strength=1", "shadow_lod=0");
    R(1.0, img[2], "shadows=1", "shadow_strength=1", "shadow_lod=2");
    if (rc == 3)
        goto done;
    size_t brighter = 0;
    for (size_t i = 0; i < 4 * n; i++)
        brighter += (i % 4 != 3) && img[2][i] > img[0][i] + 1;
    double base = mean_luma(img[0], img[0], n, bg), lod2 = mean_luma(img[2], img[0], n, bg);
    size_t d02 = channels_differ(img[1], img[2], n, &maxd);
    printf("shadow_lod 2: mean luma %.1f (base %.1f), %zu channels brighter, %zu channels differ from lod 0\n", lod2,
           base, brighter, d02);
    CHECK_FX(lod2 < 0.98 * base && brighter == 0 && d02 > n / 100, "shadow_lod 2");

    /* opacity_by_distance. */
    R(0.25, img[0], "opacity_by_distance=0");
    R(0.25, img[1], "opacity_by_distance=1");
    if (rc == 3)
        goto done;
    double c0 = mean_contrast(img[0], n, bg), c1 = mean_contrast(img[1], n, bg);
    printf("opacity_by_distance: contrast %.2f -> %.2f\n", c0, c1);
    CHECK_FX(c1 < 0.95 * c0 && c1 > 0.2 * c0, "opacity_by_distance");

    /* alpha_threshold (render_mem sets 1 unless overridden). */
    R(0.25, img[0], "alpha_threshold=1");
    R(0.25, img[1], "alpha_threshold=0.99");
    R(0.25, img[2], "alpha_threshold=0.5");
    if (rc == 3)
        goto done;
    int m99 = 0, m50 = 0;
    size_t d99 = channels_differ(img[0], img[1], n, &m99), d50 = channels_differ(img[0], img[2], n, &m50);
    printf("alpha_threshold: 0.99 changes %zu channels (max %d, bound %d), 0.5 changes %zu (max %d, bound %d)\n", d99,
           m99, (int)(0.01 * 255 + 1.5), d50, m50, (int)(0.5 * 255 + 1.5));
    CHECK_FX(m99 <= (int)(0.01 * 255 + 1.5) && m50 <= (int)(0.5 * 255 + 1.5) && d50 > n / 200, "alpha_threshold");

    /* Ramp at opacity 1: translucent, so the threshold applies. */
    R(1.0, img[0], "attribute=0", "opacity_transfer=1", "alpha_threshold=1");
    R(1.0, img[1], "attribute=0", "opacity_transfer=1", "alpha_threshold=0.5");
    if (rc == 3)
        goto done;
    size_t dr = channels_differ(img[0], img[1], n, &maxd);
    printf("ramp at opacity 1: alpha_threshold 0.5 changes %zu channels (max %d)\n", dr, maxd);
    CHECK_FX(dr > n / 200, "alpha termination with the ramp at opacity 1");

    /* neighbors = auto follows the frame quality. */
    sl_quality q = view->quality;
    view->quality = SL_QUALITY_INTERACTIVE;
    R(0.25, img[0], "neighbors=0");
    R(0.25, img[1], "neighbors=1");
    view->quality = SL_QUALITY_STILL;
    R(0.25, img[2], "neighbors=0");
    R(0.25, img[3], "neighbors=2");
    view->quality = q;
    if (rc == 3)
        goto done;
    size_t di = channels_differ(img[0], img[1], n, &maxd), ds_ = channels_differ(img[2], img[3], n, &maxd),
           doa = channels_differ(img[1], img[3], n, &maxd);
    printf("neighbors: interactive auto vs own %zu channels, still auto vs always %zu, own vs always %zu\n", di, ds_,
           doa);
    CHECK_FX(di == 0 && ds_ == 0 && doa > n / 200, "neighbors = auto");

    /* Density weighted by the transfer function (shadows and AO on). */
    char attr[32];
    snprintf(attr, sizeof attr, "attribute=%d", half);
    R(0.25, img[0], attr, "opacity_transfer=0", "scalar_min=-1", "scalar_max=1", "shadows=1", "shadow_strength=1",
      "ao=1");
    R(0.5, img[1], attr, "opacity_transfer=1", "scalar_min=-1", "scalar_max=1", "shadows=1", "shadow_strength=1",
      "ao=1");
    R(0.25, img[2], attr, "opacity_transfer=0", "scalar_min=-1", "scalar_max=1", "shadows=0", "ao=0");
    if (rc == 3)
        goto done;
    size_t dsh = channels_differ(img[0], img[2], n, &maxd);
    R(0.25, img[2], attr, "opacity_transfer=0", "scalar_min=-1", "scalar_max=3", "shadows=1", "shadow_strength=1",
      "ao=1");
    sl_voxel_lines_counters before, after;
    sl_voxel_lines_get_counters(&before);
    R(1.0, img[3], attr, "opacity_transfer=1", "scalar_min=-1", "scalar_max=3", "shadows=1", "shadow_strength=1",
      "ao=1");
    sl_voxel_lines_get_counters(&after);
    if (rc == 3)
        goto done;
    size_t dt = channels_differ(img[0], img[1], n, &maxd), dq = channels_differ(img[2], img[3], n, &maxd);
    printf("transfer function: ramp t=0.5 at 0.5 vs constant 0.25 differ in %zu channels, t=0.25 at 1 in %zu "
           "(shadows+AO change %zu channels); the range change cost %lu builds, %lu density passes\n", dt, dq, dsh,
           after.builds - before.builds, after.density_passes - before.density_passes);
    CHECK_FX(dt == 0 && dq == 0 && dsh > n / 50 && after.builds == before.builds &&
             after.density_passes == before.density_passes + 1, "density weighted by the transfer function");
    goto done;

work_steps:;
    /* Work per change. */
    struct step {
        const char *what;
        double opacity, radius_factor;
        const sl_view *view;
        const char *set[4];
        unsigned long builds, density, ao;
    } steps[] = {
        {"first frame with AO", 1.0, 1.0, view, {"ao=1", NULL}, 9, 9, 9}, /* 9: not checked */
        {"camera move", 1.0, 1.0, moved, {"ao=1", NULL}, 0, 0, 0},
        {"opacity", 0.5, 1.0, moved, {"ao=1", NULL}, 0, 0, 1},
        {"radius", 0.5, 1.25, moved, {"ao=1", NULL}, 0, 0, 1},
        {"ao_strength and shadows", 0.5, 1.25, moved, {"ao=1", "ao_strength=0.3", "shadows=1", NULL}, 0, 0, 0},
        {"camera move back", 0.5, 1.25, view, {"ao=1", "ao_strength=0.3", "shadows=1", NULL}, 0, 0, 0},
        {"ramp on attribute 0", 0.5, 1.25, view, {"ao=1", "attribute=0", "opacity_transfer=1", NULL}, 1, 1, 1},
        {"scalar range", 0.5, 1.25, view, {"ao=1", "attribute=0", "opacity_transfer=1", "scalar_max=1e-3"}, 0, 1, 1},
        {"camera move with the ramp", 0.5, 1.25, moved,
         {"ao=1", "attribute=0", "opacity_transfer=1", "scalar_max=1e-3"}, 0, 0, 0},
        /* ~1.5 voxels: the grid needs 2 voxels of padding (re-voxelized once). */
        {"radius above 1 voxel", 0.5, 4.0, moved,
         {"ao=1", "attribute=0", "opacity_transfer=1", "scalar_max=1e-3"}, 1, 1, 1},
        {"radius back (padding kept)", 0.5, 1.25, moved,
         {"ao=1", "attribute=0", "opacity_transfer=1", "scalar_max=1e-3"}, 0, 0, 1},
    };
    for (size_t k = 0; k < sizeof steps / sizeof steps[0] && rc != 3; k++) {
        const struct step *st = &steps[k];
        int j = 0;
        for (; j < 4 && st->set[j]; j++)
            extra_bools[j] = st->set[j];
        extra_bools[j] = NULL;
        sl_voxel_lines_counters c0, c1;
        sl_voxel_lines_get_counters(&c0);
        if (render(pipe, "voxel_lines", o, radius * st->radius_factor, st->opacity, st->view, img[0], NULL, &err) !=
            SL_OK) {
            fprintf(stderr, "voxel-check: %s: %s\n", st->what, err.message);
            rc = 3;
        }
        extra_bools[0] = NULL;
        sl_voxel_lines_get_counters(&c1);
        unsigned long b = c1.builds - c0.builds, dn = c1.density_passes - c0.density_passes,
                      ao = c1.ao_passes - c0.ao_passes;
        printf("work: %-26s prepared %d, builds %lu, density passes %lu, AO passes %lu\n", st->what,
               last_stats.prepared, b, dn, ao);
        if (st->builds != 9)
            CHECK_FX(last_stats.prepared == 0 && b == st->builds && dn == st->density && ao == st->ao,
                     "work for %s: want builds %lu, density %lu, AO %lu", st->what, st->builds, st->density, st->ao);
    }
#undef R
done:
    for (int k = 0; k < K; k++)
        free(img[k]);
    return rc;
}

/* tubes_mesh `opacity` (shared by name with voxel_lines and lines_oit):
 * explicitly 1 equals the default frame bit for bit (opaque path kept); at
 * o->opacity (< 1) it is fainter than opaque (< 80 % of the contrast) and
 * close to the sorted lines_oit frame over covered pixels (mean and p99 of
 * the max-channel difference within the tolerances: the only difference is
 * the blending order where tubes overlap). */
static int check_tubes(sl_pipeline *pipe, const options *o, const sl_view *view, double radius)
{
    size_t n = (size_t)view->width * view->height;
    uint8_t *a = calloc(n, 4), *b = calloc(n, 4), *c = calloc(n, 4);
    sl_err err = {0};
    int rc = 3;
    if (!a || !b || !c)
        goto done;
    /* render() sets opacity only where the schema has it: tubes_mesh must. */
    const sl_technique *t = sl_technique_find("tubes_mesh");
    sl_params p;
    sl_params_init(&p, t->params, t->param_count);
    if (sl_params_find(&p, "opacity") < 0) {
        printf("FAIL: tubes_mesh has no `opacity` parameter\n");
        rc = 1;
        goto done;
    }
    /* The default (opacity 1) against an explicit 1: render_mem always sets
     * it, so compare with a frame whose schema default was used instead. */
    sl_params_init(&p, t->params, t->param_count);
    double r = radius;
    sl_frame_stats stats;
    if (sl_params_set_numbers(&p, "radius", &r, 1, &err) != SL_OK ||
        sl_params_set_numbers(&p, "attribute", (double[]){-1}, 1, &err) != SL_OK ||
        sl_params_set_numbers(&p, "caps", (double[]){0}, 1, &err) != SL_OK ||
        sl_params_set_numbers(&p, "sides", (double[]){24}, 1, &err) != SL_OK ||
        sl_pipeline_set_technique(pipe, t, &p, &err) != SL_OK || sl_pipeline_render(pipe, view, 1, &stats, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: tubes_mesh: %s\n", err.message);
        goto done;
    }
    sl_pipeline_read_rgba(pipe, c, 1);
    if (render(pipe, "tubes_mesh", o, radius, 1.0, view, a, NULL, &err) != SL_OK ||
        render(pipe, "tubes_mesh", o, radius, o->opacity, view, b, NULL, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: tubes_mesh: %s\n", err.message);
        goto done;
    }
    int maxd = 0;
    size_t d1 = channels_differ(a, c, n, &maxd);
    double c_opaque = mean_contrast(a, n, view->background), c_blend = mean_contrast(b, n, view->background);
    printf("tubes_mesh opacity: 1 vs default differ in %zu channels; contrast opaque %.1f, at %.2f %.1f\n", d1,
           c_opaque, o->opacity, c_blend);
    rc = d1 == 0 && c_blend < 0.8 * c_opaque && c_blend > 0.1 * c_opaque ? 0 : 1;
    if (render(pipe, "lines_oit", o, radius, o->opacity, view, a, NULL, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: lines_oit: %s\n", err.message);
        rc = 3;
        goto done;
    }
    double mean, p99, max;
    size_t covered = covered_diff(a, b, view->width, view->height, view->background, &mean, &p99, &max);
    int ok = covered > n / 50 && mean <= o->tol_mean && p99 <= o->tol_p99;
    printf("tubes_mesh at %.2f vs lines_oit: %zu pixels covered; max-channel |diff| mean %.3f p99 %.1f max %.0f "
           "(limits %.3f, %.1f) %s\n", o->opacity, covered, mean, p99, max, o->tol_mean, o->tol_p99, ok ? "ok" : "FAIL");
    if (!ok)
        rc = 1;
done:
    free(a);
    free(b);
    free(c);
    return rc;
}

/* A lattice of lines exactly on voxel faces, edges and corners of a 16^3 grid
 * (grid = 16, bounds [0,16]^3 plus one padding voxel: grid coordinates are
 * the positions + 1): 12 lines along each axis at even coordinates, and two
 * corner diagonals; 9 points per line. `offset` is added in double. */
static sl_dataset *make_lattice(sl_vec3 offset)
{
    sl_err err;
    const int per = 9, lines = 3 * 12 + 2;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "lattice");
    if (!ds || sl_lines_alloc(&ds->lines, lines, (size_t)lines * per, 0, 0, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    ds->origin = offset;
    int l = 0;
    for (int axis = 0; axis < 3; axis++)
        for (int k = 0; k < 12; k++, l++) {
            int u = 2 + 4 * (k % 4), v = 2 + 4 * (k / 4) + (k % 2) * 2; /* faces (even) and edges */
            for (int i = 0; i < per; i++) {
                float p[3];
                p[axis] = 2.0f * i;
                p[(axis + 1) % 3] = (float)u;
                p[(axis + 2) % 3] = (float)v;
                memcpy(ds->lines.positions + 3 * ((size_t)l * per + i), p, sizeof p);
            }
        }
    for (int d = 0; d < 2; d++, l++)
        for (int i = 0; i < per; i++) {
            float t = 2.0f * i;
            float p[3] = {t, d ? 16.0f - t : t, t};
            memcpy(ds->lines.positions + 3 * ((size_t)l * per + i), p, sizeof p);
        }
    for (int k = 0; k <= lines; k++)
        ds->lines.line_offsets[k] = (uint32_t)(k * per);
    if (sl_dataset_finish_lines(ds, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

/* Renders the lattice (at `offset`, seen from `distance` bounding radii
 * through a `fov` degree lens) with voxel_lines opaque into rgba, and checks
 * its depth against tubes_mesh when dist_check. */
static int lattice_frame(sl_gpu *gpu, options *o, sl_vec3 offset, double distance, double fov, uint8_t *rgba,
                         int dist_check)
{
    sl_err err = {0};
    sl_pipeline *pipe = NULL;
    sl_dataset *ds = make_lattice(offset);
    if (!ds || sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return 3;
    }
    sl_view view = {.width = o->size, .height = o->size, .quality = SL_QUALITY_STILL,
                    .background = {0.1f, 0.1f, 0.12f, 1.0f}, .origin = ds->origin};
    sl_orbit orbit = {.azimuth_deg = 25, .elevation_deg = 30, .distance = distance, .fov_y_deg = fov};
    sl_vec3 lo = ds->bounds_min, hi = ds->bounds_max;
    sl_pipeline_set_dataset(pipe, ds);
    int rc = 0;
    if (sl_camera_from_orbit(&orbit, lo, hi, &view.camera, &err) != SL_OK ||
        sl_view_init(&view, sl_dataset_radius(sl_pipeline_dataset(pipe)), &err) != SL_OK) {
        rc = 2;
    } else if (dist_check) {
        rc = check_depth(pipe, o, &view, 0.3);
    }
    if (rc == 0 && render(pipe, "voxel_lines", o, 0.3, 1.0, &view, rgba, NULL, &err) != SL_OK)
        rc = 3;
    if (rc)
        fprintf(stderr, "voxel-check: lattice: %s\n", err.message);
    sl_pipeline_destroy(pipe);
    return rc;
}

/* Lines on faces, edges and corners against tubes_mesh, the same frame with
 * the data 1e6 units away from the world origin, and the lattice seen from
 * 400 bounding radii (~18 000 tube radii) through a 0.25 degree lens: its
 * depth against tubes_mesh (the capsule quadratics solved from the eye lost
 * every digit there: median 8.4-10.9 radii deep). */
static int check_stress(sl_gpu *gpu, options *o)
{
    size_t n = (size_t)o->size * o->size;
    uint8_t *a = calloc(n, 4), *b = calloc(n, 4);
    int rc = 3;
    if (a && b) {
        o->grid = 16;
        rc = lattice_frame(gpu, o, sl_v3(0, 0, 0), 2.0, 45.0, a, 1);
        if (rc == 0)
            rc = lattice_frame(gpu, o, sl_v3(1e6, -2e6, 3e6), 2.0, 45.0, b, 0);
        if (rc == 0) {
            size_t differ = 0;
            for (size_t i = 0; i < 4 * n; i++)
                differ += abs((int)a[i] - (int)b[i]) > 2;
            printf("stress: far-offset frame differs in %zu of %zu channels by > 2\n", differ, 4 * n);
            rc = differ <= n / 200 ? 0 : 1;
        }
        int far = lattice_frame(gpu, o, sl_v3(0, 0, 0), 400.0, 0.25, b, 1);
        rc = rc ? rc : far;
    }
    free(a);
    free(b);
    return rc;
}

/* Tubes of radius 1.5 voxels along the edges of the data's bounding box
 * ([0,16]^3, grid 16: h = 1): lines along x at y, z in {0, 16}, along y at
 * x = 8, z in {0, 16}, and one through the middle. Half of each edge tube lies
 * outside the data's box, up to 1.5 voxels beyond it; with one voxel of
 * padding the grid box cut them. Depth against tubes_mesh (still frame). */
static int check_edge(sl_gpu *gpu, options *o)
{
    sl_err err = {0};
    const int per = 9, lines = 7;
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, "edges");
    if (!ds || sl_lines_alloc(&ds->lines, lines, (size_t)lines * per, 0, 0, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return 3;
    }
    const float at[7][3] = {{0, 0, 0}, {0, 16, 0}, {0, 0, 16}, {0, 16, 16}, {8, 0, 0}, {8, 0, 16}, {0, 8, 8}};
    for (int l = 0; l < lines; l++) {
        int axis = l == 4 || l == 5 ? 1 : 0;
        for (int i = 0; i < per; i++) {
            float p[3] = {at[l][0], at[l][1], at[l][2]};
            p[axis] = 2.0f * i;
            memcpy(ds->lines.positions + 3 * ((size_t)l * per + i), p, sizeof p);
        }
    }
    for (int k = 0; k <= lines; k++)
        ds->lines.line_offsets[k] = (uint32_t)(k * per);
    sl_pipeline *pipe = NULL;
    if (sl_dataset_finish_lines(ds, &err) != SL_OK || sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: edge: %s\n", err.message);
        sl_dataset_destroy(ds);
        return 3;
    }
    sl_view view = {.width = o->size, .height = o->size, .quality = SL_QUALITY_STILL,
                    .background = {0.1f, 0.1f, 0.12f, 1.0f}, .origin = ds->origin};
    sl_orbit orbit = {.azimuth_deg = 20, .elevation_deg = 25, .distance = 2.0, .fov_y_deg = 45};
    sl_vec3 lo = ds->bounds_min, hi = ds->bounds_max;
    sl_pipeline_set_dataset(pipe, ds);
    int rc;
    o->grid = 16;
    if (sl_camera_from_orbit(&orbit, lo, hi, &view.camera, &err) != SL_OK ||
        sl_view_init(&view, sl_dataset_radius(sl_pipeline_dataset(pipe)), &err) != SL_OK) {
        fprintf(stderr, "voxel-check: edge: %s\n", err.message);
        rc = 2;
    } else {
        rc = check_depth(pipe, o, &view, 1.5);
    }
    sl_pipeline_destroy(pipe);
    return rc;
}

int main(int argc, char **argv)
{
    options o = {.mode = argc > 1 ? argv[1] : "", .size = 128, .quant = 256, .grid = 64, .opacity = 0.25,
                 .radius_frac = 0.004, .tol_median = 0.05, .tol_p95 = 0.3, .max_mismatch_pct = 8.0,
                 .max_mesh_only_pct = 100.0,
                 .tol_mean = 2.0, .tol_p99 = 40.0,
                 .data = "{\"generator\":\"tornado\",\"lines\":150,\"seed\":3}"};
    for (int i = 2; i + 1 < argc; i += 2) {
        const char *k = argv[i], *v = argv[i + 1];
        if (strcmp(k, "--data") == 0) o.data = v;
        else if (strcmp(k, "--size") == 0) o.size = atoi(v);
        else if (strcmp(k, "--quant") == 0) o.quant = atoi(v);
        else if (strcmp(k, "--grid") == 0) o.grid = atoi(v);
        else if (strcmp(k, "--opacity") == 0) o.opacity = atof(v);
        else if (strcmp(k, "--radius") == 0) o.radius_frac = atof(v);
        else if (strcmp(k, "--tol-median") == 0) o.tol_median = atof(v);
        else if (strcmp(k, "--tol-p95") == 0) o.tol_p95 = atof(v);
        else if (strcmp(k, "--max-mismatch-pct") == 0) o.max_mismatch_pct = atof(v);
        else if (strcmp(k, "--max-mesh-only-pct") == 0) o.max_mesh_only_pct = atof(v);
        else if (strcmp(k, "--tol-mean") == 0) o.tol_mean = atof(v);
        else if (strcmp(k, "--tol-p99") == 0) o.tol_p99 = atof(v);
        else if (strcmp(k, "--backend") == 0) o.backend = v;
        else {
            fprintf(stderr, "voxel-check: unknown option %s\n", k);
            return 2;
        }
    }
    if (strcmp(o.mode, "depth") != 0 && strcmp(o.mode, "oit") != 0 && strcmp(o.mode, "effects") != 0 &&
        strcmp(o.mode, "stress") != 0 && strcmp(o.mode, "tubes") != 0 && strcmp(o.mode, "work") != 0 &&
        strcmp(o.mode, "edge") != 0) {
        fprintf(stderr, "usage: voxel-check depth|oit|effects|work|tubes|stress|edge [options] (see the file header)\n");
        return 2;
    }
    if (o.size < 16 || o.size > 256) {
        fprintf(stderr, "voxel-check: --size must be in 16..256\n");
        return 2;
    }
    sl_err err = {0};
    sl_dataset *ds = NULL;
    if (sl_generate_json(o.data, &ds, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: %s\n", err.message);
        return 2;
    }
    sl_gpu *gpu = NULL;
    sl_pipeline *pipe = NULL;
    if (strcmp(o.mode, "stress") == 0 || strcmp(o.mode, "edge") == 0) {
        sl_dataset_destroy(ds);
        if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
            fprintf(stderr, "voxel-check: GPU: %s\n", err.message);
            return 3;
        }
        int src = strcmp(o.mode, "edge") == 0 ? check_edge(gpu, &o) : check_stress(gpu, &o);
        sl_gpu_destroy(gpu);
        return src;
    }
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK ||
        sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: GPU: %s\n", err.message);
        sl_dataset_destroy(ds);
        sl_gpu_destroy(gpu);
        return 3;
    }
    double radius = o.radius_frac * sl_dataset_radius(ds);
    int half = -1; /* effects: an all-zero attribute (see check_effects_more) */
    int work = strcmp(o.mode, "work") == 0;
    if (strcmp(o.mode, "effects") == 0) {
        if (!sl_lines_add_attribute(&ds->lines, "zero", 0, &err)) {
            fprintf(stderr, "voxel-check: %s\n", err.message);
            sl_dataset_destroy(ds);
            sl_pipeline_destroy(pipe);
            sl_gpu_destroy(gpu);
            return 3;
        }
        half = ds->lines.attribute_count - 1;
    }
    sl_view view = {.width = o.size, .height = o.size, .quality = SL_QUALITY_STILL,
                    .background = {0.1f, 0.1f, 0.12f, 1.0f}, .origin = ds->origin};
    sl_orbit orbit = {.azimuth_deg = 30, .elevation_deg = 20, .distance = 2.2, .fov_y_deg = 45};
    sl_vec3 lo = ds->bounds_min, hi = ds->bounds_max;
    sl_pipeline_set_dataset(pipe, ds); /* owned by the pipeline from here */
    int rc;
    if (sl_camera_from_orbit(&orbit, lo, hi, &view.camera, &err) != SL_OK ||
        sl_view_init(&view, sl_dataset_radius(sl_pipeline_dataset(pipe)), &err) != SL_OK) {
        fprintf(stderr, "voxel-check: camera: %s\n", err.message);
        rc = 2;
    } else if (strcmp(o.mode, "depth") == 0) {
        rc = check_depth(pipe, &o, &view, radius);
    } else if (strcmp(o.mode, "effects") == 0 || work) {
        rc = work ? 0 : check_effects(pipe, &o, &view, radius);
        sl_view moved = view;
        orbit.azimuth_deg = 75;
        orbit.elevation_deg = 35;
        int rm = 3;
        if (sl_camera_from_orbit(&orbit, lo, hi, &moved.camera, &err) == SL_OK &&
            sl_view_init(&moved, sl_dataset_radius(sl_pipeline_dataset(pipe)), &err) == SL_OK)
            rm = check_effects_more(pipe, &o, &view, &moved, radius, half, work);
        rc = rc ? rc : rm;
    } else if (strcmp(o.mode, "tubes") == 0) {
        rc = check_tubes(pipe, &o, &view, radius);
    } else {
        rc = check_oit(pipe, &o, &view, radius);
    }
    sl_pipeline_destroy(pipe);
    sl_gpu_destroy(gpu);
    return rc;
}
