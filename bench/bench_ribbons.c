/* bench_ribbons.c — the paper's Fig. 8 for `ribbons`, its peer VTK, and run time against depth error.
 *
 *   bench-ribbons [--small | --size WxH | --4k] [--frames N] [--pipelines a,b] [--sides 4,6,8,12,16,32]
 *                 [--segments S] [--no-vtk] [--skip-sweep] [--skip-fig8]
 *
 * Neuhauser et al., "Efficient high-quality rendering of ribbons and twisted
 * lines", Sec. 6 / Fig. 8; docs/ribbons_plan.md §5.
 * 1. Fig. 8 on generated data of S segments (default 1,000,000): a curly
 *    `furball` (transport frame) and `abc` streamlines (ceil(S / 300) lines
 *    of 301 points; helicity frame). Every pipeline the technique's schema lists
 *    (the `pipeline` enum's choices, read at run time; --pipelines picks) x
 *    {plain, halo, twist (3 lines), halo + twist}: wall ms median (min-max)
 *    through bench/harness/sl_bench.h (first GL command to glFinish after
 *    the readback, an orbit of N frames after a warm-up, distance 2.5,
 *    elevation 20, default 1280x720; --4k = 3840x2160), GPU-timer ms,
 *    ratio to pulling plain, triangles, GPU memory (the technique's
 *    gpu_bytes), prepare ms, peak RSS. Then VTK's vtkRibbonFilter (flat
 *    ribbons, Width = r, oriented by the normals `ribbons` itself uses,
 *    exported from ribbons_prep) under xvfb-run on the same lines, cameras
 *    and size (bench/vtk_ribbons.py via sl_bench_peer_vtk_ribbons), with the
 *    ratios, and the targets printed as met / not met.
 * 2. Run time against error: per N of --sides, one straight ribbon (r 0.1,
 *    width_ratio 0.25, data frame, min_pixels 0, halo off) seen face-on and
 *    obliquely at the bench size: max and mean |depth error| / r against the
 *    analytic elliptic profile (tests/support/ribbons_depth_error.h: rays
 *    of proto/scene.md in double, ray-ellipse in double), max over
 *    near-head-on pixels, largest N-gon bound met, max error / bound, pixels
 *    outside the bound, coverage mismatch; and the frame ms of that N on the
 *    abc set (plain), with the pipeline `pulling` (or the first picked).
 * Prints Markdown; checks nothing (tests/render/ribbons.cmake does).
 * Main thread = render thread.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_clock.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"
#include "line_style/sl_line_style.h"
#include "pipeline/sl_pipeline.h"
#include "ref_camera.h"
#include "ribbons/ribbons_prep.h"
#include "ribbons_depth_error.h"

#define PROGRAM "bench-ribbons"
#define MAX_PIPELINES 8
#define MAX_SIDES 16
#define VARIANTS 4
#define TWIST_LINES 3

typedef struct options {
    sl_bench_options bench;
    const char *pipelines[MAX_PIPELINES]; /* choice names from the schema */
    int pipeline_count;
    int sides[MAX_SIDES];
    int side_count;
    long segments;
    int no_vtk, skip_sweep, skip_fig8;
} options;

static const char *const variant_names[VARIANTS] = {"plain", "halo", "twist", "halo+twist"};

static const sl_technique *ribbons(void)
{
    return sl_technique_find("ribbons");
}

/* The `pipeline` enum's choices, or NULL. */
static const char *const *pipeline_choices(void)
{
    const sl_technique *t = ribbons();
    for (int i = 0; t && i < t->param_count; i++)
        if (strcmp(t->params[i].name, "pipeline") == 0 && t->params[i].type == SL_PARAM_ENUM)
            return t->params[i].choices;
    return NULL;
}

static int parse_pipelines(const char *list, options *o)
{
    const char *const *choices = pipeline_choices();
    o->pipeline_count = 0;
    for (const char *p = list; *p;) {
        size_t n = strcspn(p, ",");
        int found = 0;
        for (int c = 0; choices && choices[c]; c++)
            if (strlen(choices[c]) == n && strncmp(choices[c], p, n) == 0 && o->pipeline_count < MAX_PIPELINES) {
                o->pipelines[o->pipeline_count++] = choices[c];
                found = 1;
            }
        if (!found) {
            fprintf(stderr, PROGRAM ": no pipeline '%.*s'; this build has:", (int)n, p);
            for (int c = 0; choices && choices[c]; c++)
                fprintf(stderr, " %s", choices[c]);
            fprintf(stderr, "\n");
            return 0;
        }
        p += n + (p[n] == ',');
    }
    return o->pipeline_count > 0;
}

static int parse_sides(const char *list, options *o)
{
    o->side_count = 0;
    for (const char *p = list; *p && o->side_count < MAX_SIDES;) {
        char *end;
        long n = strtol(p, &end, 10);
        if (end == p || n < 3 || n > 32 || (*end && *end != ','))
            return fprintf(stderr, PROGRAM ": --sides is a comma-separated list of integers in [3, 32]\n"), 0;
        o->sides[o->side_count++] = (int)n;
        p = *end ? end + 1 : end;
    }
    return o->side_count > 0;
}

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.sides = {4, 6, 8, 12, 16, 32}, .side_count = 6, .segments = 1000000};
    sl_bench_options_init(&o->bench, 5);
    const char *const *choices = pipeline_choices();
    for (int c = 0; choices && choices[c] && c < MAX_PIPELINES; c++)
        o->pipelines[o->pipeline_count++] = choices[c];
    for (int i = 1; i < argc; i++) {
        int c = sl_bench_option(&o->bench, argc, argv, &i, PROGRAM);
        if (c < 0)
            return 0;
        if (c > 0)
            continue;
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int segments = 0;
        if (strcmp(a, "--4k") == 0) {
            o->bench.width = 3840;
            o->bench.height = 2160;
        } else if (strcmp(a, "--no-vtk") == 0) {
            o->no_vtk = 1;
        } else if (strcmp(a, "--skip-sweep") == 0) {
            o->skip_sweep = 1;
        } else if (strcmp(a, "--skip-fig8") == 0) {
            o->skip_fig8 = 1;
        } else if (strcmp(a, "--pipelines") == 0 && v) {
            if (!parse_pipelines(argv[++i], o))
                return 0;
        } else if (strcmp(a, "--sides") == 0 && v) {
            if (!parse_sides(argv[++i], o))
                return 0;
        } else if (strcmp(a, "--segments") == 0 && v && sl_bench_parse_int(v, 600, 10000000, &segments) == 0) {
            o->segments = segments;
            i++;
        } else {
            fprintf(stderr, "usage: " PROGRAM " %s [--4k] [--pipelines a,b] [--sides 4,6,8,12,16,32]\n"
                            "       [--segments S (600..1e7)] [--no-vtk] [--skip-sweep] [--skip-fig8]\n",
                    SL_BENCH_OPTIONS_HELP);
            return 0;
        }
    }
    if (o->pipeline_count == 0)
        return fprintf(stderr, PROGRAM ": the ribbons technique lists no pipeline\n"), 0;
    return 1;
}

/* A pipeline that owns ds (destroyed on failure too). */
static sl_status pipeline_for(sl_gpu *gpu, sl_dataset *ds, sl_pipeline **p, sl_err *err)
{
    sl_status st = sl_pipeline_create(gpu, p, err);
    if (st != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    sl_pipeline_set_dataset(*p, ds);
    return SL_OK;
}

/* ribbons' parameters for one pipeline and variant (0 plain, 1 halo, 2 twist, 3 both). */
static sl_status variant_params(sl_params *params, const char *pipeline, int variant, int sides, sl_err *err)
{
    const sl_technique *t = ribbons();
    sl_params_init(params, t->params, t->param_count);
    sl_status st = sl_bench_set_choice(params, "pipeline", pipeline, err);
    if (st == SL_OK)
        st = sl_bench_set(params, "halo", variant & 1, err);
    if (st == SL_OK)
        st = sl_bench_set(params, "twist_lines", variant & 2 ? TWIST_LINES : 0, err);
    if (st == SL_OK)
        st = sl_bench_set(params, "sides", sides, err);
    return st;
}

static const sl_bench_orbit fig8_orbit = {.distance = 2.5, .elevation_deg = 20, .fov_y_deg = 45};

/* ---- the normals ribbons draws with, for the VTK peer ---- */

/* 3 floats per vertex (caller frees): the face normal n of ribbons_prep,
 * rotated about t by theta = twist_scale R in the helicity frame as the
 * vertex shader does (ribbons_ring.glsl: cos theta n + sin theta t x n). */
static sl_status ribbon_normals(const sl_dataset *ds, const sl_params *params, float **out, sl_err *err)
{
    *out = NULL;
    sl_ribbons_frame frame;
    sl_status st = sl_ribbons_frame_resolve(ds, (sl_ribbons_frame)sl_params_choice(params, "frame"), &frame, err);
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    sl_ribbons_points pts;
    if (st != SL_OK || (st = sl_ribbons_points_init(&pts, &ds->lines, frame, style.radius_attribute, err)) != SL_OK)
        return st;
    float *n = malloc((pts.count ? pts.count : 1) * 3 * sizeof *n);
    if (!n) {
        sl_ribbons_points_deinit(&pts);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu normals", pts.count);
    }
    double f = sl_params_float(params, "twist_scale");
    for (size_t i = 0; i < pts.count; i++) {
        const float *nv = pts.normal_twist + 4 * i, *tv = pts.tangent_slope + 4 * i;
        double theta = frame == SL_RIBBONS_FRAME_HELICITY ? f * nv[3] : 0.0, c = cos(theta), s = sin(theta);
        double txn[3] = {tv[1] * nv[2] - tv[2] * nv[1], tv[2] * nv[0] - tv[0] * nv[2], tv[0] * nv[1] - tv[1] * nv[0]};
        for (int k = 0; k < 3; k++)
            n[3 * i + k] = (float)(c * nv[k] + s * txn[k]);
    }
    sl_ribbons_points_deinit(&pts);
    *out = n;
    return SL_OK;
}

/* ---- 1. Fig. 8 ---- */

typedef struct fig8_table {
    sl_bench_timing t[MAX_PIPELINES][VARIANTS];
    sl_bench_peer_result vtk;
    int vtk_ran;
    size_t segments;
    double seconds;
} fig8_table;

static void print_target(const char *what, double value, int measurable, int met, const char *missing)
{
    if (!measurable)
        printf("- %s: not measured (%s)\n", what, missing);
    else
        printf("- %s: %s (%.2f)\n", what, met ? "met" : "not met", value);
}

static int pipeline_index(const options *o, const char *name)
{
    for (int i = 0; i < o->pipeline_count; i++)
        if (strcmp(o->pipelines[i], name) == 0)
            return i;
    return -1;
}

static void print_fig8(const options *o, const char *label, const char *generator_json, const fig8_table *tb)
{
    int pull = pipeline_index(o, "pulling"), geo = pipeline_index(o, "geometry"), mesh = pipeline_index(o, "mesh");
    int flat = pipeline_index(o, "flat");
    int ref = pull >= 0 ? pull : 0;
    double ref_ms = tb->t[ref][0].median_ms;
    printf("\n## Fig. 8: %s, %zu segments, %dx%d (orbit of %d frames after a warm-up; %.0f s for this table)\n\n",
           label, tb->segments, o->bench.width, o->bench.height, o->bench.frames, tb->seconds);
    printf("Data: `%s`.\n\n", generator_json);
    printf("| pipeline | variant | wall ms median (min-max) | GPU ms | ratio to %s plain | triangles | GPU MB | "
           "prepare ms | peak RSS MB |\n", o->pipelines[ref]);
    printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int p = 0; p < o->pipeline_count; p++)
        for (int v = 0; v < VARIANTS; v++) {
            const sl_bench_timing *t = &tb->t[p][v];
            char gpu_cell[32];
            sl_bench_gpu_cell(t, gpu_cell, sizeof gpu_cell);
            printf("| %s | %s | %.1f (%.1f-%.1f) | %s | %.2f | %.0f | %.1f | %.0f | %.0f |\n", o->pipelines[p],
                   variant_names[v], t->median_ms, t->min_ms, t->max_ms, gpu_cell,
                   ref_ms > 0.0 ? t->median_ms / ref_ms : 0.0, t->primitives, t->gpu_bytes / 1e6, t->prepare_ms,
                   t->peak_rss_mb);
        }
    const sl_bench_peer_result *r = &tb->vtk;
    if (!tb->vtk_ran)
        printf("| VTK vtkRibbonFilter | flat | not run (--no-vtk) | | | | | | |\n");
    else if (!r->ok)
        printf("| VTK vtkRibbonFilter | flat | n/a: %s | | | | | | |\n", r->reason);
    else {
        printf("| VTK %s vtkRibbonFilter + vtkPolyDataMapper | flat, our normals | %.1f (%.1f-%.1f) | | %.2f | %.0f | "
               "%.1f (mesh) | %.0f (filter) | |\n", r->version, r->median_ms[0], r->min_ms[0], r->max_ms[0],
               ref_ms > 0.0 ? r->median_ms[0] / ref_ms : 0.0, r->triangles, r->mesh_bytes / 1e6, r->build_ms);
        if (flat >= 0 && tb->t[flat][0].median_ms > 0.0)
            printf("\nVTK / flat plain: %.2f.", r->median_ms[0] / tb->t[flat][0].median_ms);
        printf("\nVTK ran %.0f s in all (xvfb-run start-up and the filter included; first frame, which uploads the "
               "mesh, %.0f ms; GL: %s). Its GPU memory is not observable; the MB is the filter output's "
               "(vtkDataObject::GetActualMemorySize), which the mapper uploads.\n", r->seconds, r->first_frame_ms,
               r->renderer);
    }
    sl_bench_print_gpu_note();
    printf("\nTargets (the issue's), from the medians above:\n\n");
    const sl_bench_timing *pp = pull >= 0 ? tb->t[pull] : NULL;
    const char *no_pull = "no `pulling` picked";
    if (pp && geo >= 0)
        print_target("pulling faster than geometry (pulling / geometry < 1)", pp[0].median_ms / tb->t[geo][0].median_ms,
                     1, pp[0].median_ms < tb->t[geo][0].median_ms, "");
    else
        print_target("pulling faster than geometry", 0, 0, 0, pp ? "no `geometry` pipeline in this run" : no_pull);
    if (pp && mesh >= 0) {
        double ratio = pp[0].median_ms / tb->t[mesh][0].median_ms;
        print_target("pulling within 1.2x of mesh (pulling / mesh <= 1.2)", ratio, 1, ratio <= 1.2, "");
        double mem = (double)tb->t[mesh][0].gpu_bytes / (double)(pp[0].gpu_bytes ? pp[0].gpu_bytes : 1);
        print_target("at least 5x less GPU memory than mesh (mesh / pulling >= 5)", mem, 1, mem >= 5.0, "");
    } else {
        const char *why = pp ? "no `mesh` pipeline in this run" : no_pull;
        print_target("pulling within 1.2x of mesh", 0, 0, 0, why);
        print_target("at least 5x less GPU memory than mesh", 0, 0, 0, why);
    }
    if (pp) {
        double ratio = pp[3].median_ms / pp[0].median_ms;
        print_target("halos + twist lines cost at most 25 % (pulling halo+twist / plain <= 1.25)", ratio, 1,
                     ratio <= 1.25, "");
    } else
        print_target("halos + twist lines cost at most 25 %", 0, 0, 0, no_pull);
}

static sl_status run_fig8(sl_gpu *gpu, const options *o, const char *label, const char *generator_json,
                          fig8_table *tb, sl_err *err)
{
    memset(tb, 0, sizeof *tb);
    double t0 = sl_clock_ms();
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json(generator_json, &ds, err);
    sl_pipeline *p = NULL;
    if (st != SL_OK || (st = pipeline_for(gpu, ds, &p, err)) != SL_OK)
        return st;
    tb->segments = sl_bench_segment_count(ds);
    /* Each pipeline's first variant is run once untimed (warm-up + 1 frame)
     * before its timed run, so no variant is timed right after its pipeline's
     * prepare. (furball plain stayed the slowest variant with it, and also
     * when timed last: that is the variant, not the order.) */
    sl_bench_options priming = o->bench;
    priming.frames = 1;
    for (int k = 0; st == SL_OK && k < o->pipeline_count; k++)
        for (int v = 0; st == SL_OK && v < VARIANTS; v++) {
            sl_params params;
            if ((st = variant_params(&params, o->pipelines[k], v, 8, err)) != SL_OK)
                break;
            fprintf(stderr, PROGRAM ": %s %s %s\n", label, o->pipelines[k], variant_names[v]);
            sl_bench_timing primed = {0};
            if (v == 0 && (st = sl_bench_time_frames(p, ribbons(), &params, &priming, SL_QUALITY_STILL,
                                                     sl_bench_orbit_camera, &fig8_orbit, &primed, err)) != SL_OK)
                break;
            st = sl_bench_time_frames(p, ribbons(), &params, &o->bench, SL_QUALITY_STILL, sl_bench_orbit_camera,
                                      &fig8_orbit, &tb->t[k][v], err);
            if (v == 0) { /* the priming run prepared */
                tb->t[k][v].prepare_ms = primed.prepare_ms;
                tb->t[k][v].peak_rss_mb = fmax(tb->t[k][v].peak_rss_mb, primed.peak_rss_mb);
            }
        }
    if (st == SL_OK && !o->no_vtk) {
        sl_params params;
        float *normals = NULL;
        sl_line_style style;
        sl_bench_peer_files files;
        const sl_bench_view_spec view = {"orbit", sl_bench_orbit_camera, &fig8_orbit};
        if ((st = variant_params(&params, o->pipelines[0], 0, 8, err)) == SL_OK &&
            (st = ribbon_normals(ds, &params, &normals, err)) == SL_OK) {
            sl_line_style_read(&params, ds, &style);
            st = sl_bench_peer_files_write(ds, style.radius_scale, normals, &view, 1, &o->bench, &files, err);
        }
        free(normals);
        if (st == SL_OK) {
            fprintf(stderr, PROGRAM ": %s VTK\n", label);
            const sl_bench_tube_peer_desc pd = {.files = &files, .views = &view, .view_count = 1,
                                                .options = &o->bench, .radius = style.radius};
            sl_bench_peer_vtk_ribbons(&pd, &tb->vtk);
            tb->vtk_ran = 1;
            sl_bench_peer_files_remove(&files);
            if (!tb->vtk.ok)
                fprintf(stderr, PROGRAM ": VTK: %s\n", tb->vtk.reason);
        }
    }
    sl_pipeline_destroy(p);
    tb->seconds = (sl_clock_ms() - t0) / 1000.0;
    return st;
}

/* ---- 2. run time against error ---- */

#define RIBBON_RADIUS 0.1
#define RIBBON_WIDTH_RATIO 0.25
#define RIBBON_POINTS 21 /* x from -1 to 1 */
#define ERROR_VIEWS 2

typedef struct error_view { const char *name; double eye[3], up[3]; } error_view;

/* Face-on: along the face normal z (the wide side shows); oblique: the test's camera (ribbon_oblique.json). */
static const error_view error_views[ERROR_VIEWS] = {{"face-on", {0.1, 0.3, 2.2}, {0, 1, 0}},
                                                    {"oblique", {0.4, 1.6, 1.2}, {0, 0, 1}}};

/* One straight ribbon along x from -1 to 1 with data normals z, as an in-memory legacy VTK file. */
static sl_status straight_ribbon(sl_dataset **out, sl_err *err)
{
    char text[4096];
    size_t n = (size_t)snprintf(text, sizeof text, "# vtk DataFile Version 3.0\nstraight ribbon\nASCII\n"
                                                   "DATASET POLYDATA\nPOINTS %d double\n", RIBBON_POINTS);
    for (int i = 0; i < RIBBON_POINTS; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "%.17g 0 0\n", -1.0 + 2.0 * i / (RIBBON_POINTS - 1));
    n += (size_t)snprintf(text + n, sizeof text - n, "LINES 1 %d\n%d", RIBBON_POINTS + 1, RIBBON_POINTS);
    for (int i = 0; i < RIBBON_POINTS; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, " %d", i);
    n += (size_t)snprintf(text + n, sizeof text - n, "\nPOINT_DATA %d\nNORMALS n float\n", RIBBON_POINTS);
    for (int i = 0; i < RIBBON_POINTS; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "0 0 1\n");
    return sl_load_vtk((const uint8_t *)text, n, "straight ribbon", out, err);
}

static sl_status measure_error(sl_pipeline *p, const sl_dataset *ds, const options *o, const char *pipeline,
                               int sides, const error_view *ev, ribbons_depth_error *e, sl_err *err)
{
    const int w = o->bench.width, h = o->bench.height;
    const double target[3] = {0, 0, 0}, fov = 45.0;
    sl_view view = {.width = w, .height = h, .origin = ds->origin, .background = {0, 0, 0, 1}};
    view.camera = (sl_camera){.eye = sl_v3(ev->eye[0], ev->eye[1], ev->eye[2]), .target = sl_v3(0, 0, 0),
                              .up = sl_v3(ev->up[0], ev->up[1], ev->up[2]), .fov_y_deg = fov};
    sl_params params;
    sl_status st = variant_params(&params, pipeline, 0, sides, err);
    const char *frame = "data";
    if (st == SL_OK)
        st = sl_bench_set_choice(&params, "frame", frame, err);
    if (st == SL_OK)
        st = sl_bench_set(&params, "radius", RIBBON_RADIUS, err);
    if (st == SL_OK)
        st = sl_bench_set(&params, "width_ratio", RIBBON_WIDTH_RATIO, err);
    if (st == SL_OK)
        st = sl_bench_set(&params, "min_thickness", 0.0, err);
    if (st == SL_OK)
        st = sl_bench_set(&params, "min_pixels", 0.0, err);
    float *dist = st == SL_OK ? malloc((size_t)w * (size_t)h * sizeof *dist) : NULL;
    if (st == SL_OK && !dist)
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    sl_frame_stats stats;
    if (st == SL_OK && (st = sl_view_init(&view, sl_dataset_radius(ds), err)) == SL_OK &&
        (st = sl_pipeline_set_technique(p, ribbons(), &params, err)) == SL_OK &&
        (st = sl_pipeline_render(p, &view, 1, &stats, err)) == SL_OK)
        sl_pipeline_read_distance(p, &view, dist);
    ref_camera cam;
    if (st == SL_OK && ref_camera_init(&cam, ev->eye, target, ev->up, fov, w, h) != 0)
        st = sl_err_set(err, SL_ERR_INVALID, "degenerate reference camera");
    if (st == SL_OK) {
        /* The segment of straight_ribbon(): n = z (data normals), b = t x n = -y. */
        const ribbons_ref_segment seg = {.x0 = {0, 0, 0}, .n = {0, 0, 1}, .b = {0, -1, 0}, .t = {1, 0, 0},
                                         .r = RIBBON_RADIUS, .w = RIBBON_WIDTH_RATIO, .half_len = 1.0};
        const ribbons_depth_limits limits = {.sides = sides, .head_on_cos = 0.9, .eps = 1e-4, .margin_px = 1.0 / 64};
        ribbons_depth_error_measure(dist, &cam, &seg, &limits, e);
    }
    free(dist);
    return st;
}

static sl_status run_sweep(sl_gpu *gpu, const options *o, const char *abc_json, sl_err *err)
{
    int pi = pipeline_index(o, "pulling");
    const char *pipeline = o->pipelines[pi >= 0 ? pi : 0];
    ribbons_depth_error errors[MAX_SIDES][ERROR_VIEWS];
    sl_bench_timing times[MAX_SIDES];
    memset(times, 0, sizeof times);
    sl_dataset *ds = NULL;
    sl_pipeline *p = NULL;
    sl_status st = straight_ribbon(&ds, err);
    if (st != SL_OK || (st = pipeline_for(gpu, ds, &p, err)) != SL_OK)
        return st;
    for (int s = 0; st == SL_OK && s < o->side_count; s++)
        for (int v = 0; st == SL_OK && v < ERROR_VIEWS; v++)
            st = measure_error(p, ds, o, pipeline, o->sides[s], &error_views[v], &errors[s][v], err);
    sl_pipeline_destroy(p);
    p = NULL;
    double t0 = sl_clock_ms();
    size_t abc_segments = 0;
    if (st == SL_OK && (st = sl_generate_json(abc_json, &ds, err)) == SL_OK &&
        (st = pipeline_for(gpu, ds, &p, err)) == SL_OK) {
        abc_segments = sl_bench_segment_count(ds);
        for (int s = 0; st == SL_OK && s < o->side_count; s++) {
            sl_params params;
            if ((st = variant_params(&params, pipeline, 0, o->sides[s], err)) != SL_OK)
                break;
            fprintf(stderr, PROGRAM ": sweep %s sides %d\n", pipeline, o->sides[s]);
            st = sl_bench_time_frames(p, ribbons(), &params, &o->bench, SL_QUALITY_STILL, sl_bench_orbit_camera,
                                      &fig8_orbit, &times[s], err);
        }
    }
    sl_pipeline_destroy(p);
    if (st != SL_OK)
        return st;
    printf("\n## Run time against error: `%s`, circle subdivisions N (%dx%d; %.0f s for the timings)\n\n", pipeline,
           o->bench.width, o->bench.height, (sl_clock_ms() - t0) / 1000.0);
    printf("Error: one straight ribbon, r = %g, width_ratio %g (thin semi-axis %g), data frame, min_pixels 0, halo "
           "off, against the analytic elliptic profile (ray-elliptic-cylinder in double on the rays of "
           "proto/scene.md, tests/support/ribbons_depth_error.h), |error| / r over the pixels both hit; head-on: "
           "circle-space incidence cosine >= 0.9; bound: ribbons_ref_polygon_bound per pixel, the largest met "
           "(grazing pixels without a finite bound are left out); outside: pixels in front of the profile by more "
           "than 1e-4 or behind it by more than the bound + 1e-4; mismatch: pixels one of the two hits, %% of the "
           "profile's. Frame ms: `abc` (%zu-segment set of the Fig. 8 table), plain, orbit of %d frames.\n\n",
           RIBBON_RADIUS, RIBBON_WIDTH_RATIO, RIBBON_RADIUS * RIBBON_WIDTH_RATIO, abc_segments,
           o->bench.frames);
    printf("| N | view | max error / r | mean error / r | max head-on / r | largest bound / r | max error / bound | "
           "outside bound | coverage mismatch %% | abc frame ms median (min-max) | triangles |\n");
    printf("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int s = 0; s < o->side_count; s++)
        for (int v = 0; v < ERROR_VIEWS; v++) {
            const ribbons_depth_error *e = &errors[s][v];
            const sl_bench_timing *t = &times[s];
            char ms[64] = "", tri[32] = "";
            if (v == 0) {
                snprintf(ms, sizeof ms, "%.1f (%.1f-%.1f)", t->median_ms, t->min_ms, t->max_ms);
                snprintf(tri, sizeof tri, "%.0f", t->primitives);
            }
            printf("| %d | %s | %.2e | %.2e | %.2e | %.2e | %.3f | %zu | %.2f | %s | %s |\n", o->sides[s],
                   error_views[v].name, e->max_err, e->mean_err, e->max_head_on, e->max_bound, e->max_over_bound,
                   e->outside_bound, e->ref_hits ? 100.0 * (double)e->mismatch / (double)e->ref_hits : 0.0, ms, tri);
        }
    return SL_OK;
}

int main(int argc, char **argv)
{
    options o;
    if (!parse_args(argc, argv, &o))
        return 2;
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, PROGRAM ": %s\n", err.message);
        return 3;
    }
    char furball[128], abc[128];
    long abc_lines = (o.segments + 299) / 300; /* 1M: 3334 lines x 300 segments = 1,000,200 */
    snprintf(furball, sizeof furball, "{\"generator\":\"furball\",\"segments\":%ld,\"seed\":1}", o.segments);
    snprintf(abc, sizeof abc, "{\"generator\":\"abc\",\"lines\":%ld,\"points\":301,\"seed\":1}", abc_lines);
    printf("# " PROGRAM " — %s\n\nPipelines (from the schema's `pipeline` choices):", sl_gpu_renderer(gpu));
    for (int i = 0; i < o.pipeline_count; i++)
        printf(" `%s`", o.pipelines[i]);
    printf(". Variants: plain (halo off, no twist lines), halo (object space, width 0.1), twist (%d lines), "
           "halo+twist; N = 8, frustum culling on, the default radius (1/300 of the bounding radius).\n",
           TWIST_LINES);
    double t0 = sl_clock_ms();
    sl_status st = SL_OK;
    if (!o.skip_fig8) {
        static fig8_table tb; /* large: per pipeline and variant */
        const char *labels[2] = {"`furball` (curly, transport frame)", "`abc` streamlines (helicity frame)"};
        const char *json[2] = {furball, abc};
        for (int d = 0; st == SL_OK && d < 2; d++)
            if ((st = run_fig8(gpu, &o, labels[d], json[d], &tb, &err)) == SL_OK)
                print_fig8(&o, labels[d], json[d], &tb);
    }
    if (st == SL_OK && !o.skip_sweep)
        st = run_sweep(gpu, &o, abc, &err);
    if (st == SL_OK)
        printf("\nWhole run: %.0f s.\n", (sl_clock_ms() - t0) / 1000.0);
    else
        fprintf(stderr, PROGRAM ": %s\n", err.message);
    sl_gpu_destroy(gpu);
    return st == SL_OK ? 0 : 1;
}
