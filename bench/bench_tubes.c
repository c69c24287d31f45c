/* bench_tubes.c — the experiment of Russig et al. (4, Fig. 5) for `tubes`, plus accuracy tables.
 *
 *   bench-tubes [--small | --size WxH] [--frames N] [--datasets fibers,hotroom,bundle,brain,furball]
 *               [--skip-perf] [--skip-error] [--skip-cubic] [--skip-peers]
 *
 * 1. Speed: generated stand-ins for the paper's five datasets (about 3.5k,
 *    31k, 106k, 114k, 787k segments) in a far view (the bounding sphere fits
 *    the 45 degree view) and a close view (1/3 of that distance), an orbit of
 *    N frames each, timed by the harness (bench/harness/sl_bench.h: wall ms to
 *    glFinish after the readback, GPU ms as a second column): tubes (with its
 *    occlusion pre-pass, the default), tubes in one pass (the paper's), the
 *    empty fragment shader (silhouette_only), tubes_mesh; triangles; GPU memory.
 *    Then the same lines and cameras through the peers: VTK's tube filter and
 *    Embree round curves (sl_bench_peer_*), as ratios to ours.
 * 2. Error against time: every root method x iterations 2..12, 16, 20, 24, 32,
 *    depth error against the CPU reference (tests/support/tubes_reference.c)
 *    at 128x128, and the frame ms of the same scene at the benchmark size.
 * 3. How far the quadratic pair lies from the true cubic Hermite sweep
 *    (both by the reference) on smaller versions of the five datasets.
 * Defaults: 1280x720, 3 frames; --small for a quick look. Prints Markdown;
 * checks nothing. Render thread = main.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "line_style/sl_line_style.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"
#include "pipeline/sl_pipeline.h"
#include "tubes/tubes_nodes.h"

/* The reference intersector is test code kept apart from the renderer library
 * (it must share nothing with the shader path); compiled into this program. */
#include "tubes_reference.h"
#include "tubes_reference_input.h"

typedef struct bench_dataset {
    const char *name;       /* the paper's dataset it stands in for */
    const char *json;       /* full size */
    const char *json_small; /* for the cubic-vs-quadratic table */
} bench_dataset;

static const bench_dataset datasets[] = {
    {"fibers", "{\"generator\":\"tornado\",\"lines\":241,\"points\":16,\"seed\":1}",
     "{\"generator\":\"tornado\",\"lines\":60,\"points\":16,\"seed\":1}"},
    {"hotroom", "{\"generator\":\"hotroom\",\"lines\":12400,\"seed\":1}",
     "{\"generator\":\"hotroom\",\"lines\":1000,\"seed\":1}"},
    {"bundle", "{\"generator\":\"bundle\",\"lines\":1250,\"points\":85,\"seed\":1}",
     "{\"generator\":\"bundle\",\"lines\":40,\"points\":85,\"seed\":1}"},
    {"brain", "{\"generator\":\"abc\",\"lines\":1701,\"points\":68,\"seed\":1}",
     "{\"generator\":\"abc\",\"lines\":40,\"points\":68,\"seed\":1}"},
    {"furball", "{\"generator\":\"furball\",\"segments\":787327,\"seed\":1}",
     "{\"generator\":\"furball\",\"segments\":3000,\"seed\":1}"},
};
#define DATASET_COUNT ((int)(sizeof datasets / sizeof datasets[0]))

typedef struct options {
    sl_bench_options bench;
    int skip_perf, skip_error, skip_cubic, skip_peers;
    const char *only;
} options;

static double median(double *v, int n) { return sl_bench_median(v, n); }
static size_t segment_count(const sl_dataset *ds) { return sl_bench_segment_count(ds); }

static sl_status make_view(const sl_dataset *ds, double azimuth, double distance, int w, int h, sl_view *view,
                           sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = w;
    view->height = h;
    view->origin = ds->origin;
    view->background[3] = 1.0f;
    sl_orbit o = {azimuth, 20.0, distance, 45.0};
    sl_status st = sl_camera_from_orbit(&o, ds->bounds_min, ds->bounds_max, &view->camera, err);
    return st == SL_OK ? sl_view_init(view, sl_dataset_radius(ds), err) : st;
}

#define VIEWS 2

static void print_peer_cell(const sl_bench_peer_result *r, int v, double ours_ms)
{
    if (r->ok && ours_ms > 0.0)
        printf(" %.1f (%.2f) |", r->median_ms[v], r->median_ms[v] / ours_ms);
    else
        printf(" n/a |");
}

static sl_status bench_speed(sl_gpu *gpu, const options *o, sl_err *err)
{
    const sl_technique *tubes = sl_technique_find("tubes"), *mesh = sl_technique_find("tubes_mesh");
    if (!tubes || !mesh)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "tubes or tubes_mesh is not registered");
    const sl_bench_options *bo = &o->bench;
    sl_params mp0;
    sl_params_init(&mp0, mesh->params, mesh->param_count);
    printf("\n## Speed (%dx%d, %d orbit frames after a warm-up; wall ms to glFinish after the readback)\n\n"
           "tubes: defaults (occlusion_prepass auto); one pass: occlusion_prepass off, the paper's; silhouette "
           "only: boxes with a fragment shader that discards (vertex, geometry and raster cost). Peers read the same "
           "lines (legacy VTK) and cameras: VTK (Debian python3-vtk9): vtkTubeFilter (%d sides, %s, as tubes_mesh) + vtkPolyDataMapper on "
           "the same GL under xvfb-run; Embree round Hermite curves on the CPU, one thread per core. In brackets: peer "
           "ms / tubes ms (above 1: tubes is faster).\n\n",
           bo->width, bo->height, bo->frames, sl_params_int(&mp0, "sides"),
           sl_params_bool(&mp0, "caps") ? "capped" : "open");
    printf("| dataset | segments | view | tubes median (min-max) | GPU ms | one pass | silhouette only | tubes_mesh | "
           "mesh / tubes | VTK (VTK / tubes) | Embree (Embree / tubes) | tubes triangles | tubes MB | mesh MB | "
           "peak RSS MB |\n");
    printf("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const char *names[VIEWS] = {"far", "close"};
    for (int d = 0; d < DATASET_COUNT; d++) {
        if (o->only && !strstr(o->only, datasets[d].name))
            continue;
        sl_dataset *ds = NULL;
        sl_status st = sl_generate_json(datasets[d].json, &ds, err);
        if (st != SL_OK)
            return st;
        size_t segs = segment_count(ds);
        sl_pipeline *p = NULL;
        if ((st = sl_pipeline_create(gpu, &p, err)) != SL_OK) {
            sl_dataset_destroy(ds);
            return st;
        }
        sl_pipeline_set_dataset(p, ds);
        const double far = 1.0 / sin(22.5 * SL_PI / 180.0); /* bounding sphere fits the 45 degree view */
        const sl_bench_orbit orbits[VIEWS] = {{far, 20.0, 45.0}, {far / 3.0, 20.0, 45.0}};
        const sl_bench_view_spec views[VIEWS] = {{names[0], sl_bench_orbit_camera, &orbits[0]},
                                                 {names[1], sl_bench_orbit_camera, &orbits[1]}};
        sl_bench_peer_result vtk = {0}, embree = {0};
        if (!o->skip_peers) {
            sl_line_style style;
            sl_line_style_read(&mp0, ds, &style);
            sl_bench_peer_files files;
            st = sl_bench_peer_files_write(ds, style.radius_scale, NULL, views, VIEWS, bo, &files, err);
            if (st != SL_OK) {
                sl_pipeline_destroy(p);
                return st;
            }
            long cores = sysconf(_SC_NPROCESSORS_ONLN);
            sl_bench_tube_peer_desc pd = {.files = &files, .views = views, .view_count = VIEWS, .options = bo,
                                          .radius = style.radius, .sides = sl_params_int(&mp0, "sides"),
                                          .caps = sl_params_bool(&mp0, "caps"), .threads = cores > 0 ? (int)cores : 1};
            sl_bench_peer_vtk_tubes(&pd, &vtk);
            sl_bench_peer_embree_tubes(&pd, &embree);
            sl_bench_peer_files_remove(&files);
            if (!vtk.ok)
                fprintf(stderr, "bench-tubes: VTK: %s\n", vtk.reason);
            if (!embree.ok)
                fprintf(stderr, "bench-tubes: Embree: %s\n", embree.reason);
        }
        for (int v = 0; v < VIEWS && st == SL_OK; v++) {
            sl_params tp, op, sp, mp;
            sl_params_init(&tp, tubes->params, tubes->param_count);
            sl_params_init(&op, tubes->params, tubes->param_count);
            sl_params_init(&sp, tubes->params, tubes->param_count);
            sl_params_init(&mp, mesh->params, mesh->param_count);
            sl_bench_timing rt, ro, rs, rm;
            if ((st = sl_bench_set_choice(&op, "occlusion_prepass", "off", err)) != SL_OK ||
                (st = sl_bench_set(&sp, "silhouette_only", 1, err)) != SL_OK ||
                (st = sl_bench_time_frames(p, tubes, &tp, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbits[v], &rt,
                                           err)) != SL_OK ||
                (st = sl_bench_time_frames(p, tubes, &op, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbits[v], &ro,
                                           err)) != SL_OK ||
                (st = sl_bench_time_frames(p, tubes, &sp, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbits[v], &rs,
                                           err)) != SL_OK ||
                (st = sl_bench_time_frames(p, mesh, &mp, bo, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbits[v], &rm,
                                           err)) != SL_OK)
                break;
            char gpu_cell[32];
            printf("| %s | %zu | %s | %.1f (%.1f-%.1f) | %s | %.1f | %.1f | %.1f | %.2f |", datasets[d].name, segs,
                   names[v], rt.median_ms, rt.min_ms, rt.max_ms, sl_bench_gpu_cell(&rt, gpu_cell, sizeof gpu_cell),
                   ro.median_ms, rs.median_ms, rm.median_ms, rt.median_ms > 0 ? rm.median_ms / rt.median_ms : 0.0);
            print_peer_cell(&vtk, v, rt.median_ms);
            print_peer_cell(&embree, v, rt.median_ms);
            printf(" %.0f | %.1f | %.1f | %.0f |\n", rt.primitives, rt.gpu_bytes / 1048576.0, rm.gpu_bytes / 1048576.0,
                   fmax(rt.peak_rss_mb, rm.peak_rss_mb));
            fflush(stdout);
        }
        sl_pipeline_destroy(p);
        if (st != SL_OK)
            return st;
    }
    printf("\n(tubes triangles: box faces emitted by the geometry shader per box pass, 2 per face, after culling. "
           "n/a: the peer did not run; bench-tubes says why on stderr.)\n");
    sl_bench_print_gpu_note();
    return SL_OK;
}

/* Depth error of a GPU distance map against the reference, x the local radius. */
typedef struct error_stats { double max_all, max_inner, mean; long mismatch, both, away; } error_stats;

static error_stats compare(const float *gpu, const float *ref, const float *rad, int w, int h)
{
    error_stats e = {0};
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            size_t k = (size_t)j * (size_t)w + (size_t)i;
            int a = gpu[k] > 0.0f, b = ref[k] > 0.0f;
            if (a != b || !isfinite(gpu[k])) {
                e.mismatch++;
                continue;
            }
            if (!a)
                continue;
            double rel = fabs((double)gpu[k] - ref[k]) / fmax(rad[k], 1e-30);
            e.max_all = fmax(e.max_all, rel);
            if (!tubes_ref_silhouette(ref, rad, w, h, i, j)) {
                e.max_inner = fmax(e.max_inner, rel);
                e.away++;
            }
            e.mean += rel;
            e.both++;
        }
    if (e.both)
        e.mean /= (double)e.both;
    return e;
}

static sl_status reference_of(const sl_dataset *ds, const sl_view *view, const sl_params *params, int cubic,
                              float *ref, float *rad, int *seg, sl_err *err)
{
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    const char *mode = sl_params_choice_name(params, "tangents");
    tubes_ref_tangents tangents = strcmp(mode, "catmull_rom") == 0  ? TUBES_REF_TANGENTS_CATMULL_ROM
                                  : strcmp(mode, "data_exact") == 0 ? TUBES_REF_TANGENTS_DATA
                                                                    : TUBES_REF_TANGENTS_AUTO;
    tubes_ref_input in;
    char msg[256];
    if (tubes_ref_input_lines(ds, tangents, style.radius_attribute, style.radius, style.radius_scale, &in, msg,
                              sizeof msg) != 0)
        return sl_err_set(err, SL_ERR_NOMEM, "reference input: %s", msg);
    tubes_ref_desc rd = {.view = view, .origin = in.origin, .segments = in.segments, .segment_count = in.count,
                         .cubic = cubic};
    tubes_ref_render(&rd, ref, rad, seg);
    tubes_ref_input_free(&in);
    return SL_OK;
}

/* The one camera of the error table, for every frame. */
static sl_status fixed_camera(const sl_dataset *ds, int frame, int frames, const void *ctx, sl_camera *camera,
                              sl_err *err)
{
    (void)ds, (void)frame, (void)frames, (void)err;
    *camera = *(const sl_camera *)ctx;
    return SL_OK;
}

/* One row of the error table: the pipeline's technique (set by the caller) rendered 3 times at
 * the view's size (median ms), its distances against the reference, and its frame ms at the
 * benchmark size. */
static sl_status measure(sl_pipeline *p, const sl_technique *tubes, const sl_params *params, const sl_view *view,
                         const sl_bench_options *one, float *gpu_d, const float *ref, const float *rad,
                         error_stats *e, double *small_ms, double *big_ms, sl_err *err)
{
    double ms[3];
    sl_frame_stats stats;
    sl_status st;
    for (int f = 0; f < 3; f++) {
        if ((st = sl_pipeline_render(p, view, 1, &stats, err)) != SL_OK)
            return st;
        ms[f] = stats.wall_ms;
    }
    sl_pipeline_read_distance(p, view, gpu_d);
    sl_bench_timing big;
    if ((st = sl_bench_time_frames(p, tubes, params, one, SL_QUALITY_STILL, fixed_camera, &view->camera, &big, err)) !=
        SL_OK)
        return st;
    *e = compare(gpu_d, ref, rad, view->width, view->height);
    *small_ms = median(ms, 3);
    *big_ms = big.median_ms;
    return SL_OK;
}

static sl_status bench_error(sl_gpu *gpu, const options *o, sl_err *err)
{
    const char *json = "{\"generator\":\"bundle\",\"lines\":100,\"points\":50,\"seed\":2}";
    const int w = 128, h = 128;
    sl_bench_options one = o->bench;
    one.frames = 1;
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json(json, &ds, err);
    if (st != SL_OK)
        return st;
    const sl_technique *tubes = sl_technique_find("tubes");
    sl_params params;
    sl_params_init(&params, tubes->params, tubes->param_count);
    double radius = sl_dataset_radius(ds) / 60.0; /* tubes several pixels wide, so most pixels are not at a rim */
    sl_params_set_numbers(&params, "radius", &radius, 1, err);
    /* root_method and iterations are the GL path's; the Embree backend gets its own row */
    sl_params_set_choice(&params, "backend", "gl", err);
    sl_view view;
    size_t np = (size_t)w * h;
    float *ref = calloc(np, sizeof *ref), *rad = calloc(np, sizeof *rad), *gpu_d = calloc(np, sizeof *gpu_d);
    int *seg = calloc(np, sizeof *seg);
    sl_pipeline *p = NULL;
    if (!ref || !rad || !gpu_d || !seg) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((st = make_view(ds, 30.0, 1.2, w, h, &view, err)) != SL_OK ||
        (st = reference_of(ds, &view, &params, 0, ref, rad, seg, err)) != SL_OK ||
        (st = sl_pipeline_create(gpu, &p, err)) != SL_OK)
        goto done;
    size_t segs = segment_count(ds);
    sl_pipeline_set_dataset(p, ds);
    ds = NULL;
    printf("\n## Depth error against the reference, by root method and iterations\n\n");
    printf("bundle, %zu segments, radius 1/60 of the bounding radius, %dx%d, close view; error in units of the local "
           "tube radius; \"away\" excludes reference silhouettes (3x3 coverage change or depth jump > radius; "
           "tests/support/tubes_reference.c tubes_ref_silhouette).\n\n", segs, w, h);
    printf("| method | iterations | max error (away) | max error (all) | mean error | pixels (away / both hit) | "
           "coverage mismatch | frame ms %dx%d | frame ms %dx%d |\n", w, h, one.width, one.height);
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    /* Every count up to 12: a coarse grid would hide the real fewest count. */
    static const int iters[] = {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 16, 20, 24, 32};
    const int ni = (int)(sizeof iters / sizeof iters[0]);
    const char *const *methods = NULL;
    int nm = 0;
    int pm = sl_params_find(&params, "root_method");
    if (pm >= 0) {
        methods = params.schema[pm].choices;
        while (methods[nm])
            nm++;
    }
    /* Fewest iterations per method at several error levels (max away from
     * silhouettes <= level, mean <= level / 10): the bound 1e-3 r,
     * then tighter, down to near float resolution (~3.5e-5 r here). */
    static const double levels[] = {1e-3, 1e-4, 5e-5};
    enum { NL = 3 };
    int need[8][NL];
    for (int m = 0; m < nm && m < 8; m++) {
        for (int l = 0; l < NL; l++)
            need[m][l] = -1;
        for (int k = 0; k < ni; k++) {
            double it = iters[k];
            sl_params_set_numbers(&params, "iterations", &it, 1, err);
            sl_params_set_choice(&params, "root_method", methods[m], err);
            if ((st = sl_pipeline_set_technique(p, tubes, &params, err)) != SL_OK)
                goto done;
            error_stats e;
            double small_ms, big_ms;
            if ((st = measure(p, tubes, &params, &view, &one, gpu_d, ref, rad, &e, &small_ms, &big_ms, err)) != SL_OK)
                goto done;
            for (int l = 0; l < NL; l++)
                if (need[m][l] < 0 && e.max_inner <= levels[l] && e.mean <= 0.1 * levels[l])
                    need[m][l] = iters[k];
            printf("| %s | %d | %.3g | %.3g | %.3g | %ld / %ld | %ld | %.1f | %.1f |\n", methods[m], iters[k],
                   e.max_inner, e.max_all, e.mean, e.away, e.both, e.mismatch, small_ms, big_ms);
            fflush(stdout);
        }
    }
    if (sl_params_set_choice(&params, "backend", "embree", err) == SL_OK &&
        sl_pipeline_set_technique(p, tubes, &params, err) == SL_OK) {
        error_stats e;
        double small_ms, big_ms;
        if ((st = measure(p, tubes, &params, &view, &one, gpu_d, ref, rad, &e, &small_ms, &big_ms, err)) != SL_OK)
            goto done;
        printf("| backend=embree (exact double where bent) | - | %.3g | %.3g | %.3g | %ld / %ld | %ld | %.1f | %.1f |\n",
               e.max_inner, e.max_all, e.mean, e.away, e.both, e.mismatch, small_ms, big_ms);
    } else {
        printf("| backend=embree | - | not built: %s | | | | | | |\n", err->message);
    }
    sl_params_set_choice(&params, "backend", "gl", err);
    printf("\nFewest iterations (of those tried) for max error away from silhouettes <= E and mean error <= E/10 "
           "(x radius); in brackets, how many times fewer than %s (-1: not reached):\n\n| E |", nm > 0 ? methods[0] : "");
    for (int m = 0; m < nm && m < 8; m++)
        printf(" %s |", methods[m]);
    printf("\n|---:|");
    for (int m = 0; m < nm && m < 8; m++)
        printf("---:|");
    printf("\n");
    for (int l = 0; l < NL; l++) {
        printf("| %g |", levels[l]);
        for (int m = 0; m < nm && m < 8; m++) {
            printf(" %d", need[m][l]);
            if (m > 0 && need[0][l] > 0 && need[m][l] > 0)
                printf(" (%.2fx)", (double)need[0][l] / need[m][l]);
            printf(" |");
        }
        printf("\n");
    }
done:
    sl_pipeline_destroy(p);
    sl_dataset_destroy(ds);
    free(ref);
    free(rad);
    free(gpu_d);
    free(seg);
    return st;
}

/* Max and mean over segments of max_t |quadratic pair(t) - cubic Hermite(t)| / radius. */
static void curve_deviation(const sl_dataset *ds, const sl_params *params, double *dmax, double *dmean)
{
    *dmax = *dmean = 0.0;
    sl_tubes_nodes n;
    sl_err err;
    if (sl_tubes_nodes_build(&ds->lines, (sl_tubes_tangents)sl_params_choice(params, "tangents"), -1, &n, &err) != SL_OK)
        return;
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    for (size_t s = 0; s < n.segment_count; s++) {
        const float *a = n.geometry + (size_t)n.segments[2 * s] * SL_TUBES_NODE_FLOATS;
        const float *b = n.geometry + (size_t)n.segments[2 * s + 1] * SL_TUBES_NODE_FLOATS;
        double r = n.has_radii ? 0.5 * (a[3] + b[3]) * style.radius_scale : style.radius;
        double worst = 0.0;
        for (int k = 0; k <= 64; k++) {
            double t = k / 64.0, d2 = 0.0;
            for (int c = 0; c < 3; c++) {
                double p0 = a[c], t0 = a[4 + c], p1 = b[c], t1 = b[4 + c];
                double t2 = t * t, t3 = t2 * t;
                double cub = (2 * t3 - 3 * t2 + 1) * p0 + (t3 - 2 * t2 + t) * t0 + (-2 * t3 + 3 * t2) * p1 + (t3 - t2) * t1;
                double a2 = p0 + t0 / 3, b2 = p1 - t1 / 3, m = 0.5 * (a2 + b2), quad;
                if (t <= 0.5) {
                    double u = 2 * t, v = 1 - u;
                    quad = v * v * p0 + 2 * u * v * a2 + u * u * m;
                } else {
                    double u = 2 * t - 1, v = 1 - u;
                    quad = v * v * m + 2 * u * v * b2 + u * u * p1;
                }
                d2 += (quad - cub) * (quad - cub);
            }
            worst = fmax(worst, sqrt(d2));
        }
        worst /= fmax(r, 1e-30);
        *dmax = fmax(*dmax, worst);
        *dmean += worst;
    }
    if (n.segment_count)
        *dmean /= (double)n.segment_count;
    sl_tubes_nodes_deinit(&n);
}

static sl_status bench_cubic(const options *o, sl_err *err)
{
    /* Tubes several pixels wide (radius 1/60 of the bounding radius where the
     * data gives none, close view as in the error table), so that most pixels
     * hit are away from a silhouette; at the default radius in a far view
     * tubes are below a pixel and "away" would be an empty set. */
    const int w = 128, h = 128;
    printf("\n## Quadratic pair against the true cubic Hermite sweep (reference, both)\n\n");
    printf("Smaller versions of the generated datasets, %dx%d, close view (distance 1.2), radius 1/60 of the bounding "
           "radius (hotroom: its data radii). Curve deviation: max and mean over segments of |quadratic pair(t) - "
           "cubic(t)| at equal parameter (an upper bound of the distance between the curves); depth difference on "
           "pixels both hit away from silhouettes (3x3 coverage change or depth jump > radius of the cubic "
           "reference), and over all pixels both hit (there a rim may switch to another tube); pixel counts of both "
           "sets. All in units of the tube radius.\n\n", w, h);
    printf("| dataset | segments | curve dev. max | curve dev. mean | depth max (away) | depth mean (away) | "
           "pixels away | depth max (all) | pixels both hit | coverage mismatch |\n"
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const sl_technique *tubes = sl_technique_find("tubes");
    for (int d = 0; d < DATASET_COUNT; d++) {
        if (o->only && !strstr(o->only, datasets[d].name))
            continue;
        sl_dataset *ds = NULL;
        sl_status st = sl_generate_json(datasets[d].json_small, &ds, err);
        if (st != SL_OK)
            return st;
        sl_params params;
        sl_params_init(&params, tubes->params, tubes->param_count);
        double radius = sl_dataset_radius(ds) / 60.0;
        sl_params_set_numbers(&params, "radius", &radius, 1, err);
        size_t np = (size_t)w * h;
        float *q = calloc(np, sizeof *q), *qr = calloc(np, sizeof *qr), *c = calloc(np, sizeof *c),
              *cr = calloc(np, sizeof *cr);
        int *seg = calloc(np, sizeof *seg);
        sl_view view;
        if (!q || !qr || !c || !cr || !seg)
            st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
        if (st == SL_OK && (st = make_view(ds, 30.0, 1.2, w, h, &view, err)) == SL_OK &&
            (st = reference_of(ds, &view, &params, 0, q, qr, seg, err)) == SL_OK &&
            (st = reference_of(ds, &view, &params, 1, c, cr, seg, err)) == SL_OK) {
            double mx = 0.0, mean = 0.0, mx_all = 0.0;
            long both = 0, away = 0, mism = 0;
            for (int j = 0; j < h; j++)
                for (int i = 0; i < w; i++) {
                    size_t k = (size_t)j * w + i;
                    int a = q[k] > 0.0f, b = c[k] > 0.0f;
                    mism += a != b;
                    if (!(a && b))
                        continue;
                    double e = fabs((double)q[k] - c[k]) / fmax(cr[k], 1e-30);
                    mx_all = fmax(mx_all, e);
                    both++;
                    if (tubes_ref_silhouette(c, cr, w, h, i, j))
                        continue;
                    mx = fmax(mx, e);
                    mean += e;
                    away++;
                }
            double dev_max, dev_mean;
            curve_deviation(ds, &params, &dev_max, &dev_mean);
            printf("| %s | %zu | %.3g | %.3g | %.3g | %.3g | %ld | %.3g | %ld | %ld |\n", datasets[d].name,
                   segment_count(ds), dev_max, dev_mean, mx, away ? mean / away : 0.0, away, mx_all, both, mism);
            fflush(stdout);
        }
        free(q); free(qr); free(c); free(cr); free(seg);
        sl_dataset_destroy(ds);
        if (st != SL_OK)
            return st;
    }
    return SL_OK;
}

int main(int argc, char **argv)
{
    options o = {0};
    sl_bench_options_init(&o.bench, 3);
    for (int i = 1; i < argc; i++) {
        int c = sl_bench_option(&o.bench, argc, argv, &i, "bench-tubes");
        if (c < 0)
            return 1;
        if (c > 0)
            continue;
        const char *a = argv[i];
        if (strcmp(a, "--skip-perf") == 0) o.skip_perf = 1;
        else if (strcmp(a, "--skip-error") == 0) o.skip_error = 1;
        else if (strcmp(a, "--skip-cubic") == 0) o.skip_cubic = 1;
        else if (strcmp(a, "--skip-peers") == 0) o.skip_peers = 1;
        else if (strcmp(a, "--datasets") == 0 && i + 1 < argc) {
            o.only = argv[++i];
            int known = 0;
            for (int d = 0; d < DATASET_COUNT; d++)
                known += strstr(o.only, datasets[d].name) != NULL;
            if (!known) {
                fprintf(stderr, "bench-tubes: --datasets names none of fibers,hotroom,bundle,brain,furball\n");
                return 1;
            }
        }
        else {
            fprintf(stderr, "usage: bench-tubes %s [--datasets fibers,hotroom,bundle,brain,furball]\n"
                            "                   [--skip-perf] [--skip-error] [--skip-cubic] [--skip-peers]\n",
                    SL_BENCH_OPTIONS_HELP);
            return 1;
        }
    }
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "bench-tubes: GPU: %s\n", err.message);
        return 3;
    }
    printf("# bench-tubes — %s\n", sl_gpu_renderer(gpu));
    sl_status st = SL_OK;
    if (!o.skip_perf)
        st = bench_speed(gpu, &o, &err);
    if (st == SL_OK && !o.skip_error)
        st = bench_error(gpu, &o, &err);
    if (st == SL_OK && !o.skip_cubic)
        st = bench_cubic(&o, &err);
    sl_gpu_destroy(gpu);
    if (st != SL_OK) {
        fprintf(stderr, "bench-tubes: %s\n", err.message);
        return 2;
    }
    return 0;
}
