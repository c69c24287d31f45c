/* voxel_check.c — GPU checks of `voxel_lines` against its baselines, on llvmpipe.
 *
 * usage: voxel-check depth [--data JSON] [--size N] [--quant N] [--grid N]
 *                          [--tol-median F] [--tol-p95 F] [--max-mismatch-pct P]
 *        voxel-check oit   [--data JSON] [--size N] [--opacity A] [--tol-mean F] [--tol-p99 F]
 *        voxel-check effects [--data JSON] [--size N]
 *        voxel-check stress [--size N] [depth tolerances]
 * depth: opaque voxel_lines eye distances against tubes_mesh on the same
 *   lines and radius (still frame, neighbour search on): on pixels both hit,
 *   the median and 95th percentile of |difference| in units of the tube
 *   radius must stay below the tolerances; pixels hit by one side only
 *   (silhouettes, the dropped end pieces) below max-mismatch-pct of the
 *   pixels either hits.
 * oit: transparent voxel_lines colour against lines_oit (no overflow) at the
 *   same opacity: mean and 99th percentile of the per-pixel max channel
 *   difference (0..255).
 * stress: a lattice of lines exactly on voxel faces, edges and corners
 *   (axis-parallel and through corners, grid 16) passes the depth check, and
 *   the same data 1e6 units from the origin gives the same image (<= 0.5 %
 *   of channels differ by > 2).
 * effects: empty-space skipping leaves the image unchanged (<= 0.1 % of
 *   channels, each by <= 2); full-strength shadows and AO darken the mean
 *   luma of covered pixels by more than 2 % and brighten no channel by > 1;
 *   so do hard shadows from representative lines (shadow_mode = lines).
 * Exit 0 pass, 1 fail, 2 bad input, 3 GPU failure. Render thread = main.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "pipeline/sl_pipeline.h"

typedef struct options {
    const char *mode, *data;
    int size, quant, grid;
    double opacity, radius_frac;
    double tol_median, tol_p95, max_mismatch_pct, tol_mean, tol_p99;
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
static const char *extra_bools[4]; /* NULL-terminated */

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
    }
    for (int i = 0; i < 4 && extra_bools[i] && st == SL_OK; i++) {
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
    sl_frame_stats stats;
    if (st == SL_OK)
        st = sl_pipeline_render(pipe, view, 1, &stats, err);
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
    size_t both = 0, either = 0, only = 0, bad = 0;
    for (size_t i = 0; i < n; i++) {
        int ha = a[i] > 0.0f, hb = b[i] > 0.0f;
        if (!isfinite(a[i]) || !isfinite(b[i]))
            bad++;
        either += ha || hb;
        only += ha != hb;
        if (ha && hb)
            diff[both++] = fabsf(a[i] - b[i]) / (float)radius;
    }
    qsort(diff, both, sizeof *diff, cmp_float);
    double med = both ? diff[both / 2] : INFINITY, p95 = both ? diff[(size_t)(0.95 * (both - 1))] : INFINITY;
    double mismatch = either ? 100.0 * (double)only / (double)either : 100.0;
    printf("depth: %zu pixels both hit, |d| / radius median %.4f p95 %.4f max %.4f; one side only %.2f%% "
           "(limits %.4f, %.4f, %.2f%%)\n",
           both, med, p95, both ? diff[both - 1] : 0.0, mismatch, o->tol_median, o->tol_p95, o->max_mismatch_pct);
    rc = (both > n / 50 && bad == 0 && med <= o->tol_median && p95 <= o->tol_p95 &&
          mismatch <= o->max_mismatch_pct) ? 0 : 1;
done:
    free(a);
    free(b);
    free(diff);
    return rc;
}

static int check_oit(sl_pipeline *pipe, const options *o, const sl_view *view, double radius)
{
    size_t n = (size_t)view->width * view->height;
    uint8_t *a = calloc(n, 4), *b = calloc(n, 4);
    float *diff = calloc(n, sizeof *diff);
    sl_err err = {0};
    int rc = 3;
    if (!a || !b || !diff)
        goto done;
    if (render(pipe, "lines_oit", o, radius, o->opacity, view, a, NULL, &err) != SL_OK ||
        render(pipe, "voxel_lines", o, radius, o->opacity, view, b, NULL, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: %s\n", err.message);
        goto done;
    }
    double sum = 0.0;
    size_t covered = 0;
    for (size_t i = 0; i < n; i++) {
        int m = 0, touched = 0;
        for (int c = 0; c < 3; c++) {
            int d = abs((int)a[4 * i + c] - (int)b[4 * i + c]);
            m = d > m ? d : m;
            touched |= a[4 * i + c] != (uint8_t)(view->background[c] * 255.0f + 0.5f);
        }
        diff[i] = (float)m;
        sum += m;
        covered += touched;
    }
    qsort(diff, n, sizeof *diff, cmp_float);
    double mean = sum / (double)n, p99 = diff[(size_t)(0.99 * (n - 1))];
    printf("oit: %zu pixels covered; max-channel |diff| mean %.3f p99 %.1f max %.0f (limits %.3f, %.1f)\n", covered,
           mean, p99, diff[n - 1], o->tol_mean, o->tol_p99);
    rc = (covered > n / 50 && mean <= o->tol_mean && p99 <= o->tol_p99) ? 0 : 1;
    /* Overflow (Fig. 17): with room for only 2000 fragments the frame still
     * renders, pixels that lost fragments are white; with room, none are. */
    size_t white_full = 0, white_capped = 0;
    for (size_t i = 0; i < n; i++)
        white_full += a[4 * i] == 255 && a[4 * i + 1] == 255 && a[4 * i + 2] == 255;
    if (render_mem(pipe, "lines_oit", o, radius, o->opacity, 2000.0 * 12.0 / (1024.0 * 1024.0), view, a, NULL,
                   &err) != SL_OK) {
        fprintf(stderr, "voxel-check: capped lines_oit: %s\n", err.message);
        rc = 1;
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        white_capped += a[4 * i] == 255 && a[4 * i + 1] == 255 && a[4 * i + 2] == 255;
    /* Opacity transfer function (ramp over the colour attribute): both agree too. */
    const char *ramp[3] = {"attribute=0", "opacity_transfer=1", NULL};
    memcpy(extra_bools, ramp, sizeof ramp);
    uint8_t *c = calloc(n, 4), *d = calloc(n, 4);
    double ramp_sum = 0.0;
    if (!c || !d || render(pipe, "lines_oit", o, radius, o->opacity, view, c, NULL, &err) != SL_OK ||
        render(pipe, "voxel_lines", o, radius, o->opacity, view, d, NULL, &err) != SL_OK) {
        fprintf(stderr, "voxel-check: ramp: %s\n", err.message);
        rc = 1;
    } else {
        for (size_t i = 0; i < n; i++) {
            int m = 0;
            for (int ch = 0; ch < 3; ch++) {
                int dd = abs((int)c[4 * i + ch] - (int)d[4 * i + ch]);
                m = dd > m ? dd : m;
            }
            ramp_sum += m;
        }
        printf("oit ramp: max-channel |diff| mean %.3f (limit %.3f)\n", ramp_sum / (double)n, o->tol_mean);
        if (ramp_sum / (double)n > o->tol_mean)
            rc = 1;
    }
    extra_bools[0] = extra_bools[1] = NULL;
    free(c);
    free(d);
    printf("oit overflow: white pixels %zu with memory, %zu with a 2000-fragment pool\n", white_full, white_capped);
    if (white_full != 0 || white_capped < 100)
        rc = 1;
done:
    free(a);
    free(b);
    free(diff);
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

/* Renders the lattice (at `offset`) with voxel_lines opaque into rgba, and
 * checks its depth against tubes_mesh when dist_check. */
static int lattice_frame(sl_gpu *gpu, options *o, sl_vec3 offset, uint8_t *rgba, int dist_check)
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
    sl_orbit orbit = {.azimuth_deg = 25, .elevation_deg = 30, .distance = 2.0, .fov_y_deg = 45};
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

/* Lines on faces, edges and corners against tubes_mesh, and the same frame
 * with the data 1e6 units away from the world origin. */
static int check_stress(sl_gpu *gpu, options *o)
{
    size_t n = (size_t)o->size * o->size;
    uint8_t *a = calloc(n, 4), *b = calloc(n, 4);
    int rc = 3;
    if (a && b) {
        o->grid = 16;
        rc = lattice_frame(gpu, o, sl_v3(0, 0, 0), a, 1);
        if (rc == 0)
            rc = lattice_frame(gpu, o, sl_v3(1e6, -2e6, 3e6), b, 0);
        if (rc == 0) {
            size_t differ = 0;
            for (size_t i = 0; i < 4 * n; i++)
                differ += abs((int)a[i] - (int)b[i]) > 2;
            printf("stress: far-offset frame differs in %zu of %zu channels by > 2\n", differ, 4 * n);
            rc = differ <= n / 200 ? 0 : 1;
        }
    }
    free(a);
    free(b);
    return rc;
}

int main(int argc, char **argv)
{
    options o = {.mode = argc > 1 ? argv[1] : "", .size = 128, .quant = 256, .grid = 64, .opacity = 0.25,
                 .radius_frac = 0.004, .tol_median = 0.05, .tol_p95 = 0.3, .max_mismatch_pct = 8.0,
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
        else if (strcmp(k, "--tol-mean") == 0) o.tol_mean = atof(v);
        else if (strcmp(k, "--tol-p99") == 0) o.tol_p99 = atof(v);
        else {
            fprintf(stderr, "voxel-check: unknown option %s\n", k);
            return 2;
        }
    }
    if (strcmp(o.mode, "depth") != 0 && strcmp(o.mode, "oit") != 0 && strcmp(o.mode, "effects") != 0 &&
        strcmp(o.mode, "stress") != 0) {
        fprintf(stderr, "usage: voxel-check depth|oit|effects|stress [options] (see the file header)\n");
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
    if (strcmp(o.mode, "stress") == 0) {
        sl_dataset_destroy(ds);
        if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
            fprintf(stderr, "voxel-check: GPU: %s\n", err.message);
            return 3;
        }
        int src = check_stress(gpu, &o);
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
    } else if (strcmp(o.mode, "effects") == 0) {
        rc = check_effects(pipe, &o, &view, radius);
    } else {
        rc = check_oit(pipe, &o, &view, radius);
    }
    sl_pipeline_destroy(pipe);
    sl_gpu_destroy(gpu);
    return rc;
}
