/* bench_volume_dvr.c — run time against error of `volume_dvr`, and the cost of each mode.
 *
 *   bench-volume-dvr [--small | --size WxH] [--frames N] [--steps 2,1,0.5,0.25,0.125]
 *                    [--error-size WxH] [--volume-size N] [--datasets ml,head,ct]
 *
 * Per dataset (Marschner–Lobb and the `head` phantom at --volume-size³,
 * default 256; the CT sample data/samples/cranium.nhdr when present), with a
 * fixed transfer function (points form), orbit 30/20/2.5:
 * 1. Error: frame 0's camera at --error-size (default 160x90), jitter off,
 *    composite; mean and max |ΔRGB| (0..255, every channel) of each step
 *    against the CPU reference (tests/support/volume_reference.h) at step
 *    0.0625, the converged integral. Next to it the frame time at the bench
 *    size (harness: wall ms to glFinish after the readback, orbit of N frames
 *    after a warm-up) with empty-space skipping on and off, and the skipped
 *    fraction of frame 0.
 * 2. Modes at step 0.5: composite, composite + shading, mip, iso, skipping
 *    on and off.
 * 3. Peers (unless --vtk 0): the same volume, transfer function, cameras,
 *    sizes and step 0.5 through VTK's vtkGPUVolumeRayCastMapper and
 *    vtkFixedPointVolumeRayCastMapper (bench/vtk_volume.py under xvfb-run,
 *    the same llvmpipe): error against the same reference and frame time,
 *    with the ratio peer / ours.
 * Prints Markdown; checks nothing (tests/render/volume_dvr.cmake does).
 * Numbers on llvmpipe depend on what else runs on the machine.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "core/sl_clock.h"
#include "core/sl_technique.h"
#include "data/sl_dataset_open.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"
#include "image/sl_image.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "volume_reference.h"

#define MAX_STEPS 8

typedef struct options {
    sl_bench_options bench;
    double steps[MAX_STEPS];
    int step_count;
    int error_w, error_h, volume_size, vtk;
    char datasets[64];
} options;

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.steps = {2, 1, 0.5, 0.25, 0.125}, .step_count = 5, .error_w = 160, .error_h = 90,
                   .volume_size = 256, .vtk = 1};
    snprintf(o->datasets, sizeof o->datasets, "ml,head,ct");
    sl_bench_options_init(&o->bench, 3);
    for (int i = 1; i < argc; i++) {
        int c = sl_bench_option(&o->bench, argc, argv, &i, "bench-volume-dvr");
        if (c < 0)
            return 0;
        if (c > 0)
            continue;
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            return fprintf(stderr, "bench-volume-dvr: %s needs a value\n", a), 0;
        i++;
        if (strcmp(a, "--steps") == 0) {
            o->step_count = 0;
            for (const char *p = v; *p && o->step_count < MAX_STEPS;) {
                char *end = NULL;
                double s = strtod(p, &end);
                if (end == p || !(s >= 0.01 && s <= 16))
                    return fprintf(stderr, "bench-volume-dvr: --steps values must be in [0.01, 16]\n"), 0;
                o->steps[o->step_count++] = s;
                p = *end == ',' ? end + 1 : end;
            }
        } else if (strcmp(a, "--error-size") == 0) {
            if (sscanf(v, "%dx%d", &o->error_w, &o->error_h) != 2 || o->error_w < 8 || o->error_h < 8 ||
                o->error_w > 1280 || o->error_h > 1280)
                return fprintf(stderr, "bench-volume-dvr: --error-size WxH, 8..1280\n"), 0;
        } else if (strcmp(a, "--volume-size") == 0) {
            if (sl_bench_parse_int(v, 16, 512, &o->volume_size) != 0)
                return fprintf(stderr, "bench-volume-dvr: --volume-size in [16, 512]\n"), 0;
        } else if (strcmp(a, "--vtk") == 0) {
            o->vtk = atoi(v) != 0;
        } else if (strcmp(a, "--datasets") == 0) {
            snprintf(o->datasets, sizeof o->datasets, "%s", v);
        } else {
            return fprintf(stderr, "usage: bench-volume-dvr " SL_BENCH_OPTIONS_HELP
                                   " [--steps a,b,...] [--error-size WxH] [--volume-size N] [--datasets ml,head,ct]\n"), 0;
        }
    }
    return 1;
}

typedef struct bench_dataset {
    const char *key, *label;
    const char *tf;     /* points form JSON */
    double iso;
} bench_dataset;

static const bench_dataset datasets[] = {
    {"ml", "marschner_lobb", "[[0.3,0,0,0,0],[0.5,1,0.6,0.2,0.3],[0.7,0.2,0.5,1,0.6]]", 0.5},
    {"head", "head", "[[0,0,0,0,0],[600,0.8,0.5,0.4,0],[1100,1,0.8,0.7,0.2],[2500,1,1,1,0.8]]", 1400},
    {"ct", "cranium.nhdr (CT sample)", "[[-1000,0,0,0,0],[200,0.8,0.5,0.3,0.0],[400,1,0.9,0.8,0.3],[1500,1,1,1,0.9]]",
     400},
};

static sl_status open_dataset(const bench_dataset *b, int size, sl_dataset **out, sl_err *err)
{
    char json[160];
    if (strcmp(b->key, "ct") == 0) {
        const char *src = getenv("SIGHTLINE_SOURCE_DIR");
        char path[512];
        snprintf(path, sizeof path, "%s/data/samples/cranium.nhdr", src ? src : SIGHTLINE_SOURCE_DIR);
        if (access(path, R_OK) != 0)
            return sl_err_set(err, SL_ERR_IO, "%s is missing (scripts/fetch-sample-data)", path);
        return sl_dataset_open(path, NULL, out, err);
    }
    snprintf(json, sizeof json, "{\"generator\":\"%s\",\"size\":%d}", b->key[0] == 'm' ? "marschner_lobb" : "head", size);
    return sl_dataset_open(json, NULL, out, err);
}

static sl_status base_params(const sl_technique *t, const bench_dataset *b, sl_params *p, sl_err *err)
{
    sl_params_init(p, t->params, t->param_count);
    char json[400];
    snprintf(json, sizeof json, "{\"jitter\":false,\"transfer_function\":%s,\"isovalue\":%g}", b->tf, b->iso);
    cJSON *patch = cJSON_Parse(json);
    sl_status st = sl_params_apply_json(p, patch, err);
    cJSON_Delete(patch);
    return st;
}

static const sl_bench_orbit orbit = {.distance = 2.5, .elevation_deg = 20, .fov_y_deg = 45};

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

/* Mean and max |ΔRGB| of a frame at `step` against ref (error size). */
static sl_status frame_error(sl_pipeline *p, const sl_technique *t, sl_params params, double step, const sl_view *view,
                             const uint8_t *ref, uint8_t *buf, double *mean, int *max, sl_err *err)
{
    sl_status st = sl_bench_set(&params, "step", step, err);
    sl_frame_stats fs;
    if (st == SL_OK && (st = sl_pipeline_set_technique(p, t, &params, err)) == SL_OK &&
        (st = sl_pipeline_render(p, view, 1, &fs, err)) == SL_OK) {
        sl_pipeline_read_rgba(p, buf, 1);
        size_t n = (size_t)view->width * view->height;
        double sum = 0;
        *max = 0;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                int e = abs((int)buf[4 * i + c] - (int)ref[4 * i + c]);
                sum += e;
                *max = e > *max ? e : *max;
            }
        *mean = sum / (3.0 * n);
    }
    return st;
}

/* Skipped fraction of frame 0 at the bench size. */
static sl_status skipped_fraction(sl_pipeline *p, const sl_technique *t, const sl_params *params, const sl_view *view,
                                  double *frac, sl_err *err)
{
    sl_frame_stats fs;
    sl_status st = sl_pipeline_set_technique(p, t, params, err);
    if (st == SL_OK && (st = sl_pipeline_render(p, view, 1, &fs, err)) == SL_OK) {
        double all = fs.render.samples + fs.render.samples_skipped;
        *frac = all > 0 ? fs.render.samples_skipped / all : 0.0;
    }
    return st;
}

static sl_status time_both(sl_pipeline *p, const sl_technique *t, sl_params params, const options *o,
                           sl_bench_timing *on, sl_bench_timing *off, sl_err *err)
{
    sl_status st = sl_bench_set(&params, "empty_space_skipping", 1, err);
    if (st == SL_OK)
        st = sl_bench_time_frames(p, t, &params, &o->bench, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit, on, err);
    if (st == SL_OK)
        st = sl_bench_set(&params, "empty_space_skipping", 0, err);
    if (st == SL_OK)
        st = sl_bench_time_frames(p, t, &params, &o->bench, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit, off, err);
    return st;
}

/* ---- peers: VTK's mappers on the same volume and cameras ---- */

static const char *source_dir(void)
{
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    return src ? src : SIGHTLINE_SOURCE_DIR;
}

/* Writes one camera line per frame: "VIEW INDEX eye target up fov" (warm-up -1 when frames > 1). */
static sl_status write_cameras(const char *path, const sl_dataset *ds, int frames, sl_err *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "cannot write %s", path);
    sl_status st = SL_OK;
    for (int k = frames > 1 ? -1 : 0; st == SL_OK && k < frames; k++) {
        sl_camera c;
        if ((st = sl_bench_orbit_camera(ds, k < 0 ? 0 : k, frames, &orbit, &c, err)) == SL_OK)
            fprintf(f, "v %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", k, c.eye.x, c.eye.y,
                    c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg);
    }
    fclose(f);
    return st;
}

/* Runs vtk_volume.py; fills *ms (median) or returns a reason in err. */
static sl_status run_vtk(const char *dir, const sl_dataset *ds, const sl_transfer_function *tf, const char *mapper,
                         double step, int w, int h, const char *cameras, const char *png, double *ms, sl_err *err)
{
    static const char *const types[] = {"uint8", "uint16", "int16", "float32"};
    const sl_volume *v = &ds->volume;
    char tfs[2048] = "";
    for (int k = 0; k < tf->count; k++)
        snprintf(tfs + strlen(tfs), sizeof tfs - strlen(tfs), "%s%.9g,%g,%g,%g,%g", k ? ";" : "", tf->point[k][0],
                 tf->point[k][1], tf->point[k][2], tf->point[k][3], tf->point[k][4]);
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "xvfb-run -a /usr/bin/python3 %s/bench/vtk_volume.py --raw %s/volume.raw --type %s "
             "--dims %d %d %d --spacing %.17g %.17g %.17g --origin %.17g %.17g %.17g --tf='%s' --step %g --mapper %s "
             "--cameras %s --size %dx%d --background 0.1,0.1,0.12%s%s 2>/dev/null", source_dir(), dir, types[v->type],
             v->dims[0], v->dims[1], v->dims[2], v->spacing[0], v->spacing[1], v->spacing[2], ds->origin.x,
             ds->origin.y, ds->origin.z, tfs, step, mapper, cameras, w, h, png ? " --png " : "", png ? png : "");
    FILE *p = popen(cmd, "r");
    if (!p)
        return sl_err_set(err, SL_ERR_IO, "cannot run xvfb-run");
    char line[8192] = "";
    while (fgets(line, sizeof line, p) && line[0] != '{')
        ;
    pclose(p);
    cJSON *j = cJSON_Parse(line);
    const cJSON *ok = cJSON_GetObjectItemCaseSensitive(j, "ok");
    sl_status st = SL_OK;
    if (!cJSON_IsTrue(ok)) {
        const cJSON *e = cJSON_GetObjectItemCaseSensitive(j, "error");
        st = sl_err_set(err, SL_ERR_UNSUPPORTED, "vtk_volume.py: %s", cJSON_IsString(e) ? e->valuestring : "no output");
    } else {
        const cJSON *views = cJSON_GetObjectItemCaseSensitive(j, "views");
        const cJSON *m = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(views, "v"), "median_ms");
        *ms = cJSON_IsNumber(m) ? m->valuedouble : 0.0;
    }
    cJSON_Delete(j);
    return st;
}

static void peers(const options *o, const sl_dataset *ds, const sl_transfer_function *tf, const uint8_t *ref,
                  int ew, int eh, double ours_error, double ours_ms)
{
    char dir[] = "/tmp/sl-bench-volume-XXXXXX";
    if (!mkdtemp(dir)) {
        printf("\nVTK peers: no temporary folder\n");
        return;
    }
    char raw[128], cam_e[128], cam_t[128], png[128], png_file[160];
    snprintf(raw, sizeof raw, "%s/volume.raw", dir);
    snprintf(cam_e, sizeof cam_e, "%s/error.txt", dir);
    snprintf(cam_t, sizeof cam_t, "%s/time.txt", dir);
    snprintf(png, sizeof png, "%s/vtk", dir);
    snprintf(png_file, sizeof png_file, "%s-v.png", png);
    const sl_volume *v = &ds->volume;
    size_t n = (size_t)v->dims[0] * v->dims[1] * v->dims[2];
    FILE *f = fopen(raw, "wb");
    int wrote = f && fwrite(v->data, sl_voxel_type_size(v->type), n, f) == n;
    if (f)
        fclose(f);
    sl_err err = {0};
    printf("\n### Peers at step 0.5: VTK (same volume, transfer function, cameras; xvfb-run, the same llvmpipe)\n\n");
    printf("| renderer | mean abs dRGB vs reference (%dx%d) | wall ms (%dx%d) | ratio peer / ours |\n", ew, eh,
           o->bench.width, o->bench.height);
    printf("|---|---:|---:|---:|\n");
    printf("| volume_dvr | %.3f | %.1f | 1.00 |\n", ours_error, ours_ms);
    static const char *const mappers[] = {"gpu", "fixed"};
    static const char *const names[] = {"vtkGPUVolumeRayCastMapper", "vtkFixedPointVolumeRayCastMapper"};
    for (int m = 0; wrote && m < 2; m++) {
        double ms = 0, unused = 0;
        sl_image img = {0};
        sl_status st = write_cameras(cam_e, ds, 1, &err);
        if (st == SL_OK)
            st = run_vtk(dir, ds, tf, mappers[m], 0.5, ew, eh, cam_e, png, &unused, &err);
        if (st == SL_OK)
            st = sl_png_read(png_file, &img, &err);
        double mean = -1;
        if (st == SL_OK && img.width == ew && img.height == eh) {
            double sum = 0;
            for (size_t i = 0; i < (size_t)ew * eh; i++)
                for (int c = 0; c < 3; c++)
                    sum += abs((int)img.rgba[4 * i + c] - (int)ref[4 * i + c]);
            mean = sum / (3.0 * ew * eh);
        }
        sl_image_deinit(&img);
        if (st == SL_OK && (st = write_cameras(cam_t, ds, o->bench.frames, &err)) == SL_OK)
            st = run_vtk(dir, ds, tf, mappers[m], 0.5, o->bench.width, o->bench.height, cam_t, NULL, &ms, &err);
        if (st != SL_OK)
            printf("| %s | — | — | (%s) |\n", names[m], err.message);
        else
            printf("| %s | %.3f | %.1f | %.2f |\n", names[m], mean, ms, ours_ms > 0 ? ms / ours_ms : 0);
        fflush(stdout);
    }
    unlink(raw);
    unlink(cam_e);
    unlink(cam_t);
    unlink(png_file);
    rmdir(dir);
}

static sl_status run_dataset(sl_gpu *gpu, const options *o, const bench_dataset *b, sl_err *err)
{
    sl_dataset *ds = NULL;
    sl_status st = open_dataset(b, o->volume_size, &ds, err);
    if (st != SL_OK)
        return st;
    const sl_technique *t = sl_technique_find("volume_dvr");
    sl_pipeline *p = NULL;
    if ((st = sl_pipeline_create(gpu, &p, err)) != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    sl_pipeline_set_dataset(p, ds);
    ds = NULL;
    const sl_dataset *pds = sl_pipeline_dataset(p);
    sl_params params;
    sl_view ev, bv;
    size_t en = (size_t)o->error_w * o->error_h;
    uint8_t *ref = malloc(en * 4), *buf = malloc(en * 4);
    if (!ref || !buf)
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    if (st == SL_OK && (st = base_params(t, b, &params, err)) == SL_OK &&
        (st = view_at(pds, o->error_w, o->error_h, &ev, err)) == SL_OK)
        st = view_at(pds, o->bench.width, o->bench.height, &bv, err);
    const sl_transfer_function *tf = st == SL_OK ? sl_params_transfer(&params, "transfer_function") : NULL;
    double ref_ms = 0;
    if (st == SL_OK) {
        volume_ref_desc d = {.view = &ev, .volume = pds, .tf_count = tf->count, .tf = (const double (*)[5])tf->point,
                             .mode = VOLUME_REF_COMPOSITE, .step = 0.0625, .alpha_stop = 0.99};
        double t0 = sl_clock_ms();
        if (volume_ref_render(&d, ref, NULL) != 0)
            st = sl_err_set(err, SL_ERR_INVALID, "the reference refused %s", b->label);
        ref_ms = sl_clock_ms() - t0;
    }
    if (st == SL_OK) {
        const sl_volume *v = &pds->volume;
        printf("\n## `%s` (%dx%dx%d %s), composite: run time against error\n\n", b->label, v->dims[0], v->dims[1],
               v->dims[2], sl_voxel_type_name(v->type));
        printf("Error: %dx%d, frame 0's camera, against the CPU reference at step 0.0625 (%.0f ms to compute); time: "
               "%dx%d, orbit of %d frames after a warm-up.\n\n", o->error_w, o->error_h, ref_ms, o->bench.width,
               o->bench.height, o->bench.frames);
        printf("| step | mean abs dRGB | max abs dRGB | wall ms, skipping on | off | on / off | skipped fraction |\n");
        printf("|---:|---:|---:|---:|---:|---:|---:|\n");
    }
    double ours_error_05 = -1, ours_ms_05 = 0;
    for (int s = 0; st == SL_OK && s < o->step_count; s++) {
        double mean = 0, frac = 0;
        int max = 0;
        sl_bench_timing on, off;
        sl_params q = params;
        if ((st = frame_error(p, t, params, o->steps[s], &ev, ref, buf, &mean, &max, err)) != SL_OK ||
            (st = sl_bench_set(&q, "step", o->steps[s], err)) != SL_OK ||
            (st = skipped_fraction(p, t, &q, &bv, &frac, err)) != SL_OK ||
            (st = time_both(p, t, q, o, &on, &off, err)) != SL_OK)
            break;
        if (o->steps[s] == 0.5) {
            ours_error_05 = mean;
            ours_ms_05 = on.median_ms;
        }
        printf("| %g | %.3f | %d | %.1f (%.1f-%.1f) | %.1f | %.2f | %.3f |\n", o->steps[s], mean, max, on.median_ms,
               on.min_ms, on.max_ms, off.median_ms, off.median_ms > 0 ? on.median_ms / off.median_ms : 0, frac);
        fflush(stdout);
    }
    if (st == SL_OK) {
        printf("\n### Modes at step 0.5 (%dx%d)\n\n| mode | wall ms, skipping on | off | skipped fraction | GPU MB |\n",
               o->bench.width, o->bench.height);
        printf("|---|---:|---:|---:|---:|\n");
    }
    static const char *const modes[] = {"composite", "composite + shading", "mip", "iso"};
    for (int m = 0; st == SL_OK && m < 4; m++) {
        sl_params q = params;
        sl_bench_timing on, off;
        double frac = 0;
        if ((st = sl_bench_set(&q, "step", 0.5, err)) != SL_OK ||
            (st = sl_bench_set_choice(&q, "mode", m == 1 ? "composite" : modes[m], err)) != SL_OK ||
            (st = sl_bench_set(&q, "shading", m == 1, err)) != SL_OK ||
            (st = skipped_fraction(p, t, &q, &bv, &frac, err)) != SL_OK ||
            (st = time_both(p, t, q, o, &on, &off, err)) != SL_OK)
            break;
        printf("| %s | %.1f (%.1f-%.1f) | %.1f | %.3f | %.1f |\n", modes[m], on.median_ms, on.min_ms, on.max_ms,
               off.median_ms, frac, on.gpu_bytes / 1048576.0);
        fflush(stdout);
    }
    if (st == SL_OK && o->vtk) {
        if (ours_error_05 < 0) {
            sl_bench_timing on, off;
            sl_params q = params;
            if ((st = frame_error(p, t, params, 0.5, &ev, ref, buf, &ours_error_05, &(int){0}, err)) == SL_OK &&
                (st = sl_bench_set(&q, "step", 0.5, err)) == SL_OK && (st = time_both(p, t, q, o, &on, &off, err)) == SL_OK)
                ours_ms_05 = on.median_ms;
        }
        if (st == SL_OK)
            peers(o, pds, tf, ref, o->error_w, o->error_h, ours_error_05, ours_ms_05);
    }
    free(ref);
    free(buf);
    sl_pipeline_destroy(p);
    return st;
}

int main(int argc, char **argv)
{
    options o;
    if (!parse_args(argc, argv, &o))
        return 2;
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "bench-volume-dvr: %s\n", err.message);
        return 3;
    }
    printf("# bench-volume-dvr — %s\n", sl_gpu_renderer(gpu));
    int rc = 0;
    for (size_t k = 0; k < sizeof datasets / sizeof datasets[0]; k++) {
        if (!strstr(o.datasets, datasets[k].key))
            continue;
        if (run_dataset(gpu, &o, &datasets[k], &err) != SL_OK) {
            fprintf(stderr, "bench-volume-dvr: %s: %s\n", datasets[k].label, err.message);
            rc = 1;
        }
    }
    sl_gpu_destroy(gpu);
    return rc;
}
