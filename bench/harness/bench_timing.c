/* bench_timing.c — timed frames through the pipeline, cameras, peak memory, table cells,
 * sample percentiles (sl_bench.h).
 *
 * A frame's time runs from its first GL command (sl_pipeline_render begins the
 * target) to glFinish after glReadPixels into host memory, less the prepare
 * that only the warm-up frame runs. Peak RSS is the kernel's VmHWM, reset
 * before each run through /proc/self/clear_refs ("5") where that is allowed;
 * elsewhere it is the peak since the process started (said in the table).
 * Main thread (GL); the sl_bench_stat functions run on any thread, one object per thread.
 */
#include "sl_bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_clock.h"
#include "gpu/sl_gpu.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

double sl_bench_median(double *v, int n)
{
    if (n <= 0)
        return 0.0;
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void sl_bench_stat_add(sl_bench_stat *s, double x)
{
    if (s->n < SL_BENCH_STAT_MAX)
        s->v[s->n++] = x;
    else
        s->dropped++;
}

void sl_bench_stat_merge(sl_bench_stat *into, const sl_bench_stat *from)
{
    for (int i = 0; i < from->n; i++)
        sl_bench_stat_add(into, from->v[i]);
    into->dropped += from->dropped;
}

double sl_bench_stat_pct(sl_bench_stat *s, double p)
{
    if (s->n == 0)
        return NAN;
    qsort(s->v, (size_t)s->n, sizeof s->v[0], cmp_double);
    int i = (int)ceil(p / 100.0 * s->n) - 1;
    return s->v[i < 0 ? 0 : i >= s->n ? s->n - 1 : i];
}

double sl_bench_stat_mean(const sl_bench_stat *s)
{
    double sum = 0;
    for (int i = 0; i < s->n; i++)
        sum += s->v[i];
    return s->n ? sum / s->n : NAN;
}

size_t sl_bench_segment_count(const sl_dataset *ds)
{
    size_t n = 0;
    if (ds->kind != SL_DATASET_LINES)
        return 0;
    for (size_t k = 0; k < ds->lines.line_count; k++) {
        size_t len = ds->lines.line_offsets[k + 1] - ds->lines.line_offsets[k];
        n += len >= 2 ? len - 1 : 0;
    }
    return n;
}

sl_status sl_bench_orbit_camera(const sl_dataset *ds, int frame, int frames, const void *ctx, sl_camera *camera,
                                sl_err *err)
{
    const sl_bench_orbit *o = ctx;
    sl_orbit orbit = {frame < 0 ? 0.0 : 360.0 * frame / (frames > 0 ? frames : 1), o->elevation_deg, o->distance,
                      o->fov_y_deg > 0.0 ? o->fov_y_deg : 45.0};
    return sl_camera_from_orbit(&orbit, ds->bounds_min, ds->bounds_max, camera, err);
}

sl_status sl_bench_circle_camera(const sl_dataset *ds, int frame, int frames, const void *ctx, sl_camera *camera,
                                 sl_err *err)
{
    (void)ds;
    const sl_bench_circle *c = ctx;
    double a = frame < 0 ? 0.0 : 2.0 * SL_PI * frame / (frames > 0 ? frames : 1);
    *camera = (sl_camera){.eye = {c->target.x + c->radius * sin(a), c->target.y, c->target.z + c->radius * cos(a)},
                          .target = c->target,
                          .up = {0.0, 1.0, 0.0},
                          .fov_y_deg = c->fov_y_deg > 0.0 ? c->fov_y_deg : 45.0};
    return sl_camera_validate(camera, err);
}

/* 1 when the peak counter could be reset. */
static int reset_peak_rss(void)
{
    FILE *f = fopen("/proc/self/clear_refs", "w");
    if (!f)
        return 0;
    int ok = fputs("5", f) >= 0;
    return fclose(f) == 0 && ok;
}

static double peak_rss_mb(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f)
        return 0.0;
    char line[256];
    double kb = 0.0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %lf kB", &kb) == 1)
            break;
    fclose(f);
    return kb / 1024.0;
}

sl_status sl_bench_set(sl_params *params, const char *name, double value, sl_err *err)
{
    return sl_params_set_numbers(params, name, &value, 1, err);
}

sl_status sl_bench_set_choice(sl_params *params, const char *name, const char *choice, sl_err *err)
{
    return sl_params_set_choice(params, name, choice, err);
}

sl_status sl_bench_time_frames(sl_pipeline *p, const sl_technique *t, const sl_params *params,
                               const sl_bench_options *o, sl_quality quality, sl_bench_camera_fn camera,
                               const void *camera_ctx, sl_bench_timing *out, sl_err *err)
{
    memset(out, 0, sizeof *out);
    sl_status st = sl_pipeline_set_technique(p, t, params, err);
    if (st != SL_OK)
        return st;
    const sl_dataset *ds = sl_pipeline_dataset(p);
    size_t pixels = (size_t)o->width * (size_t)o->height;
    double *wall = calloc(2 * (size_t)o->frames, sizeof *wall), *gpu = wall ? wall + o->frames : NULL;
    uint8_t *rgba = malloc(pixels * 4);
    if (!wall || !rgba) {
        free(wall);
        free(rgba);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %dx%d frames", o->width, o->height);
    }
    int reset = reset_peak_rss();
    for (int f = -1; f < o->frames && st == SL_OK; f++) {
        sl_view view = {.width = o->width, .height = o->height, .quality = quality, .origin = ds->origin,
                        .background = {0.1f, 0.1f, 0.12f, 1.0f}};
        if ((st = camera(ds, f, o->frames, camera_ctx, &view.camera, err)) != SL_OK ||
            (st = sl_view_init(&view, sl_dataset_radius(ds), err)) != SL_OK)
            break;
        sl_frame_stats stats;
        double t0 = sl_clock_ms();
        if ((st = sl_pipeline_render(p, &view, 1, &stats, err)) != SL_OK)
            break;
        sl_pipeline_read_rgba(p, rgba, 0);
        glFinish();
        double ms = sl_clock_ms() - t0 - (stats.prepared ? stats.prepare_ms : 0.0);
        if (f < 0) {
            out->prepare_ms = stats.prepare_ms;
            continue;
        }
        wall[f] = ms;
        gpu[f] = stats.gpu_ms;
        out->primitives = stats.render.primitives;
        out->gpu_bytes = stats.gpu_bytes;
    }
    if (st == SL_OK) {
        out->frames = o->frames;
        out->median_ms = sl_bench_median(wall, o->frames); /* sorted now */
        out->min_ms = wall[0];
        out->max_ms = wall[o->frames - 1];
        out->gpu_ms = sl_bench_median(gpu, o->frames);
        out->peak_rss_mb = peak_rss_mb();
        out->peak_rss_since_start = !reset;
    }
    free(wall);
    free(rgba);
    return st;
}

/* Set when a cell was flagged since the last note (main thread only). */
static int gpu_flagged;

const char *sl_bench_gpu_cell(const sl_bench_timing *t, char *buf, size_t size)
{
    int flag = t->gpu_ms < 0.5 * t->median_ms;
    gpu_flagged |= flag;
    snprintf(buf, size, "%.1f%s", t->gpu_ms, flag ? " (!)" : "");
    return buf;
}

void sl_bench_print_gpu_note(void)
{
    if (!gpu_flagged)
        return;
    gpu_flagged = 0;
    printf("\n(!) GPU-timer ms under half the wall ms: the timer missed work (on llvmpipe a query can end "
           "before the queued rasterization runs); compare the wall column.\n");
}
