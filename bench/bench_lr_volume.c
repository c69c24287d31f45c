/* bench_lr_volume.c — run time against image error of `lr_volume`: adaptive
 * step (min element side / 2^d, paper Eq. 4) against the uniform step.
 *
 *   bench-lr-volume [--small | --size WxH] [--frames N] [--error-size WxH]
 *
 * Dataset: lr_field sphere, degree 2, 6 cells, grading 0.6 (element sides
 * varying 4x; 216 elements; k-d forest look-up). Fixed transfer function (points form),
 * no shading, orbit 30/20/2.5. Error: frame 0's camera at --error-size
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
 * images' difference. Third table: the cost of streamline tubes in the
 * frame (lr_field sphere as a vector field, the same grading): ms per frame
 * without them and with 64 / 256 seeds (rk4, mixed precision, the default
 * heuristic step), the trace's one-time cost (trace + tubes prepare, the
 * first frame's rebuild_ms) apart, and the orbit's frames after it (the
 * cache holds: no frame traces again). --small for a quick table.
 * Prints Markdown; checks nothing (tests/unit/test_lr_volume.c does).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"
#include "lrspline/sl_lr.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"

static const sl_bench_orbit orbit = {.distance = 2.5, .elevation_deg = 20, .fov_y_deg = 45};
static const char *const DATASET =
    "{\"generator\":\"lr_field\",\"field\":\"sphere\",\"degree\":2,\"cells\":6,\"grading\":0.6}";
static const char *const BASE_PARAMS =
    "{\"shading\":false,\"transfer_function\":[[0,0,0,0,0],[0.3,1,0.5,0.2,0.4],[0.6,0.2,0.6,1,0.8],[1,1,1,1,1]]}";

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
         ",\"step_mode\":\"uniform\",\"step\":0.5}"},
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
        double sum = 0;
        int mx = 0;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                int e = abs((int)img[0][4 * i + c] - (int)img[1][4 * i + c]);
                sum += e;
                mx = e > mx ? e : mx;
            }
        printf("\n## Peer: lr_volume on the trilinear-equivalent spline vs volume_dvr on the voxels\n\n"
               "marschner_lobb 41^3 both ways (lr_field trilinear_ml, 64000 elements), step 0.5 voxel, "
               "time at %dx%d, median of %d frames; images compared at %dx%d\n\n"
               "| technique | samples (error frame) | ms / frame |\n|---|---|---|\n"
               "| lr_volume | %.0f | %.1f |\n| volume_dvr | %.0f | %.1f |\n\n"
               "ratio lr_volume / volume_dvr: %.2f; images: mean dRGB %.3f, max %d\n",
               bo->width, bo->height, bo->frames, ew, eh, samples[0], ms[0], samples[1], ms[1],
               ms[1] > 0 ? ms[0] / ms[1] : 0.0, sum / (3.0 * n), mx);
    }
    free(img[0]);
    free(img[1]);
    return st;
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
    sl_dataset *ds = NULL;
    sl_status st = sl_pipeline_create(gpu, &p, err);
    if (st == SL_OK && (st = sl_generate_json(FIELD, &ds, err)) == SL_OK)
        sl_pipeline_set_dataset(p, ds);
    if (st == SL_OK)
        printf("\n## lr_volume: streamline tubes in the frame\n\n%s; timing at %dx%d, median of %d "
               "orbit frames after the first (which traces: its rebuild ms is the trace + tubes prepare)\n\n"
               "| streamlines | seeds | trace + tubes prepare ms (once) | ms / frame | ratio to the volume alone |\n"
               "|---|---|---|---|---|\n", FIELD, bo->width, bo->height, bo->frames);
    double alone = 0;
    for (size_t r = 0; r < sizeof rows / sizeof rows[0] && st == SL_OK; r++) {
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
        printf("| %s | %d | %.0f | %.1f | %.2f |\n", r == 0 ? "off" : r == 1 ? "64 seeds" : "256 seeds", seeds,
               fs.render.rebuild_ms, tm.median_ms, alone > 0 ? tm.median_ms / alone : 0.0);
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
        fprintf(stderr, "usage: bench-lr-volume %s [--error-size WxH]\n", SL_BENCH_OPTIONS_HELP);
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
    sl_view ev;
    if (st == SL_OK)
        st = view_at(ds, ew, eh, &ev, &err);
    size_t n = (size_t)ew * eh;
    uint8_t *ref = malloc(4 * n), *img = malloc(4 * n);
    double samples = 0;
    sl_params rp = base;
    if (st == SL_OK && ref && img) {
        st = sl_bench_set_choice(&rp, "step_mode", "uniform", &err);
        if (st == SL_OK)
            st = sl_bench_set(&rp, "step", 1.0 / 32.0, &err);
        if (st == SL_OK)
            st = render_into(p, t, &rp, &ev, ref, &samples, &err);
    }
    if (st != SL_OK || !ref || !img) {
        fprintf(stderr, "bench-lr-volume: %s\n", err.message);
        return 2;
    }
    printf("## lr_volume: adaptive vs uniform step\n\n%s, %zu elements; error at %dx%d against uniform 1/32 "
           "(%.0f samples); time at %dx%d, median of %d frames\n\n", DATASET, ds->lr->element_count, ew, eh, samples,
           bo.width, bo.height, bo.frames);
    printf("| step | samples (error frame) | mean dRGB | max dRGB | ms / frame |\n|---|---|---|---|---|\n");
    fflush(stdout);
    static const struct { const char *mode; double value; } rows[] = {
        {"uniform", 2}, {"uniform", 1}, {"uniform", 0.5}, {"uniform", 0.25}, {"uniform", 0.125},
        {"adaptive", 0}, {"adaptive", 1}, {"adaptive", 2}, {"adaptive", 3}, {"adaptive", 4},
    };
    for (size_t r = 0; r < sizeof rows / sizeof rows[0] && st == SL_OK; r++) {
        sl_params q = base;
        st = sl_bench_set_choice(&q, "step_mode", rows[r].mode, &err);
        if (st == SL_OK)
            st = sl_bench_set(&q, strcmp(rows[r].mode, "uniform") == 0 ? "step" : "step_depth", rows[r].value, &err);
        if (st == SL_OK)
            st = render_into(p, t, &q, &ev, img, &samples, &err);
        sl_bench_timing tm;
        if (st == SL_OK)
            st = sl_bench_time_frames(p, t, &q, &bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit, &tm, &err);
        if (st != SL_OK)
            break;
        double sum = 0;
        int mx = 0;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                int e = abs((int)img[4 * i + c] - (int)ref[4 * i + c]);
                sum += e;
                mx = e > mx ? e : mx;
            }
        char label[48];
        if (strcmp(rows[r].mode, "uniform") == 0)
            snprintf(label, sizeof label, "uniform %g x min side", rows[r].value);
        else
            snprintf(label, sizeof label, "adaptive d = %g", rows[r].value);
        printf("| %s | %.0f | %.3f | %d | %.1f |\n", label, samples, sum / (3.0 * n), mx, tm.median_ms);
        fflush(stdout);
    }
    if (st == SL_OK)
        st = peer_table(gpu, &bo, ew, eh, &err);
    if (st == SL_OK)
        st = streamline_table(gpu, &bo, &err);
    if (st != SL_OK)
        fprintf(stderr, "bench-lr-volume: %s\n", err.message);
    free(ref);
    free(img);
    sl_pipeline_destroy(p);
    sl_gpu_destroy(gpu);
    return st == SL_OK ? 0 : 2;
}
