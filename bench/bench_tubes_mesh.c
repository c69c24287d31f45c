/* bench_tubes_mesh.c — run time against error of the `tubes_mesh` baseline, per cross-section size.
 *
 *   bench-tubes-mesh [--small | --size WxH] [--frames N] [--sides 6,8,12,16,24,30]
 *
 * The only accuracy knob of a swept-circle mesh is `sides` (n vertices per
 * ring): the prism lies inside the true tube, so the depth error is at most
 * r (1 - cos(pi/n)) head-on and grows towards the silhouettes.
 * 1. Error: one straight tube of radius r seen side-on (no caps), every
 *    pixel's depth against the exact ray-cylinder distance computed here in
 *    double on the rays of proto/scene.md (tests/support/ref_camera.h, not
 *    the renderer's matrices): max and mean |error| / r over the pixels both
 *    hit, max over pixels hit nearly head-on (incidence cosine >= 0.9) next to the bound,
 *    and coverage mismatch.
 * 2. Time through the harness (bench/harness/sl_bench.h: wall ms to glFinish
 *    after the readback, an orbit of N frames after a warm-up, default
 *    1280x720) on the built-in tornado (1000 lines x 200 points) and furball
 *    (100k segments), far view: median / min / max, GPU-timer ms, triangles,
 *    prepare ms, GPU memory and peak RSS, with the ratio to the default n.
 * Prints Markdown; checks nothing (tests/render/tubes_mesh.cmake does).
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "pipeline/sl_pipeline.h"
#include "harness/sl_bench.h"
#include "ref_camera.h"

#define MAX_SIDES 16

typedef struct options {
    sl_bench_options bench;
    int width, height, frames; /* copies of bench's */
    int sides[MAX_SIDES];
    int side_count;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.sides = {6, 8, 12, 16, 24, 30}, .side_count = 6};
    sl_bench_options_init(&o->bench, 5);
    for (int i = 1; i < argc; i++) {
        int c = sl_bench_option(&o->bench, argc, argv, &i, "bench-tubes-mesh");
        if (c < 0)
            return 0;
        if (c > 0)
            continue;
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--sides") == 0 && v) {
            i++;
            o->side_count = 0;
            for (const char *p = v; *p && o->side_count < MAX_SIDES;) {
                int n = (int)strtol(p, (char **)&p, 10);
                if (n < 6 || n > 30)
                    return fprintf(stderr, "bench-tubes-mesh: --sides values must be in [6, 30]\n"), 0;
                o->sides[o->side_count++] = n;
                if (*p == ',')
                    p++;
                else if (*p)
                    return fprintf(stderr, "bench-tubes-mesh: --sides is a comma-separated list\n"), 0;
            }
        } else {
            fprintf(stderr, "usage: bench-tubes-mesh %s [--sides 6,8,12,...]\n", SL_BENCH_OPTIONS_HELP);
            return 0;
        }
    }
    o->width = o->bench.width;
    o->height = o->bench.height;
    o->frames = o->bench.frames;
    return 1;
}

static sl_status set_technique(sl_pipeline *p, int sides, sl_err *err)
{
    const sl_technique *t = sl_technique_find("tubes_mesh");
    sl_params params;
    sl_params_init(&params, t->params, t->param_count);
    double n = sides, caps = 0.0;
    sl_status st = sl_params_set_numbers(&params, "sides", &n, 1, err);
    if (st == SL_OK)
        st = sl_params_set_numbers(&params, "caps", &caps, 1, err);
    return st == SL_OK ? sl_pipeline_set_technique(p, t, &params, err) : st;
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

/* ---- 1. error of one straight tube against the exact cylinder ---- */

#define TUBE_RADIUS 0.1
#define TUBE_HALF_LENGTH 1.0

typedef struct error_row { double max_err, mean_err, max_head_on, mismatch_pct; size_t both; } error_row;

/* Exact distance along unit ray (o, d) to the cylinder around the x axis of
 * radius r with |x| <= half, entering through the mantle; -1 when missed. */
static double cylinder_hit(const double o[3], const double d[3], double r, double half, double *cos_in)
{
    double a = d[1] * d[1] + d[2] * d[2], b = o[1] * d[1] + o[2] * d[2], c = o[1] * o[1] + o[2] * o[2] - r * r;
    double disc = b * b - a * c;
    if (a <= 0.0 || disc < 0.0)
        return -1.0;
    double t = (-b - sqrt(disc)) / a;
    double x = o[0] + t * d[0];
    if (t <= 0.0 || fabs(x) > half)
        return -1.0;
    double ny = (o[1] + t * d[1]) / r, nz = (o[2] + t * d[2]) / r;
    *cos_in = -(ny * d[1] + nz * d[2]);
    return t;
}

static sl_status measure_error(sl_gpu *gpu, const options *o, int sides, error_row *row, sl_err *err)
{
    char json[256];
    snprintf(json, sizeof json,
             "{\"nodes\":[{\"p\":[%g,0,0],\"t\":[%g,0,0],\"r\":%g},{\"p\":[%g,0,0],\"t\":[%g,0,0],\"r\":%g}],"
             "\"segments\":[[0,1]]}",
             -TUBE_HALF_LENGTH, 2 * TUBE_HALF_LENGTH, TUBE_RADIUS, TUBE_HALF_LENGTH, 2 * TUBE_HALF_LENGTH, TUBE_RADIUS);
    cJSON *root = cJSON_Parse(json);
    sl_dataset *ds = NULL;
    sl_status st = sl_hermite_dataset_from_json(root, "straight tube", &ds, err);
    cJSON_Delete(root);
    sl_pipeline *p = NULL;
    if (st != SL_OK || (st = pipeline_for(gpu, ds, &p, err)) != SL_OK)
        return st;
    /* Side-on, slightly from above, the tube filling about half the width. */
    const double eye[3] = {0.1, 0.35, 2.2}, target[3] = {0.0, 0.0, 0.0}, fov = 45.0;
    sl_view view = {.width = o->width, .height = o->height, .origin = ds->origin, .background = {0, 0, 0, 1}};
    view.camera = (sl_camera){.eye = sl_v3(eye[0], eye[1], eye[2]), .target = sl_v3(target[0], target[1], target[2]),
                              .up = sl_v3(0, 1, 0), .fov_y_deg = fov};
    size_t n = (size_t)o->width * (size_t)o->height;
    float *dist = malloc(n * sizeof *dist);
    sl_frame_stats stats;
    if (!dist)
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    if (st == SL_OK && (st = sl_view_init(&view, sl_dataset_radius(ds), err)) == SL_OK &&
        (st = set_technique(p, sides, err)) == SL_OK && (st = sl_pipeline_render(p, &view, 1, &stats, err)) == SL_OK)
        sl_pipeline_read_distance(p, &view, dist);
    if (st == SL_OK) {
        /* The reference camera: proto/scene.md's rays in double (tests/support/ref_camera.h). */
        const double up[3] = {0, 1, 0};
        ref_camera cam;
        if (ref_camera_init(&cam, eye, target, up, fov, o->width, o->height) != 0)
            st = sl_err_set(err, SL_ERR_INVALID, "degenerate reference camera");
        double sum = 0.0;
        size_t mismatch = 0, hits = 0;
        *row = (error_row){0};
        for (int j = 0; st == SL_OK && j < o->height; j++)
            for (int i = 0; i < o->width; i++) {
                double d[3];
                ref_camera_ray(&cam, i, j, d);
                double cos_in = 0.0, t_ref = cylinder_hit(eye, d, TUBE_RADIUS, TUBE_HALF_LENGTH, &cos_in);
                double t_gpu = dist[(size_t)j * o->width + i];
                int ref_hit = t_ref > 0.0, gpu_hit = t_gpu > 0.0;
                hits += ref_hit;
                if (ref_hit != gpu_hit) {
                    mismatch++;
                    continue;
                }
                if (!ref_hit)
                    continue;
                double e = fabs(t_gpu - t_ref) / TUBE_RADIUS;
                row->both++;
                sum += e;
                if (e > row->max_err)
                    row->max_err = e;
                if (cos_in >= 0.9 && e > row->max_head_on)
                    row->max_head_on = e;
            }
        row->mean_err = row->both ? sum / (double)row->both : 0.0;
        row->mismatch_pct = hits ? 100.0 * (double)mismatch / (double)hits : 0.0;
    }
    free(dist);
    sl_pipeline_destroy(p);
    return st;
}

/* ---- 2. frame time on generated data ---- */

typedef struct time_row { sl_bench_timing t; } time_row;

static sl_status measure_time(sl_gpu *gpu, const options *o, const char *builtin, const int *sides, int count,
                              time_row *rows, sl_err *err)
{
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json(sl_builtin_lookup(builtin), &ds, err);
    sl_pipeline *p = NULL;
    if (st != SL_OK || (st = pipeline_for(gpu, ds, &p, err)) != SL_OK)
        return st;
    const sl_technique *t = sl_technique_find("tubes_mesh");
    const sl_bench_orbit orbit = {.distance = 2.5, .elevation_deg = 20, .fov_y_deg = 45};
    for (int s = 0; st == SL_OK && s < count; s++) {
        sl_params params;
        sl_params_init(&params, t->params, t->param_count);
        if ((st = sl_bench_set(&params, "sides", sides[s], err)) != SL_OK)
            break;
        st = sl_bench_time_frames(p, t, &params, &o->bench, SL_QUALITY_STILL, sl_bench_orbit_camera, &orbit,
                                  &rows[s].t, err);
    }
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
        fprintf(stderr, "bench-tubes-mesh: %s\n", err.message);
        return 3;
    }
    printf("# bench-tubes-mesh — %s\n\n", sl_gpu_renderer(gpu));
    printf("## Depth error against the exact cylinder (%dx%d, radius %g, side-on, no caps)\n\n", o.width, o.height,
           TUBE_RADIUS);
    printf("Errors in units of the radius r over the pixels both hit; head-on: incidence cosine >= 0.9; "
           "bound: 1 - cos(pi/n), the inscribed polygon's error straight on (it grows as 1/c towards the rims, and at "
           "the silhouette a grazing ray can miss a polygon face and hit the far side, so the max is up to ~r).\n\n");
    printf("| sides | max error / r | mean error / r | max head-on / r | bound 1-cos(pi/n) | coverage mismatch %% |\n");
    printf("|---:|---:|---:|---:|---:|---:|\n");
    sl_status st = SL_OK;
    for (int s = 0; st == SL_OK && s < o.side_count; s++) {
        error_row row;
        if ((st = measure_error(gpu, &o, o.sides[s], &row, &err)) == SL_OK)
            printf("| %d | %.2e | %.2e | %.2e | %.2e | %.2f |\n", o.sides[s], row.max_err, row.mean_err,
                   row.max_head_on, 1.0 - cos(M_PI / o.sides[s]), row.mismatch_pct);
    }
    static const char *const datasets[] = {"tornado", "furball"};
    for (int d = 0; st == SL_OK && d < 2; d++) {
        time_row rows[MAX_SIDES];
        memset(rows, 0, sizeof rows);
        if ((st = measure_time(gpu, &o, datasets[d], o.sides, o.side_count, rows, &err)) != SL_OK)
            break;
        int ref = 0;
        for (int s = 0; s < o.side_count; s++)
            if (o.sides[s] == 12)
                ref = s;
        printf("\n## Frame time, built-in `%s` (%dx%d, far orbit of %d frames after a warm-up)\n\n", datasets[d], o.width,
               o.height, o.frames);
        printf("| sides | wall ms median (min-max) | GPU ms | ratio to %d sides | triangles | prepare ms | GPU MB | "
               "peak RSS MB |\n", o.sides[ref]);
        printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (int s = 0; s < o.side_count; s++) {
            const sl_bench_timing *t = &rows[s].t;
            char gpu_cell[32];
            printf("| %d | %.1f (%.1f-%.1f) | %s | %.2f | %.0f | %.0f | %.1f | %.0f |\n", o.sides[s], t->median_ms,
                   t->min_ms, t->max_ms, sl_bench_gpu_cell(t, gpu_cell, sizeof gpu_cell),
                   rows[ref].t.median_ms > 0.0 ? t->median_ms / rows[ref].t.median_ms : 0.0, t->primitives,
                   t->prepare_ms, t->gpu_bytes / 1048576.0, t->peak_rss_mb);
        }
        sl_bench_print_gpu_note();
    }
    if (st != SL_OK)
        fprintf(stderr, "bench-tubes-mesh: %s\n", err.message);
    sl_gpu_destroy(gpu);
    return st == SL_OK ? 0 : 1;
}
