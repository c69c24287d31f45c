/* bench_tubes_mesh.c — run time against error of the `tubes_mesh` baseline, per cross-section size.
 *
 *   bench-tubes-mesh [--size WxH] [--frames N] [--sides 6,8,12,16,24,30]
 *
 * The only accuracy knob of a swept-circle mesh is `sides` (n vertices per
 * ring): the prism lies inside the true tube, so the depth error is at most
 * r (1 - cos(pi/n)) head-on and grows towards the silhouettes.
 * 1. Error: one straight tube of radius r seen side-on (no caps), every
 *    pixel's depth against the exact ray-cylinder distance computed here in
 *    double from the camera formula of proto/scene.md (not the renderer's
 *    matrices): max and mean |error| / r over the pixels both hit, max over
 *    pixels hit nearly head-on (incidence cosine >= 0.9) next to the bound,
 *    and coverage mismatch.
 * 2. Time: median GPU ms over an orbit of N frames on the built-in tornado
 *    (1000 lines x 200 points) and furball (100k segments), far view,
 *    triangles, prepare ms and GPU memory, with the ratio to the default n.
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

#define MAX_SIDES 16

typedef struct options {
    int width, height, frames;
    int sides[MAX_SIDES];
    int side_count;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.width = 256, .height = 144, .frames = 5, .sides = {6, 8, 12, 16, 24, 30}, .side_count = 6};
    for (int i = 1; i < argc; i += 2) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--size") == 0 && v) {
            if (sscanf(v, "%dx%d", &o->width, &o->height) != 2 || o->width < 16 || o->height < 16 ||
                o->width > 8192 || o->height > 8192)
                return fprintf(stderr, "bench-tubes-mesh: --size must be WxH in [16, 8192]\n"), 0;
        } else if (strcmp(a, "--frames") == 0 && v) {
            o->frames = atoi(v);
            if (o->frames < 1 || o->frames > 100000)
                return fprintf(stderr, "bench-tubes-mesh: --frames must be in [1, 100000]\n"), 0;
        } else if (strcmp(a, "--sides") == 0 && v) {
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
            fprintf(stderr, "usage: bench-tubes-mesh [--size WxH] [--frames N] [--sides 6,8,12,...]\n");
            return 0;
        }
    }
    return 1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
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
        /* The reference camera, built here from the scene.md formula. */
        double f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]}, up[3] = {0, 1, 0};
        double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        for (int k = 0; k < 3; k++)
            f[k] /= fl;
        double r[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
        double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        for (int k = 0; k < 3; k++)
            r[k] /= rl;
        double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
        double th = tan(fov * M_PI / 360.0), aspect = (double)o->width / o->height;
        double sum = 0.0;
        size_t mismatch = 0, hits = 0;
        *row = (error_row){0};
        for (int j = 0; j < o->height; j++)
            for (int i = 0; i < o->width; i++) {
                double sx = (2.0 * (i + 0.5) / o->width - 1.0) * th * aspect, sy = (1.0 - 2.0 * (j + 0.5) / o->height) * th;
                double d[3], dl = 0.0;
                for (int k = 0; k < 3; k++) {
                    d[k] = f[k] + sx * r[k] + sy * u[k];
                    dl += d[k] * d[k];
                }
                for (int k = 0; k < 3; k++)
                    d[k] /= sqrt(dl);
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

typedef struct time_row { double ms, prepare_ms, triangles, mb; } time_row;

static sl_status measure_time(sl_gpu *gpu, const options *o, const char *builtin, const int *sides, int count,
                              time_row *rows, sl_err *err)
{
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json(sl_builtin_lookup(builtin), &ds, err);
    sl_pipeline *p = NULL;
    if (st != SL_OK || (st = pipeline_for(gpu, ds, &p, err)) != SL_OK)
        return st;
    double *ms = malloc((size_t)o->frames * sizeof *ms);
    if (!ms)
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    for (int s = 0; st == SL_OK && s < count; s++) {
        if ((st = set_technique(p, sides[s], err)) != SL_OK)
            break;
        sl_frame_stats stats = {0};
        for (int f = -1; st == SL_OK && f < o->frames; f++) { /* frame -1 prepares, untimed */
            sl_view view = {.width = o->width, .height = o->height, .origin = ds->origin, .background = {0, 0, 0, 1}};
            sl_orbit orbit = {360.0 * (f < 0 ? 0 : f) / o->frames, 20.0, 2.5, 45.0};
            if ((st = sl_camera_from_orbit(&orbit, ds->bounds_min, ds->bounds_max, &view.camera, err)) != SL_OK ||
                (st = sl_view_init(&view, sl_dataset_radius(ds), err)) != SL_OK ||
                (st = sl_pipeline_render(p, &view, 1, &stats, err)) != SL_OK)
                break;
            if (f < 0)
                rows[s].prepare_ms = stats.prepare_ms;
            else
                ms[f] = stats.gpu_ms > 0.0 ? stats.gpu_ms : stats.wall_ms;
        }
        if (st == SL_OK) {
            rows[s].ms = median(ms, o->frames);
            rows[s].triangles = stats.render.primitives;
            rows[s].mb = (double)stats.gpu_bytes / (1024.0 * 1024.0);
        }
    }
    free(ms);
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
        time_row rows[MAX_SIDES] = {{0}};
        if ((st = measure_time(gpu, &o, datasets[d], o.sides, o.side_count, rows, &err)) != SL_OK)
            break;
        int ref = 0;
        for (int s = 0; s < o.side_count; s++)
            if (o.sides[s] == 12)
                ref = s;
        printf("\n## Frame time, built-in `%s` (%dx%d, far orbit, median of %d frames)\n\n", datasets[d], o.width,
               o.height, o.frames);
        printf("| sides | GPU ms | ratio to %d sides | triangles | prepare ms | GPU MB |\n", o.sides[ref]);
        printf("|---:|---:|---:|---:|---:|---:|\n");
        for (int s = 0; s < o.side_count; s++)
            printf("| %d | %.2f | %.2f | %.0f | %.0f | %.1f |\n", o.sides[s], rows[s].ms,
                   rows[ref].ms > 0.0 ? rows[s].ms / rows[ref].ms : 0.0, rows[s].triangles, rows[s].prepare_ms,
                   rows[s].mb);
    }
    if (st != SL_OK)
        fprintf(stderr, "bench-tubes-mesh: %s\n", err.message);
    sl_gpu_destroy(gpu);
    return st == SL_OK ? 0 : 1;
}
