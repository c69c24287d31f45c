/* volume_check.c — volume_dvr frames against the CPU reference (tests/support/volume_reference.h).
 *
 * usage: volume-check compare --dataset SRC [--size N] [--orbit AZ,EL,DIST] --params JSON
 *                     [--tol-mean M] [--tol-max X] [--depth-tol F] [--max-miss-pct P]
 *                     [--ref-step S] [--ref-uncorrected 1] [--skipping-equal 1] [--max-samples N]
 *                     [--min-skipped F] [--interactive 1] [--save PREFIX]
 *        volume-check work --dataset SRC
 * SRC: generator JSON ({"generator": ...}), a file path, or synthetic:NAME
 * (constant, line, slab, aniso, huge, nan). compare renders one frame with
 * the pipeline (no MSAA, jitter off unless the params say otherwise) and the
 * reference with the same camera, transfer function (point form only), mode,
 * step (or --ref-step; --ref-uncorrected drops the reference's opacity
 * correction, to see the check fail), alpha threshold, isovalue,
 * interpolation and clip box; prints mean and max |ΔRGB| over every channel
 * of every pixel (0..255 units) and, for iso, the distance error over pixels
 * both hit relative to the box diagonal and the pixels hit by one only.
 * --skipping-equal also renders with empty-space skipping off: identical
 * image required. --interactive renders the frame as an interactive one
 * (view.quality; the reference still takes the params' step or --ref-step). work checks sl_volume_counters and re-prepares across
 * camera moves and parameter changes. Exit 0 ok, 1 "check failed: ...", 2 setup.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset_open.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "image/sl_image.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "volume/sl_volume.h"
#include "volume_reference.h"

static int failures;

#define FAIL(...) do { fprintf(stderr, "volume-check: check failed: " __VA_ARGS__); fputc('\n', stderr); failures++; } while (0)

/* A small synthetic volume (f32) for the stress cases. */
static sl_dataset *synthetic(const char *name, sl_err *err)
{
    int dims[3] = {16, 16, 16};
    double spacing[3] = {1, 1, 1};
    if (strcmp(name, "line") == 0) dims[0] = dims[1] = 1, dims[2] = 32;
    else if (strcmp(name, "slab") == 0) dims[0] = dims[1] = 32, dims[2] = 1;
    else if (strcmp(name, "aniso") == 0) dims[0] = dims[1] = 32, dims[2] = 12, spacing[2] = 4;
    else if (strcmp(name, "huge") == 0 || strcmp(name, "nan") == 0 || strcmp(name, "constant") == 0) dims[0] = dims[1] = dims[2] = 24;
    else {
        sl_err_set(err, SL_ERR_INVALID, "no synthetic volume '%s'", name);
        return NULL;
    }
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, name);
    if (!ds || sl_volume_alloc(&ds->volume, dims, 1, SL_VOXEL_F32, err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    memcpy(ds->volume.spacing, spacing, sizeof spacing);
    ds->origin = sl_v3(-3.0, 2.0, 0.5);
    float *v = ds->volume.data;
    size_t i = 0;
    for (int z = 0; z < dims[2]; z++)
        for (int y = 0; y < dims[1]; y++)
            for (int x = 0; x < dims[0]; x++, i++) {
                double cx = (x + 0.5) / dims[0] - 0.5, cy = (y + 0.5) / dims[1] - 0.5, cz = (z + 0.5) / dims[2] - 0.5;
                double r = sqrt(cx * cx + cy * cy + cz * cz);
                double f = 0.5 + 0.5 * cos(9.0 * r) * (0.6 + 0.4 * sin(5.0 * cx + 2.0 * cz));
                if (strcmp(name, "constant") == 0)
                    f = 0.5;
                else if (strcmp(name, "huge") == 0 && (x * 7 + y * 3 + z) % 11 == 0)
                    f = 1e30;
                else if (strcmp(name, "nan") == 0 && r < 0.25)
                    f = NAN;
                v[i] = (float)f;
            }
    if (sl_dataset_finish_volume(ds, err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

static sl_dataset *open_dataset(const char *src, sl_err *err)
{
    sl_dataset *ds = NULL;
    if (strncmp(src, "synthetic:", 10) == 0)
        return synthetic(src + 10, err);
    return sl_dataset_open(src, NULL, &ds, err) == SL_OK ? ds : NULL;
}

static int make_view(const sl_dataset *ds, const double orbit[3], int size, sl_view *view, sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = view->height = size;
    const float bg[4] = {0.1f, 0.1f, 0.12f, 1.0f};
    memcpy(view->background, bg, sizeof bg);
    view->origin = ds->origin;
    sl_orbit o = {orbit[0], orbit[1], orbit[2], 45.0};
    if (sl_camera_from_orbit(&o, ds->bounds_min, ds->bounds_max, &view->camera, err) != SL_OK)
        return 0;
    return sl_view_init(view, sl_dataset_radius(ds), err) == SL_OK;
}

typedef struct options {
    const char *cmd, *dataset, *params, *save;
    int size, skipping_equal, ref_uncorrected, interactive;
    double orbit[3], tol_mean, tol_max, depth_tol, max_miss_pct, ref_step, max_samples, min_skipped;
} options;

static int parse(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->size = 96;
    o->orbit[0] = 30, o->orbit[1] = 20, o->orbit[2] = 2.5;
    o->tol_mean = 1.0, o->tol_max = 4.0, o->depth_tol = -1, o->max_miss_pct = 0.5;
    o->max_samples = -1, o->min_skipped = -1;
    o->params = "{}";
    if (argc < 2)
        return 0;
    o->cmd = argv[1];
    for (int i = 2; i + 1 < argc; i += 2) {
        const char *k = argv[i], *v = argv[i + 1];
        if (strcmp(k, "--dataset") == 0) o->dataset = v;
        else if (strcmp(k, "--params") == 0) o->params = v;
        else if (strcmp(k, "--save") == 0) o->save = v;
        else if (strcmp(k, "--size") == 0) o->size = atoi(v);
        else if (strcmp(k, "--orbit") == 0) sscanf(v, "%lf,%lf,%lf", &o->orbit[0], &o->orbit[1], &o->orbit[2]);
        else if (strcmp(k, "--tol-mean") == 0) o->tol_mean = atof(v);
        else if (strcmp(k, "--tol-max") == 0) o->tol_max = atof(v);
        else if (strcmp(k, "--depth-tol") == 0) o->depth_tol = atof(v);
        else if (strcmp(k, "--max-miss-pct") == 0) o->max_miss_pct = atof(v);
        else if (strcmp(k, "--ref-step") == 0) o->ref_step = atof(v);
        else if (strcmp(k, "--max-samples") == 0) o->max_samples = atof(v);
        else if (strcmp(k, "--min-skipped") == 0) o->min_skipped = atof(v);
        else if (strcmp(k, "--skipping-equal") == 0) o->skipping_equal = atoi(v);
        else if (strcmp(k, "--ref-uncorrected") == 0) o->ref_uncorrected = atoi(v);
        else if (strcmp(k, "--interactive") == 0) o->interactive = atoi(v);
        else return 0;
    }
    return o->dataset && o->size > 0 && o->size <= 1024;
}

typedef struct rig {
    sl_gpu *gpu;
    sl_pipeline *pipe;
    const sl_technique *tech;
    sl_params params;
} rig;

static int rig_init(rig *r, const options *o, sl_err *err)
{
    memset(r, 0, sizeof *r);
    sl_dataset *ds = open_dataset(o->dataset, err);
    if (!ds)
        return 0;
    r->tech = sl_technique_find("volume_dvr");
    sl_params_init(&r->params, r->tech->params, r->tech->param_count);
    sl_params_set_numbers(&r->params, "jitter", &(double){0}, 1, err);
    cJSON *patch = cJSON_Parse(o->params);
    if (!patch || sl_params_apply_json(&r->params, patch, err) != SL_OK) {
        if (!patch)
            sl_err_set(err, SL_ERR_INVALID, "--params is not JSON");
        cJSON_Delete(patch);
        sl_dataset_destroy(ds);
        return 0;
    }
    cJSON_Delete(patch);
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &r->gpu, err) != SL_OK ||
        sl_pipeline_create(r->gpu, &r->pipe, err) != SL_OK) {
        sl_dataset_destroy(ds);
        return 0;
    }
    sl_pipeline_set_dataset(r->pipe, ds);
    return sl_pipeline_set_technique(r->pipe, r->tech, &r->params, err) == SL_OK;
}

static void rig_deinit(rig *r)
{
    sl_pipeline_destroy(r->pipe);
    sl_gpu_destroy(r->gpu);
}

static int frame(rig *r, const sl_view *view, uint8_t *rgba, float *dist, sl_frame_stats *stats, sl_err *err)
{
    if (sl_pipeline_set_technique(r->pipe, r->tech, &r->params, err) != SL_OK ||
        sl_pipeline_render(r->pipe, view, 1, stats, err) != SL_OK)
        return 0;
    if (rgba)
        sl_pipeline_read_rgba(r->pipe, rgba, 1);
    if (dist)
        sl_pipeline_read_distance(r->pipe, view, dist);
    return 1;
}

/* Distances of the frame (gd) and the reference (rd): max and mean error over
 * the pixels both hit, relative to the box diagonal, and the pixels hit by one only. */
static void compare_depth(const options *o, const sl_dataset *ds, const volume_ref_desc *d, const float *gd,
                          const float *rd, size_t n, const char *what)
{
    double diag = 0.0;
    for (int a = 0; a < 3; a++) {
        double e = ds->volume.dims[a] > 1 ? (ds->volume.dims[a] - 1) * ds->volume.spacing[a] : ds->volume.spacing[a];
        diag += e * e;
    }
    diag = sqrt(diag);
    double worst = 0.0, sum = 0.0;
    size_t both = 0, one = 0, hit = 0;
    for (size_t i = 0; i < n; i++) {
        int a = gd[i] > 0.0f, b = rd[i] > 0.0f;
        hit += (size_t)(a || b);
        if (a && b) {
            double e = fabs((double)gd[i] - rd[i]) / diag;
            worst = e > worst ? e : worst;
            sum += e;
            both++;
        } else if (a != b) {
            one++;
        }
    }
    double miss_pct = hit ? 100.0 * one / hit : 0.0;
    printf("volume-check: %s %s step %g: distance error / diagonal max %.3g mean %.3g over %zu pixels hit by both; "
           "hit by one only %zu (%.2f %% of %zu hit)\n", o->dataset, what, d->step, worst, both ? sum / both : 0.0, both,
           one, miss_pct, hit);
    if (both == 0)
        FAIL("%s: no pixel has a distance", what);
    if (o->depth_tol >= 0 && worst > o->depth_tol)
        FAIL("%s: distance error %.3g of the diagonal > %g", what, worst, o->depth_tol);
    if (miss_pct > o->max_miss_pct)
        FAIL("%s: %.2f %% of the pixels with a distance have one in one image only > %g %%", what, miss_pct,
             o->max_miss_pct);
}

static int compare(const options *o)
{
    sl_err err = {0};
    rig r;
    if (!rig_init(&r, o, &err)) {
        fprintf(stderr, "volume-check: %s\n", err.message);
        rig_deinit(&r);
        return 2;
    }
    const sl_dataset *ds = sl_pipeline_dataset(r.pipe);
    const sl_transfer_function *tf = sl_params_transfer(&r.params, "transfer_function");
    if (tf->colormap >= 0) {
        fprintf(stderr, "volume-check: give the transfer function as points\n");
        rig_deinit(&r);
        return 2;
    }
    if (sl_params_choice(&r.params, "mode") == 2 && sl_params_is_auto(&r.params, "isovalue")) {
        fprintf(stderr, "volume-check: give the isovalue as a number (the reference resolves no \"auto\")\n");
        rig_deinit(&r);
        return 2;
    }
    sl_view view;
    if (!make_view(ds, o->orbit, o->size, &view, &err)) {
        fprintf(stderr, "volume-check: %s\n", err.message);
        rig_deinit(&r);
        return 2;
    }
    if (o->interactive)
        view.quality = SL_QUALITY_INTERACTIVE;
    size_t n = (size_t)o->size * o->size;
    uint8_t *gpu = malloc(n * 4), *ref = malloc(n * 4), *gpu2 = malloc(n * 4);
    float *gd = malloc(n * sizeof *gd), *rd = malloc(n * sizeof *rd);
    sl_frame_stats st;
    int rc = 2;
    if (!gpu || !ref || !gpu2 || !gd || !rd || !frame(&r, &view, gpu, gd, &st, &err)) {
        fprintf(stderr, "volume-check: %s\n", err.message);
        goto done;
    }
    float cmin[3], cmax[3];
    sl_params_vec3(&r.params, "clip_min", cmin);
    sl_params_vec3(&r.params, "clip_max", cmax);
    volume_ref_desc d = {
        .view = &view, .volume = ds, .tf_count = tf->count, .tf = (const double (*)[5])tf->point,
        .mode = (volume_ref_mode)sl_params_choice(&r.params, "mode"),
        .step = o->ref_step > 0 ? o->ref_step : sl_params_float(&r.params, "step"),
        .alpha_stop = sl_params_float(&r.params, "alpha_threshold"), .iso = sl_params_float(&r.params, "isovalue"),
        .nearest = sl_params_choice(&r.params, "interpolation") == 1,
        .clip_min = {cmin[0], cmin[1], cmin[2]}, .clip_max = {cmax[0], cmax[1], cmax[2]},
        .uncorrected = o->ref_uncorrected,
    };
    if (volume_ref_render(&d, ref, rd) != 0) {
        fprintf(stderr, "volume-check: the reference refused the input\n");
        goto done;
    }
    if (o->save) {
        char path[4096];
        snprintf(path, sizeof path, "%s.gpu.png", o->save);
        sl_png_write(path, gpu, o->size, o->size, &err);
        snprintf(path, sizeof path, "%s.ref.png", o->save);
        sl_png_write(path, ref, o->size, o->size, &err);
    }
    rc = 0;
    if (d.mode == VOLUME_REF_COMPOSITE && o->depth_tol >= 0)
        compare_depth(o, ds, &d, gd, rd, n, "composite (alpha > 0.5)");
    if (d.mode != VOLUME_REF_ISO) {
        double sum = 0.0;
        int mx = 0;
        size_t covered = 0;
        for (size_t i = 0; i < n; i++) {
            int px = 0;
            for (int c = 0; c < 3; c++) {
                int e = abs((int)gpu[4 * i + c] - (int)ref[4 * i + c]);
                sum += e;
                mx = e > mx ? e : mx;
                px |= ref[4 * i + c] != (c == 2 ? 31 : 26);
            }
            covered += (size_t)px;
        }
        double mean = sum / (3.0 * n);
        printf("volume-check: %s mode %d step %g: mean |dRGB| %.4f, max %d (0..255) over %zu pixels (%zu drawn in "
               "the reference); ray samples %.0f, skipped %.0f (%.1f %%)\n", o->dataset, (int)d.mode, d.step, mean, mx,
               n, covered, st.render.samples, st.render.samples_skipped,
               100.0 * st.render.samples_skipped / fmax(1.0, st.render.samples + st.render.samples_skipped));
        if (mean > o->tol_mean)
            FAIL("mean |dRGB| %.4f > %g", mean, o->tol_mean);
        if (mx > o->tol_max)
            FAIL("max |dRGB| %d > %g", mx, o->tol_max);
    } else {
        compare_depth(o, ds, &d, gd, rd, n, "iso");
    }
    if (o->max_samples >= 0 && st.render.samples > o->max_samples)
        FAIL("%.0f ray samples > %g", st.render.samples, o->max_samples);
    double frac = st.render.samples_skipped / fmax(1.0, st.render.samples + st.render.samples_skipped);
    if (o->min_skipped >= 0 && frac < o->min_skipped)
        FAIL("skipped fraction %.3f < %g", frac, o->min_skipped);
    if (o->skipping_equal) {
        sl_params_set_numbers(&r.params, "empty_space_skipping", &(double){0}, 1, &err);
        sl_frame_stats st2;
        if (!frame(&r, &view, gpu2, NULL, &st2, &err)) {
            fprintf(stderr, "volume-check: %s\n", err.message);
            rc = 2;
            goto done;
        }
        int mx = 0;
        for (size_t i = 0; i < 4 * n; i++) {
            int e = abs((int)gpu[i] - (int)gpu2[i]);
            mx = e > mx ? e : mx;
        }
        printf("volume-check: skipping off: max |dRGB| %d against skipping on; samples %.0f (on: %.0f + %.0f skipped)\n",
               mx, st2.render.samples, st.render.samples, st.render.samples_skipped);
        if (mx != 0)
            FAIL("empty-space skipping changed the image (max |dRGB| %d)", mx);
        if (st2.render.samples_skipped != 0)
            FAIL("skipping off still skipped %.0f samples", st2.render.samples_skipped);
    }
    if (failures)
        rc = 1;
done:
    free(gpu);
    free(ref);
    free(gpu2);
    free(gd);
    free(rd);
    rig_deinit(&r);
    return rc;
}

static int counters_equal(const sl_volume_counters *a, const sl_volume_counters *b)
{
    return a->texture_uploads == b->texture_uploads && a->minmax_builds == b->minmax_builds &&
           a->mask_builds == b->mask_builds && a->tf_uploads == b->tf_uploads;
}

/* Applies a JSON patch, renders, and checks prepared and the counter deltas
 * (texture, minmax, mask, tf, gradient). */
static void work_step(rig *r, const sl_view *view, const char *patch, const long want[5], const char *what)
{
    sl_err err = {0};
    cJSON *p = cJSON_Parse(patch);
    if (sl_params_apply_json(&r->params, p, &err) != SL_OK)
        FAIL("%s: %s", what, err.message);
    cJSON_Delete(p);
    sl_volume_counters before, after;
    sl_volume_get_counters(&before);
    sl_frame_stats st;
    if (!frame(r, view, NULL, NULL, &st, &err)) {
        FAIL("%s: %s", what, err.message);
        return;
    }
    sl_volume_get_counters(&after);
    long got[5] = {(long)(after.texture_uploads - before.texture_uploads),
                   (long)(after.minmax_builds - before.minmax_builds),
                   (long)(after.mask_builds - before.mask_builds), (long)(after.tf_uploads - before.tf_uploads),
                   (long)(after.gradient_builds - before.gradient_builds)};
    printf("volume-check: %s: prepared %d, volume uploads %ld, min-max builds %ld, mask builds %ld, TF uploads %ld, "
           "gradient builds %ld\n", what, st.prepared, got[0], got[1], got[2], got[3], got[4]);
    if (st.prepared)
        FAIL("%s re-prepared", what);
    for (int k = 0; k < 5; k++)
        if (got[k] != want[k])
            FAIL("%s: counter %d moved by %ld, expected %ld", what, k, got[k], want[k]);
}

static int work(const options *o)
{
    sl_err err = {0};
    rig r;
    if (!rig_init(&r, o, &err)) {
        fprintf(stderr, "volume-check: %s\n", err.message);
        rig_deinit(&r);
        return 2;
    }
    const sl_dataset *ds = sl_pipeline_dataset(r.pipe);
    sl_view a, b;
    double orbit_b[3] = {o->orbit[0] + 70, o->orbit[1] - 10, o->orbit[2] * 0.8};
    if (!make_view(ds, o->orbit, 48, &a, &err) || !make_view(ds, orbit_b, 48, &b, &err)) {
        fprintf(stderr, "volume-check: %s\n", err.message);
        rig_deinit(&r);
        return 2;
    }
    sl_volume_counters c0, c1;
    sl_volume_get_counters(&c0);
    sl_frame_stats st;
    if (!frame(&r, &a, NULL, NULL, &st, &err)) {
        fprintf(stderr, "volume-check: %s\n", err.message);
        rig_deinit(&r);
        return 2;
    }
    sl_volume_get_counters(&c1);
    if (!st.prepared || c1.texture_uploads != c0.texture_uploads + 1 || c1.minmax_builds != c0.minmax_builds + 1)
        FAIL("the first frame must prepare, upload the volume and build the min-max grid once");
    (void)counters_equal;
    work_step(&r, &b, "{}", (const long[5]){0, 0, 0, 0, 0}, "camera move");
    work_step(&r, &a, "{}", (const long[5]){0, 0, 0, 0, 0}, "camera back");
    work_step(&r, &a, "{\"transfer_function\": [[0, 0, 0, 0, 0], [0.6, 1, 0.5, 0, 0.3], [1, 1, 1, 1, 0.8]]}",
              (const long[5]){0, 0, 1, 1, 0}, "transfer function change");
    work_step(&r, &b, "{}", (const long[5]){0, 0, 0, 0, 0}, "camera move after the TF change");
    work_step(&r, &a, "{\"step\": 0.3, \"shading\": true, \"interpolation\": \"nearest\", \"clip_max\": [0.8, 1, 1]}",
              (const long[5]){0, 0, 0, 0, 0}, "step, shading, interpolation, clip");
    work_step(&r, &a, "{\"gradient\": \"texture\"}", (const long[5]){0, 0, 0, 0, 1}, "gradient texture, first use");
    work_step(&r, &b, "{\"transfer_function\": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 0.5]]}", (const long[5]){0, 0, 1, 1, 0},
              "TF change with the gradient texture");
    work_step(&r, &a, "{\"gradient\": \"on_the_fly\"}", (const long[5]){0, 0, 0, 0, 0}, "gradient on the fly");
    work_step(&r, &a, "{\"gradient\": \"texture\"}", (const long[5]){0, 0, 0, 0, 0}, "gradient texture again");
    work_step(&r, &a, "{\"mode\": \"iso\"}", (const long[5]){0, 0, 1, 0, 0}, "mode iso");
    work_step(&r, &a, "{\"isovalue\": 0.4}", (const long[5]){0, 0, 1, 0, 0}, "isovalue change");
    work_step(&r, &a, "{\"mode\": \"mip\"}", (const long[5]){0, 0, 1, 0, 0}, "mode mip");
    work_step(&r, &b, "{}", (const long[5]){0, 0, 0, 0, 0}, "camera move in mip");
    rig_deinit(&r);
    return failures ? 1 : 0;
}

int main(int argc, char **argv)
{
    options o;
    if (!parse(argc, argv, &o)) {
        fprintf(stderr, "usage: volume-check compare|work --dataset SRC [options] (see the file header)\n");
        return 2;
    }
    if (strcmp(o.cmd, "compare") == 0)
        return compare(&o);
    if (strcmp(o.cmd, "work") == 0)
        return work(&o);
    fprintf(stderr, "volume-check: unknown command '%s'\n", o.cmd);
    return 2;
}
