/* bench_lr_volume.c — run time against image error of `lr_volume`: adaptive
 * step (min element side / 2^d, paper Eq. 4) against the uniform step.
 *
 *   bench-lr-volume [--small | --size WxH] [--frames N] [--error-size WxH] [--table steps|woodgrain|peer|streamlines]
 *
 * Dataset: lr_field sphere, degree 2, 6 cells, grading 0.6 (element sides
 * varying 4x; 216 elements; k-d forest look-up). Fixed transfer function (points form),
 * no shading, no jitter (but in the wood-grain rows), orbit 30/20/2.5. Error: frame 0's camera at --error-size
 * (default 160x90), mean and max |ΔRGB| (0..255, every channel) against
 * lr_volume itself at uniform step 1/32 of the smallest side (the converged
 * integral: the field is evaluated exactly, only the quadrature differs).
 * Time: the harness's wall ms per frame (orbit of N frames after a warm-up)
 * at the bench size (default 1280x720), with the samples of frame 0.
 * Peer (second table): the same field both ways — lr_field trilinear_ml
 * (degree 1, knots at the voxel centres: exactly the trilinear interpolant)
 * through lr_volume, and the marschner_lobb voxels through volume_dvr (what a
 * user would otherwise pick), same camera, transfer function and step of
 * half a voxel (no jitter, no shading); ms per frame, their ratio and the
 * images' difference. Streamline tubes (third table): the cost of the tubes
 * in the frame (lr_field sphere as a vector field, the same grading): ms per
 * frame without them and with 64 / 256 seeds (rk4, mixed precision, the
 * default heuristic step), the one-time costs apart: the prepare (Bézier
 * blocks, proxy, upload, and with streamlines the trace and the tubes'
 * prepare) and of it the trace (flow program, dispatch, read-back) and the
 * tubes' prepare; then the orbit's frames (no frame traces again). Wood-grain (fourth table): uniform 2 and 1, adaptive
 * d = 0 and 1, each with samples at segment midpoints and with the
 * per-pixel jitter (parameter `jitter`), the error of the whole frame at the
 * bench size against uniform 1/32 without jitter at that size: mean, max and
 * `band` (mean |8x8-block average of the signed difference|: the coherent
 * error, rings, that noise of zero mean does not leave). --small for a quick
 * run; --table for one table. Prints Markdown; checks nothing
 * (tests/unit/test_lr_volume.c does).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/sl_clock.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"
#include "image_error.h"
#include "lrspline/sl_lr.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"

static const sl_bench_orbit orbit = {.distance = 2.5, .elevation_deg = 20, .fov_y_deg = 45};
static const char *const DATASET =
    "{\"generator\":\"lr_field\",\"field\":\"sphere\",\"degree\":2,\"cells\":6,\"grading\":0.6}";
static const char *const BASE_PARAMS =
    "{\"shading\":false,\"jitter\":false,\"transfer_function\":[[0,0,0,0,0],[0.3,1,0.5,0.2,0.4],[0.6,0.2,0.6,1,0.8],"
    "[1,1,1,1,1]]}";

static sl_status view_at(const sl_dataset *ds, int w, int h, sl_view *view, sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = w;
    view->height = h;
    view->background[0] = view->background[1] = 0.1f;
    view->background[2] = 0.12f;
    view->background[3] = 1.0f;
    view->origin = ds->origin;
    sl_status st = sl_bench_orbit_camera(ds, 0, 1, &orbit, &view->camera, err);
    return st == SL_OK ? sl_view_init(view, sl_dataset_radius(ds), err) : st;
}

static sl_status render_into(sl_pipeline *p, const sl_technique *t, const sl_params *params, const sl_view *view,
                             uint8_t *rgba, double *samples, sl_err *err)
{
    sl_frame_stats fs;
    sl_status st = sl_pipeline_set_technique(p, t, params, err);
    if (st == SL_OK && (st = sl_pipeline_render(p, view, 1, &fs, err)) == SL_OK) {
        if (rgba)
            sl_pipeline_read_rgba(p, rgba, 1);
        *samples = fs.render.samples;
    }
    return st;
}

/* lr_volume on the spline that equals the marschner_lobb volume's trilinear
 * interpolant against volume_dvr on the voxels: same view, TF and step. */
static sl_status peer_table(sl_gpu *gpu, const sl_bench_options *bo, int ew, int eh, sl_err *err)
{
    static const char *const TF = "{\"transfer_function\":[[0,0,0,0,0],[0.3,1,0.5,0.2,0.05],[0.6,0.2,0.6,1,0.3],"
                                  "[1,1,1,1,0.8]],\"shading\":false";
    static const struct { const char *technique, *dataset, *extra; } sides[2] = {
        {"lr_volume", "{\"generator\":\"lr_field\",\"field\":\"trilinear_ml\",\"degree\":1,\"cells\":40}",
         ",\"step_mode\":\"uniform\",\"step\":0.5,\"jitter\":false}"},
        {"volume_dvr", "{\"generator\":\"marschner_lobb\",\"size\":41}", ",\"step\":0.5,\"jitter\":false}"},
    };
    size_t n = (size_t)ew * eh;
    uint8_t *img[2] = {malloc(4 * n), malloc(4 * n)};
    double ms[2] = {0, 0}, samples[2] = {0, 0};
    sl_status st = img[0] && img[1] ? SL_OK : sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    for (int k = 0; k < 2 && st == SL_OK; k++) {
        sl_pipeline *p = NULL;
        sl_dataset *ds = NULL;
        const sl_technique *t = sl_technique_find(sides[k].technique);
        if ((st = sl_pipeline_create(gpu, &p, err)) != SL_OK)
            break;
        if ((st = sl_generate_json(sides[k].dataset, &ds, err)) == SL_OK) {
            sl_pipeline_set_dataset(p, ds);
            ds = (sl_dataset *)sl_pipeline_dataset(p);
            sl_params q;
            sl_params_init(&q, t->params, t->param_count);
            char json[512];
            snprintf(json, sizeof json, "%s%s", TF, sides[k].extra);
            cJSON *patch = cJSON_Parse(json);
            st = patch ? sl_params_apply_json(&q, patch, err) : sl_err_set(err, SL_ERR_INVALID, "bad peer JSON");
            cJSON_Delete(patch);
            sl_view ev;
            sl_bench_timing tm;
            if (st == SL_OK && (st = view_at(ds, ew, eh, &ev, err)) == SL_OK &&
                (st = render_into(p, t, &q, &ev, img[k], &samples[k], err)) == SL_OK &&
                (st = sl_bench_time_frames(p, t, &q, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit, &tm,
                                           err)) == SL_OK)
                ms[k] = tm.median_ms;
        }
        sl_pipeline_destroy(p);
    }
    if (st == SL_OK) {
        image_error ie = image_error_compare(img[0], img[1], ew, eh, 8);
        printf("\n## Peer: lr_volume on the trilinear-equivalent spline vs volume_dvr on the voxels\n\n"
               "marschner_lobb 41^3 both ways (lr_field trilinear_ml, 64000 elements), step 0.5 voxel, "
               "time at %dx%d, median of %d frames; images compared at %dx%d\n\n"
               "| technique | samples (error frame) | ms / frame |\n|---|---|---|\n"
               "| lr_volume | %.0f | %.1f |\n| volume_dvr | %.0f | %.1f |\n\n"
               "ratio lr_volume / volume_dvr: %.2f; images: mean dRGB %.3f, max %d\n",
               bo->width, bo->height, bo->frames, ew, eh, samples[0], ms[0], samples[1], ms[1],
               ms[1] > 0 ? ms[0] / ms[1] : 0.0, ie.mean, ie.max);
    }
    free(img[0]);
    free(img[1]);
    return st;
}

/* Adaptive against uniform steps: error at ew x eh against uniform 1/32,
 * time at the bench size. */
static sl_status steps_table(sl_pipeline *p, const sl_technique *t, const sl_params *base, const sl_dataset *ds,
                             const sl_bench_options *bo, int ew, int eh, sl_err *err)
{
    sl_view ev;
    sl_status st = view_at(ds, ew, eh, &ev, err);
    size_t n = (size_t)ew * eh;
    uint8_t *ref = malloc(4 * n), *img = malloc(4 * n);
    double samples = 0;
    sl_params rp = *base;
    if (st == SL_OK && (!ref || !img))
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    if (st == SL_OK)
        st = sl_bench_set_choice(&rp, "step_mode", "uniform", err);
    if (st == SL_OK)
        st = sl_bench_set(&rp, "step", 1.0 / 32.0, err);
    if (st == SL_OK)
        st = render_into(p, t, &rp, &ev, ref, &samples, err);
    if (st == SL_OK) {
        printf("## lr_volume: adaptive vs uniform step\n\n%s, %zu elements; error at %dx%d against uniform 1/32 "
               "(%.0f samples); time at %dx%d, median of %d frames\n\n", DATASET, ds->lr->element_count, ew, eh,
               samples, bo->width, bo->height, bo->frames);
        printf("| step | samples (error frame) | mean dRGB | max dRGB | ms / frame |\n|---|---|---|---|---|\n");
        fflush(stdout);
    }
    static const struct { const char *mode; double value; } rows[] = {
        {"uniform", 2}, {"uniform", 1}, {"uniform", 0.5}, {"uniform", 0.25}, {"uniform", 0.125},
        {"adaptive", 0}, {"adaptive", 1}, {"adaptive", 2}, {"adaptive", 3}, {"adaptive", 4},
    };
    for (size_t r = 0; r < sizeof rows / sizeof rows[0] && st == SL_OK; r++) {
        sl_params q = *base;
        st = sl_bench_set_choice(&q, "step_mode", rows[r].mode, err);
        if (st == SL_OK)
            st = sl_bench_set(&q, strcmp(rows[r].mode, "uniform") == 0 ? "step" : "step_depth", rows[r].value, err);
        if (st == SL_OK)
            st = render_into(p, t, &q, &ev, img, &samples, err);
        sl_bench_timing tm;
        if (st == SL_OK)
            st = sl_bench_time_frames(p, t, &q, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit, &tm, err);
        if (st != SL_OK)
            break;
        image_error ie = image_error_compare(img, ref, ew, eh, 8);
        char label[48];
        if (strcmp(rows[r].mode, "uniform") == 0)
            snprintf(label, sizeof label, "uniform %g x min side", rows[r].value);
        else
            snprintf(label, sizeof label, "adaptive d = %g", rows[r].value);
        printf("| %s | %.0f | %.3f | %d | %.1f |\n", label, samples, ie.mean, ie.max, tm.median_ms);
        fflush(stdout);
    }
    free(ref);
    free(img);
    return st;
}

/* Wood-grain: the sample lattice at midpoints against the per-pixel jitter,
 * same steps (so the same sample count up to the segments skipping moves),
 * the error of the whole frame at the bench size against uniform 1/32
 * without jitter, rendered at that size too. */
static sl_status woodgrain_table(sl_pipeline *p, const sl_technique *t, const sl_params *base, const sl_dataset *ds,
                                 const sl_bench_options *bo, sl_err *err)
{
    const int w = bo->width, h = bo->height;
    size_t n = (size_t)w * (size_t)h;
    uint8_t *ref = malloc(4 * n), *img = malloc(4 * n);
    sl_view v;
    double samples = 0;
    sl_params rp = *base;
    sl_status st = ref && img ? view_at(ds, w, h, &v, err) : sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    if (st == SL_OK)
        st = sl_bench_set_choice(&rp, "step_mode", "uniform", err);
    if (st == SL_OK)
        st = sl_bench_set(&rp, "step", 1.0 / 32.0, err);
    double t0 = sl_clock_ms();
    if (st == SL_OK)
        st = render_into(p, t, &rp, &v, ref, &samples, err);
    if (st == SL_OK) {
        printf("\n## lr_volume: wood-grain, samples at segment midpoints against per-pixel jitter\n\n"
               "%s; the whole frame at %dx%d against uniform 1/32 without jitter (%.0f samples, %.0f ms); "
               "band = mean |8x8-block average of the signed dRGB| (the coherent part: rings, not noise); "
               "time at %dx%d, median of %d frames\n\n"
               "| step | jitter | samples | mean dRGB | band dRGB | max dRGB | ms / frame |\n"
               "|---|---|---|---|---|---|---|\n", DATASET, w, h, samples, sl_clock_ms() - t0, w, h, bo->frames);
        fflush(stdout);
    }
    static const struct { const char *mode; double value; } rows[] = {
        {"uniform", 2}, {"uniform", 1}, {"adaptive", 0}, {"adaptive", 1},
    };
    for (size_t r = 0; r < 2 * (sizeof rows / sizeof rows[0]) && st == SL_OK; r++) {
        int jitter = (int)(r % 2);
        sl_params q = *base;
        const char *mode = rows[r / 2].mode;
        st = sl_bench_set_choice(&q, "step_mode", mode, err);
        if (st == SL_OK)
            st = sl_bench_set(&q, strcmp(mode, "uniform") == 0 ? "step" : "step_depth", rows[r / 2].value, err);
        if (st == SL_OK)
            st = sl_bench_set(&q, "jitter", jitter, err);
        if (st == SL_OK)
            st = render_into(p, t, &q, &v, img, &samples, err);
        sl_bench_timing tm;
        if (st == SL_OK)
            st = sl_bench_time_frames(p, t, &q, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit, &tm, err);
        if (st != SL_OK)
            break;
        image_error ie = image_error_compare(img, ref, w, h, 8);
        printf("| %s %g | %s | %.0f | %.3f | %.3f | %d | %.1f |\n", mode, rows[r / 2].value, jitter ? "on" : "off",
               samples, ie.mean, ie.band, ie.max, tm.median_ms);
        fflush(stdout);
    }
    free(ref);
    free(img);
    return st;
}

/* The prepare's extra `name` of a frame that prepared; 0 when absent. */
static double prepare_extra(const sl_frame_stats *fs, const char *name)
{
    for (int i = 0; fs->prepared && i < fs->prepare.extra_count; i++)
        if (strcmp(fs->prepare.extra[i].name, name) == 0)
            return fs->prepare.extra[i].value;
    return 0.0;
}

/* Frames with streamline tubes against the volume alone (same view and TF). */
static sl_status streamline_table(sl_gpu *gpu, const sl_bench_options *bo, sl_err *err)
{
    static const char *const FIELD =
        "{\"generator\":\"lr_field\",\"field\":\"sphere\",\"degree\":2,\"cells\":6,\"grading\":0.6,"
        "\"components\":\"vector\"}";
    static const char *const rows[] = {
        "{}",
        "{\"streamlines\":true,\"seed_count\":64}",
        "{\"streamlines\":true,\"seed_count\":256}",
    };
    const sl_technique *t = sl_technique_find("lr_volume");
    sl_pipeline *p = NULL;
    sl_status st = sl_pipeline_create(gpu, &p, err);
    if (st == SL_OK)
        printf("\n## lr_volume: streamline tubes in the frame\n\n%s; timing at %dx%d, median of %d "
               "orbit frames after the first (which prepares: blocks, proxy, upload, and the trace and the tubes' "
               "prepare)\n\n"
               "| streamlines | seeds | samples | prepare ms (once) | of it trace ms | of it tubes ms | ms / frame | "
               "ratio to the volume alone |\n"
               "|---|---|---|---|---|---|---|---|\n", FIELD, bo->width, bo->height, bo->frames);
    double alone = 0;
    for (size_t r = 0; r < sizeof rows / sizeof rows[0] && st == SL_OK; r++) {
        /* A fresh dataset per row, so every row's first frame prepares (and traces there). */
        sl_dataset *ds = NULL;
        if ((st = sl_generate_json(FIELD, &ds, err)) != SL_OK)
            break;
        sl_pipeline_set_dataset(p, ds);
        sl_params q;
        sl_params_init(&q, t->params, t->param_count);
        cJSON *base = cJSON_Parse(BASE_PARAMS), *extra = cJSON_Parse(rows[r]);
        st = base && extra && sl_params_apply_json(&q, base, err) == SL_OK ? sl_params_apply_json(&q, extra, err)
                                                                         : sl_err_set(err, SL_ERR_INVALID, "bad row");
        cJSON_Delete(base);
        cJSON_Delete(extra);
        sl_view v;
        sl_frame_stats fs;
        if (st == SL_OK && (st = view_at(sl_pipeline_dataset(p), bo->width, bo->height, &v, err)) == SL_OK &&
            (st = sl_pipeline_set_technique(p, t, &q, err)) == SL_OK)
            st = sl_pipeline_render(p, &v, 1, &fs, err);
        sl_bench_timing tm;
        if (st == SL_OK)
            st = sl_bench_time_frames(p, t, &q, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit, &tm, err);
        if (st != SL_OK)
            break;
        if (r == 0)
            alone = tm.median_ms;
        int seeds = r == 0 ? 0 : r == 1 ? 64 : 256;
        printf("| %s | %d | %.0f | %.0f | %.0f | %.0f | %.1f | %.2f |\n", r == 0 ? "off" : r == 1 ? "64 seeds" : "256 seeds",
               seeds, prepare_extra(&fs, "streamline_samples"), fs.prepare_ms,
               prepare_extra(&fs, "streamline_trace_ms"), prepare_extra(&fs, "streamline_tubes_ms"), tm.median_ms,
               alone > 0 ? tm.median_ms / alone : 0.0);
        fflush(stdout);
    }
    sl_pipeline_destroy(p);
    return st;
}

int main(int argc, char **argv)
{
    sl_bench_options bo;
    sl_bench_options_init(&bo, 4);
    int ew = 160, eh = 90;
    const char *only = NULL;
    for (int i = 1; i < argc; i++) {
        int r = sl_bench_option(&bo, argc, argv, &i, "bench-lr-volume"); /* leaves i on its last word */
        if (r < 0)
            return 1;
        if (r > 0)
            continue;
        if (strcmp(argv[i], "--error-size") == 0 && i + 1 < argc && sscanf(argv[i + 1], "%dx%d", &ew, &eh) == 2 &&
            ew > 0 && eh > 0 && ew <= 4096 && eh <= 4096) {
            i++;
            continue;
        }
        if (strcmp(argv[i], "--table") == 0 && i + 1 < argc &&
            (strcmp(argv[i + 1], "steps") == 0 || strcmp(argv[i + 1], "woodgrain") == 0 ||
             strcmp(argv[i + 1], "peer") == 0 || strcmp(argv[i + 1], "streamlines") == 0)) {
            only = argv[++i];
            continue;
        }
        fprintf(stderr, "usage: bench-lr-volume %s [--error-size WxH] [--table steps|woodgrain|peer|streamlines]\n",
                SL_BENCH_OPTIONS_HELP);
        return 1;
    }
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_pipeline *p = NULL;
    sl_dataset *ds = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK || sl_pipeline_create(gpu, &p, &err) != SL_OK ||
        sl_generate_json(DATASET, &ds, &err) != SL_OK) {
        fprintf(stderr, "bench-lr-volume: %s\n", err.message);
        return 2;
    }
    sl_pipeline_set_dataset(p, ds);
    ds = (sl_dataset *)sl_pipeline_dataset(p);
    const sl_technique *t = sl_technique_find("lr_volume");
    sl_params base;
    sl_params_init(&base, t->params, t->param_count);
    cJSON *patch = cJSON_Parse(BASE_PARAMS);
    sl_status st = patch ? sl_params_apply_json(&base, patch, &err) : SL_ERR_INVALID;
    cJSON_Delete(patch);
    if (st == SL_OK && (!only || strcmp(only, "steps") == 0))
        st = steps_table(p, t, &base, ds, &bo, ew, eh, &err);
    if (st == SL_OK && (!only || strcmp(only, "woodgrain") == 0))
        st = woodgrain_table(p, t, &base, ds, &bo, &err);
    if (st == SL_OK && (!only || strcmp(only, "peer") == 0))
        st = peer_table(gpu, &bo, ew, eh, &err);
    if (st == SL_OK && (!only || strcmp(only, "streamlines") == 0))
        st = streamline_table(gpu, &bo, &err);
    if (st != SL_OK)
        fprintf(stderr, "bench-lr-volume: %s\n", err.message);
    sl_pipeline_destroy(p);
    sl_gpu_destroy(gpu);
    return st == SL_OK ? 0 : 2;
}
