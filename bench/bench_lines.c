/* bench_lines.c — every opaque line technique against the peers a user would otherwise pick, on one file.
 *
 *   bench-lines [--small | --size WxH] [--frames N] [--lines N] [--points N] [--only thin|thick] [--skip-peers]
 *
 * Data: `random_walk` (AR(1) steps about 0.01-0.05 long in a +-3 box), thin
 * (radius 0.004-0.006) and thick (0.04-0.06), written once as legacy VTK with
 * the radius as a point scalar; our techniques load that very file
 * (radius_attribute = its `radius`; voxel_lines: one radius, the middle), VTK's
 * tube filter (bench/vtk_tubes.py, same llvmpipe) and Embree round Hermite
 * curves (peer-embree-tubes, CPU) read it too, with the same cameras: an eye
 * circling the data at distance 8 (frame 0: eye (0, 0, 8)), fov 45, constant
 * colour. `tubes` in both executions (backend auto = embree on software GL; gl with
 * and without its occlusion pre-pass). Prints wall ms (median / min / max), GPU ms,
 * prepare, peak RSS, GPU memory and the ratios peer / ours. Checks nothing. Main thread = render thread.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "data/sl_generate.h"
#include "data/sl_load.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"

typedef struct line_set { const char *name; double rmin, rmax; } line_set;

static const line_set sets[] = {{"thin", 0.004, 0.006}, {"thick", 0.04, 0.06}};
#define SET_COUNT ((int)(sizeof sets / sizeof sets[0]))

typedef struct row {
    const char *technique, *label;
    const char *param;       /* one enum parameter that differs from the defaults, or NULL */
    const char *choice;
    const char *param2, *choice2; /* a second one, or NULL */
} row;

static const row rows[] = {
    {"tubes", "tubes (default: backend auto)", NULL, NULL, NULL, NULL},
    {"tubes", "tubes backend=embree", "backend", "embree", NULL, NULL},
    {"tubes", "tubes backend=gl (occlusion pre-pass auto)", "backend", "gl", NULL, NULL},
    {"tubes", "tubes backend=gl, pre-pass on", "occlusion_prepass", "on", "backend", "gl"},
    {"tubes", "tubes backend=gl, one pass (paper)", "occlusion_prepass", "off", "backend", "gl"},
    {"tubes_mesh", "tubes_mesh (12 sides)", NULL, NULL, NULL, NULL},
    {"voxel_lines", "voxel_lines opaque (default: backend auto)", NULL, NULL, NULL, NULL},
    {"voxel_lines", "voxel_lines opaque backend=gl", "backend", "gl", NULL, NULL},
};
#define ROW_COUNT ((int)(sizeof rows / sizeof rows[0]))

static int attribute_index(const sl_dataset *ds, const char *name)
{
    for (int a = 0; a < ds->lines.attribute_count; a++)
        if (strcmp(ds->lines.attributes[a].name, name) == 0)
            return a;
    return -1;
}

static sl_status params_for(const sl_technique *t, const row *r, const sl_dataset *ds, const line_set *set,
                            sl_params *p, sl_err *err)
{
    sl_params_init(p, t->params, t->param_count);
    sl_status st = sl_bench_set(p, "attribute", -1, err); /* constant colour, as the peers */
    if (st == SL_OK && sl_params_find(p, "radius_attribute") >= 0)
        st = sl_bench_set(p, "radius_attribute", attribute_index(ds, "radius"), err);
    if (st == SL_OK)
        st = sl_bench_set(p, "radius", 0.5 * (set->rmin + set->rmax), err);
    if (st == SL_OK && r->param)
        st = sl_bench_set_choice(p, r->param, r->choice, err);
    if (st == SL_OK && r->param2)
        st = sl_bench_set_choice(p, r->param2, r->choice2, err);
    return st;
}

static void print_ratio(double peer_ms, double ours_ms, int ok)
{
    if (ok && ours_ms > 0.0)
        printf(" %.2f |", peer_ms / ours_ms);
    else
        printf(" |");
}

static sl_status bench_set(sl_gpu *gpu, const line_set *set, int lines, int points, int skip_peers,
                           const sl_bench_options *o, sl_err *err)
{
    char json[256];
    snprintf(json, sizeof json,
             "{\"generator\":\"random_walk\",\"lines\":%d,\"points\":%d,\"radius_min\":%g,\"radius_max\":%g,\"seed\":1}",
             lines, points, set->rmin, set->rmax);
    sl_dataset *generated = NULL, *ds = NULL;
    sl_status st = sl_generate_json(json, &generated, err);
    if (st != SL_OK)
        return st;
    const sl_bench_circle circle = {.target = {0, 0, 0}, .radius = 8.0, .fov_y_deg = 45.0};
    const sl_bench_view_spec view = {"circle", sl_bench_circle_camera, &circle};
    sl_bench_peer_files files;
    st = sl_bench_peer_files_write(generated, 1.0f, NULL, &view, 1, o, &files, err);
    /* The file's coordinates are the generated world less its origin, and that
     * is the loaded dataset's world: our circle is about the same point. */
    const sl_vec3 shift = generated->origin;
    const sl_bench_circle ours = {.target = {-shift.x, -shift.y, -shift.z}, .radius = 8.0, .fov_y_deg = 45.0};
    sl_dataset_destroy(generated);
    if (st != SL_OK)
        return st;
    sl_pipeline *p = NULL;
    if ((st = sl_load_file(files.lines, &ds, err)) != SL_OK || (st = sl_pipeline_create(gpu, &p, err)) != SL_OK) {
        sl_dataset_destroy(ds);
        sl_bench_peer_files_remove(&files);
        return st;
    }
    sl_pipeline_set_dataset(p, ds);
    ds = (sl_dataset *)sl_pipeline_dataset(p);

    sl_bench_peer_result vtk = {0}, embree = {0};
    if (skip_peers) {
        snprintf(vtk.reason, sizeof vtk.reason, "skipped (--skip-peers)");
        snprintf(embree.reason, sizeof embree.reason, "skipped (--skip-peers)");
    } else {
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        sl_bench_tube_peer_desc d = {.files = &files, .views = &view, .view_count = 1, .options = o,
                                     .radius = 0.5 * (set->rmin + set->rmax), .sides = 12, .caps = 1,
                                     .threads = cores > 0 ? (int)cores : 1};
        fprintf(stderr, "bench-lines: %s: VTK\n", set->name);
        sl_bench_peer_vtk_tubes(&d, &vtk);
        fprintf(stderr, "bench-lines: %s: Embree\n", set->name);
        sl_bench_peer_embree_tubes(&d, &embree);
    }

    printf("\n## %s: %d lines x %d points, radius %g-%g, %dx%d, %d frames\n\n", set->name, lines, points, set->rmin,
           set->rmax, o->width, o->height, o->frames);
    printf("| renderer | median ms | min | max | GPU ms | prepare ms | peak RSS MB | GPU MB | VTK / this | Embree / this |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int r = 0; r < ROW_COUNT && st == SL_OK; r++) {
        const sl_technique *t = sl_technique_find(rows[r].technique);
        sl_params params;
        sl_bench_timing tm;
        fprintf(stderr, "bench-lines: %s: %s\n", set->name, rows[r].label);
        if (!t)
            st = sl_err_set(err, SL_ERR_UNSUPPORTED, "%s is not registered", rows[r].technique);
        if (st == SL_OK && (st = params_for(t, &rows[r], ds, set, &params, err)) == SL_OK)
            st = sl_bench_time_frames(p, t, &params, o, SL_QUALITY_STILL, sl_bench_circle_camera, &ours, &tm, err);
        if (st != SL_OK)
            break;
        char gpu_cell[32];
        printf("| %s | %.1f | %.1f | %.1f | %s | %.0f | %.0f%s | %.1f |", rows[r].label, tm.median_ms, tm.min_ms,
               tm.max_ms, sl_bench_gpu_cell(&tm, gpu_cell, sizeof gpu_cell), tm.prepare_ms, tm.peak_rss_mb,
               tm.peak_rss_since_start ? "*" : "", tm.gpu_bytes / 1048576.0);
        print_ratio(vtk.median_ms[0], tm.median_ms, vtk.ok);
        print_ratio(embree.median_ms[0], tm.median_ms, embree.ok);
        printf("\n");
        fflush(stdout);
    }
    if (st == SL_OK) {
        if (vtk.ok)
            printf("| VTK %s vtkTubeFilter (12 sides, capped) + vtkPolyDataMapper | %.1f | %.1f | %.1f | | %.0f (filter) | | | 1 | |\n",
                   vtk.version, vtk.median_ms[0], vtk.min_ms[0], vtk.max_ms[0], vtk.build_ms);
        else
            printf("| VTK tube filter: not available (%s) | | | | | | | | | |\n", vtk.reason);
        if (embree.ok)
            printf("| Embree %s round Hermite curves, CPU | %.1f | %.1f | %.1f | | %.0f (BVH) | | | | 1 |\n",
                   embree.version, embree.median_ms[0], embree.min_ms[0], embree.max_ms[0], embree.build_ms);
        else
            printf("| Embree: not available (%s) | | | | | | | | | |\n", embree.reason);
        if (vtk.ok)
            printf("\n(VTK's GL: %s.)\n", vtk.renderer);
        sl_bench_print_gpu_note();
    }
    sl_pipeline_destroy(p);
    sl_bench_peer_files_remove(&files);
    return st;
}

int main(int argc, char **argv)
{
    sl_bench_options o;
    sl_bench_options_init(&o, 3);
    int lines = 1000, points = 200, skip_peers = 0;
    const char *only = NULL;
    for (int i = 1; i < argc; i++) {
        int c = sl_bench_option(&o, argc, argv, &i, "bench-lines");
        if (c < 0)
            return 1;
        if (c > 0)
            continue;
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--skip-peers") == 0) {
            skip_peers = 1;
        } else if (strcmp(a, "--lines") == 0 || strcmp(a, "--points") == 0) {
            int is_lines = a[2] == 'l';
            if (!v || sl_bench_parse_int(v, is_lines ? 1 : 2, is_lines ? 1000000 : 10000, is_lines ? &lines : &points)) {
                fprintf(stderr, "bench-lines: %s wants a count in [%d, %d]\n", a, is_lines ? 1 : 2,
                        is_lines ? 1000000 : 10000);
                return 1;
            }
            i++;
        } else if (strcmp(a, "--only") == 0 && v) {
            if (strcmp(v, "thin") != 0 && strcmp(v, "thick") != 0) {
                fprintf(stderr, "bench-lines: --only wants thin or thick, not %s\n", v);
                return 1;
            }
            only = v;
            i++;
        } else {
            fprintf(stderr, "usage: bench-lines %s [--lines N] [--points N] [--only thin|thick] [--skip-peers]\n",
                    SL_BENCH_OPTIONS_HELP);
            return 1;
        }
    }
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "bench-lines: GPU: %s\n", err.message);
        return 3;
    }
    printf("# bench-lines — %s\n\nWall ms: first GL command of a frame to glFinish after reading the whole frame "
           "back (VTK: Render + WaitForCompletion + the same readback; Embree: all threads joined, image in host "
           "memory). Ratios: peer ms / our ms, so above 1 means ours is faster.\n",
           sl_gpu_renderer(gpu));
    sl_status st = SL_OK;
    for (int s = 0; s < SET_COUNT && st == SL_OK; s++)
        if (!only || strcmp(only, sets[s].name) == 0)
            st = bench_set(gpu, &sets[s], lines, points, skip_peers, &o, &err);
    sl_gpu_destroy(gpu);
    if (st != SL_OK) {
        fprintf(stderr, "bench-lines: %s\n", err.message);
        return 2;
    }
    return 0;
}
