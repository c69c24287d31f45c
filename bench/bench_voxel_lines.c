/* bench-voxel-lines — the tables of Kanzler et al. (TVCG 2018) on generated data.
 *
 * Table 1: memory of the voxel model (5-byte headers + bit-packed lines, as
 * the paper counts it) and CPU / GPU preprocessing time per grid V^3 and
 * quantization Q^2, next to the original geometry (3 floats + 1 byte per
 * vertex) and the linked-list memory lines_oit needed at 25 % opacity.
 * Table 2: median wall frame ms through the harness (bench/harness/sl_bench.h:
 * render + readback + glFinish, an orbit after a warm-up) at 25 % opacity
 * (lines_oit vs voxel_lines, still = with neighbour search, and interactive =
 * own voxel only) and opaque (tubes_mesh vs voxel_lines), with ratios, GPU
 * memory and the GPU-timer ms as a second column (flagged where it missed
 * the work: on llvmpipe it does for voxel_lines).
 * Datasets stand in for the paper's (generator, lines x points): Tornado
 * (tornado 1000x250), Aneurysm I/II (bundle 4700x410, 9200x367), Turbulence
 * (abc 50000x220), Forecast (abc 212000x13). --scale multiplies the line
 * counts (default 0.05, so the whole run takes minutes on llvmpipe).
 * Usage: bench-voxel-lines [--scale S] [--small | --size WxH] [--frames N] [--grid V] [--quant Q]
 *        [--table1-grids 256/128,256/32,128/128,128/32,64/8] [--only NAME] [--no-table1] [--no-table2]
 * Runs on the main thread, which owns the GL context.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "harness/sl_bench.h"
#include "pipeline/sl_pipeline.h"
#include "voxel_lines/voxel_gpu.h"
#include "voxel_lines/voxel_grid.h"

typedef struct bench_data {
    const char *name, *generator;
    int lines, points;
} bench_data;

static const bench_data datasets[] = {
    {"Tornado", "tornado", 1000, 250},
    {"Aneurysm I (bundle)", "bundle", 4700, 410},
    {"Aneurysm II (bundle)", "bundle", 9200, 367},
    {"Turbulence (abc)", "abc", 50000, 220},
    {"Forecast (abc, short)", "abc", 212000, 13},
};
#define DATASET_COUNT (int)(sizeof datasets / sizeof datasets[0])

typedef struct options {
    double scale;
    sl_bench_options bench;
    int grid, quant;
    int t1_grid[8], t1_quant[8], t1_count;
    const char *only;
    int table1, table2;
} options;

/* Times one technique through the harness; *t->median_ms is NAN on error. */
static void time_technique(sl_pipeline *pipe, const char *name, double opacity, const options *o, sl_quality quality,
                           const sl_bench_orbit *orbit, sl_bench_timing *t)
{
    const sl_technique *tech = sl_technique_find(name);
    sl_params p;
    sl_err err = {0};
    sl_params_init(&p, tech->params, tech->param_count);
    char q[16];
    snprintf(q, sizeof q, "%d", o->quant);
    sl_status st = sl_bench_set(&p, "attribute", -1, &err);
    if (st == SL_OK && sl_params_find(&p, "opacity") >= 0)
        st = sl_bench_set(&p, "opacity", opacity, &err);
    if (st == SL_OK && strcmp(name, "voxel_lines") == 0) {
        st = sl_bench_set(&p, "grid", o->grid, &err);
        if (st == SL_OK)
            st = sl_bench_set_choice(&p, "quantization", q, &err);
    }
    if (st == SL_OK)
        st = sl_bench_time_frames(pipe, tech, &p, &o->bench, quality, sl_bench_orbit_camera, orbit, t, &err);
    if (st != SL_OK) {
        fprintf(stderr, "bench-voxel-lines: %s: %s\n", name, err.message);
        memset(t, 0, sizeof *t);
        t->median_ms = NAN;
    }
}

static int parse_settings(const char *s, options *o)
{
    o->t1_count = 0;
    while (*s && o->t1_count < 8) {
        int g, q, used = 0;
        if (sscanf(s, "%d/%d%n", &g, &q, &used) != 2 || g < 1 || g > 512 || sl_voxel_quant_bits(q) < 0)
            return -1;
        o->t1_grid[o->t1_count] = g;
        o->t1_quant[o->t1_count++] = q;
        s += used;
        if (*s == ',')
            s++;
        else if (*s)
            return -1;
    }
    return o->t1_count > 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    options o = {.scale = 0.05, .grid = 128, .quant = 32, .table1 = 1, .table2 = 1};
    sl_bench_options_init(&o.bench, 3);
    parse_settings("256/128,256/32,128/128,128/32,64/8", &o);
    for (int i = 1; i < argc; i++) {
        int c = sl_bench_option(&o.bench, argc, argv, &i, "bench-voxel-lines");
        if (c < 0)
            return 2;
        if (c > 0)
            continue;
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : "";
        if (strcmp(a, "--no-table1") == 0) { o.table1 = 0; continue; }
        if (strcmp(a, "--no-table2") == 0) { o.table2 = 0; continue; }
        i++;
        char *end = NULL;
        if (strcmp(a, "--scale") == 0) {
            o.scale = strtod(v, &end);
            if (end == v || *end)
                o.scale = -1.0; /* refused below */
        }
        else if (strcmp(a, "--grid") == 0 && sl_bench_parse_int(v, 0, 512, &o.grid) == 0) {}
        else if (strcmp(a, "--quant") == 0 && sl_bench_parse_int(v, 1, 256, &o.quant) == 0) {}
        else if (strcmp(a, "--only") == 0) o.only = v;
        else if (strcmp(a, "--table1-grids") == 0) {
            if (parse_settings(v, &o) != 0) {
                fprintf(stderr, "bench-voxel-lines: bad --table1-grids %s (e.g. 256/32,128/8)\n", v);
                return 2;
            }
        } else {
            fprintf(stderr, "usage: bench-voxel-lines [--scale S] %s [--grid V] [--quant Q]\n"
                            "       [--table1-grids V/Q,...] [--only NAME] [--no-table1] [--no-table2]\n",
                    SL_BENCH_OPTIONS_HELP);
            return 2;
        }
    }
    if (!(o.scale > 0.0 && o.scale <= 1.0) ||
        sl_voxel_quant_bits(o.quant) < 0 || o.grid < 0 || o.grid > 512) {
        fprintf(stderr, "bench-voxel-lines: bad option value\n");
        return 2;
    }
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_pipeline *pipe = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK || sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        fprintf(stderr, "bench-voxel-lines: GPU: %s\n", err.message);
        sl_gpu_destroy(gpu);
        return 3;
    }
    printf("# voxel_lines benchmark\n\nGPU: %s. Line counts x %.3g of the paper's; image %dx%d; median wall ms of an "
           "orbit of %d frames after a warm-up (render + readback + glFinish); radius automatic (1/300 of the bounding "
           "radius); constant colour; still quality unless said.\n\n",
           sl_gpu_renderer(gpu), o.scale, o.bench.width, o.bench.height, o.bench.frames);

    char t1[DATASET_COUNT][1024], t2[DATASET_COUNT][1024];
    int rows = 0;
    for (int d = 0; d < DATASET_COUNT; d++) {
        const bench_data *bd = &datasets[d];
        if (o.only && !strstr(bd->name, o.only))
            continue;
        int lines = (int)lround(bd->lines * o.scale);
        if (lines < 10)
            lines = 10;
        char json[256];
        snprintf(json, sizeof json, "{\"generator\":\"%s\",\"lines\":%d,\"points\":%d,\"seed\":1}", bd->generator,
                 lines, bd->points);
        sl_dataset *ds = NULL;
        if (sl_generate_json(json, &ds, &err) != SL_OK) {
            fprintf(stderr, "bench-voxel-lines: %s: %s\n", json, err.message);
            continue;
        }
        double orig_mb = (double)ds->lines.vertex_count * 13.0 / 1e6;
        int n = snprintf(t1[rows], sizeof t1[rows], "| %s | %d (%d) | %.1f MB", bd->name, lines, bd->points, orig_mb);
        if (o.table1) {
            for (int s = 0; s < o.t1_count; s++) {
                sl_voxel_grid_desc desc = {.resolution = o.t1_grid[s], .quant = o.t1_quant[s], .padding = 1,
                                           .attribute = -1};
                sl_voxel_grid g, gg;
                if (sl_voxel_grid_build(&g, ds, &desc, &err) != SL_OK) {
                    n += snprintf(t1[rows] + n, sizeof t1[rows] - (size_t)n, " | error");
                    continue;
                }
                double mb = ((double)g.voxel_count * 5.0 + (double)g.line_count * g.line_bytes) / 1e6;
                double gpu_s = NAN;
                if (sl_voxel_grid_build_gpu(&gg, ds, &desc, &err) == SL_OK) {
                    gpu_s = gg.build_ms / 1e3;
                    sl_voxel_grid_deinit(&gg);
                }
                n += snprintf(t1[rows] + n, sizeof t1[rows] - (size_t)n, " | %.1f MB (%.2f s / %.2f s)%s", mb,
                              g.build_ms / 1e3, gpu_s, g.dropped_overflow ? "*" : "");
                sl_voxel_grid_deinit(&g);
            }
        }
        sl_pipeline_set_dataset(pipe, ds);
        const sl_bench_orbit orbit = {.distance = 2.2, .elevation_deg = 20, .fov_y_deg = 45};
        sl_bench_timing oit = {0}, vt = {0}, mesh = {0}, vo = {0}, vi = {0};
        oit.median_ms = vt.median_ms = mesh.median_ms = vo.median_ms = vi.median_ms = NAN;
        time_technique(pipe, "lines_oit", 0.25, &o, SL_QUALITY_STILL, &orbit, &oit);
        if (o.table2) {
            time_technique(pipe, "voxel_lines", 0.25, &o, SL_QUALITY_STILL, &orbit, &vt);
            /* own voxel only, as while the camera moves */
            time_technique(pipe, "voxel_lines", 0.25, &o, SL_QUALITY_INTERACTIVE, &orbit, &vi);
            time_technique(pipe, "tubes_mesh", 1.0, &o, SL_QUALITY_STILL, &orbit, &mesh);
            time_technique(pipe, "voxel_lines", 1.0, &o, SL_QUALITY_STILL, &orbit, &vo);
        }
        snprintf(t1[rows] + n, sizeof t1[rows] - (size_t)n, " | %.1f MB |", oit.gpu_bytes / 1e6);
        char g_oit[32], g_vt[32], g_mesh[32], g_vo[32];
        snprintf(t2[rows], sizeof t2[rows],
                 "| %s | %.0f ms (%.0f MB, RSS %.0f) | %.0f ms (%.0f MB, RSS %.0f) | **%.2fx** | %.0f ms (%.2fx) | %.0f ms "
                 "(%.0f MB) | %.0f ms (%.0f MB) | **%.2fx** | %s / %s / %s / %s |",
                 bd->name, oit.median_ms, oit.gpu_bytes / 1e6, oit.peak_rss_mb, vt.median_ms, vt.gpu_bytes / 1e6,
                 vt.peak_rss_mb, oit.median_ms / vt.median_ms, vi.median_ms, oit.median_ms / vi.median_ms,
                 mesh.median_ms, mesh.gpu_bytes / 1e6, vo.median_ms, vo.gpu_bytes / 1e6, mesh.median_ms / vo.median_ms,
                 sl_bench_gpu_cell(&oit, g_oit, sizeof g_oit), sl_bench_gpu_cell(&vt, g_vt, sizeof g_vt),
                 sl_bench_gpu_cell(&mesh, g_mesh, sizeof g_mesh), sl_bench_gpu_cell(&vo, g_vo, sizeof g_vo));
        fprintf(stderr, "%s done\n", bd->name);
        rows++;
    }
    if (o.table1) {
        printf("## Table 1 — memory (headers + packed lines) and preprocessing (CPU s / GPU s)\n\n"
               "| Dataset | Lines (points) | Original geometry |");
        for (int s = 0; s < o.t1_count; s++)
            printf(" %d^3/%d^2 |", o.t1_grid[s], o.t1_quant[s]);
        printf(" lines_oit at 25%% (lists + mesh) |\n|---|---|---|");
        for (int s = 0; s < o.t1_count; s++)
            printf("---|");
        printf("---|\n");
        for (int r = 0; r < rows; r++)
            printf("%s\n", t1[r]);
        printf("\n(* = some voxels exceeded 255 lines; the excess was dropped and counted)\n\n");
    }
    if (o.table2) {
        printf("## Table 2 — median wall frame time, voxel grid %d^3 (0 = auto) / %d^2\n\n"
               "| Dataset | lines_oit 25%% | voxel_lines 25%% still | OIT / voxel | voxel_lines 25%% interactive (ratio) "
               "| tubes_mesh opaque | voxel_lines opaque still | mesh / voxel | GPU-timer ms: OIT / voxel 25%% / mesh / "
               "voxel opaque |\n|---|---|---|---|---|---|---|---|---|\n",
               o.grid, o.quant);
        for (int r = 0; r < rows; r++)
            printf("%s\n", t2[r]);
        sl_bench_print_gpu_note();
        printf("\n");
    }
    sl_pipeline_destroy(pipe);
    sl_gpu_destroy(gpu);
    return 0;
}
