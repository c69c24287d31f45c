/* sl_bench.h — the one benchmark harness every bench-* program uses.
 *
 * Frame time is what a user waits: wall time from the frame's first GL command
 * to glFinish after the readback into host memory (sl_bench_time_frames). The
 * GPU timer is a second column only; it can miss most of the work on llvmpipe
 * (a timer query ends when the commands are queued, not rasterized), so
 * sl_bench_gpu_cell marks a GPU ms under half the wall ms. Defaults are the
 * size people look at (1280x720) and an orbit of frames after one warm-up;
 * preprocessing is reported apart. Peers a user would otherwise pick (VTK's
 * tube filter, Embree's round curves) read the same file and cameras
 * (sl_bench_peer_*). Prints nothing by itself but tables the caller asks for;
 * checks nothing. Main thread = render thread (it owns the GL context).
 */
#ifndef SL_BENCH_H
#define SL_BENCH_H

#include <stddef.h>

#include "core/sl_technique.h"
#include "data/sl_dataset.h"
#include "pipeline/sl_pipeline.h"

/* ---- options every benchmark takes ---- */

typedef struct sl_bench_options {
    int width, height;   /* default 1280x720; --small 256x144; --size WxH */
    int frames;          /* timed frames of an orbit, after one warm-up; --frames N */
} sl_bench_options;

#define SL_BENCH_OPTIONS_HELP "[--small | --size WxH] [--frames N]"

/* Defaults: 1280x720, `frames` timed frames (the program's own default). */
void sl_bench_options_init(sl_bench_options *o, int frames);

/* Parses a whole decimal integer in [lo, hi] into *out: 0, or -1 (nothing written). */
int sl_bench_parse_int(const char *text, long lo, long hi, int *out);

/* Reads argv[*i] (and its value) when it is a common option: returns 1 and
 * advances *i past it, 0 when it is not one (nothing changes), -1 on a bad
 * value (a message naming the option went to stderr). */
int sl_bench_option(sl_bench_options *o, int argc, char **argv, int *i, const char *program);

/* ---- timed frames through the pipeline ---- */

/* The camera of frame `frame` of `frames` (frame -1: the warm-up); fills view->camera only. */
typedef sl_status (*sl_bench_camera_fn)(const sl_dataset *ds, int frame, int frames, const void *ctx,
                                        sl_camera *camera, sl_err *err);

/* An orbit about the bounds centre (sl_orbit: distance in bounding radii), azimuth 360 f / frames. */
typedef struct sl_bench_orbit { double distance, elevation_deg, fov_y_deg; } sl_bench_orbit;
sl_status sl_bench_orbit_camera(const sl_dataset *ds, int frame, int frames, const void *orbit,
                                sl_camera *camera, sl_err *err);

/* An eye circling a fixed target in world units: frame 0 at target + (0, 0, radius),
 * then about +y, up +y (the peers' comparison: eye (0, 0, 8) looking at the origin). */
typedef struct sl_bench_circle { sl_vec3 target; double radius, fov_y_deg; } sl_bench_circle;
sl_status sl_bench_circle_camera(const sl_dataset *ds, int frame, int frames, const void *circle,
                                 sl_camera *camera, sl_err *err);

typedef struct sl_bench_timing {
    int frames;
    double median_ms, min_ms, max_ms;  /* wall, render + readback + glFinish */
    double gpu_ms;                     /* median GPU-timer ms (second column) */
    double prepare_ms;                 /* the warm-up's prepare (0 when none ran) */
    double peak_rss_mb;                /* the process' peak resident set during the run (VmHWM) */
    int peak_rss_since_start;          /* 1: the peak could not be reset, it counts from process start */
    double primitives;                 /* as the technique reports, last frame */
    size_t gpu_bytes;                  /* GPU memory the technique holds */
} sl_bench_timing;

/* Selects t with params, renders one warm-up frame (which prepares) and
 * o->frames timed frames at o's size with `quality`, reading every frame back.
 * The peak RSS is reset first where the kernel allows (/proc/self/clear_refs). */
sl_status sl_bench_time_frames(sl_pipeline *p, const sl_technique *t, const sl_params *params,
                               const sl_bench_options *o, sl_quality quality, sl_bench_camera_fn camera,
                               const void *camera_ctx, sl_bench_timing *out, sl_err *err);

/* Sets a parameter by name from a number or choice text; fails naming it. */
sl_status sl_bench_set(sl_params *params, const char *name, double value, sl_err *err);
sl_status sl_bench_set_choice(sl_params *params, const char *name, const char *choice, sl_err *err);

/* "12.3", or "0.8 (!)" when the GPU ms is under half the wall ms (the timer missed work). */
const char *sl_bench_gpu_cell(const sl_bench_timing *t, char *buf, size_t size);
/* The footnote that explains "(!)"; prints only when a cell was flagged since the last call. */
void sl_bench_print_gpu_note(void);

/* Median of n values (sorts v). */
double sl_bench_median(double *v, int n);

/* Samples of one measured quantity (latencies, open times) for percentiles.
 * Zero-initialised = empty; keeps the first SL_BENCH_STAT_MAX samples and
 * counts the rest in `dropped`. Not thread-safe: one per thread, then merge. */
#define SL_BENCH_STAT_MAX 8192
typedef struct sl_bench_stat {
    double v[SL_BENCH_STAT_MAX];
    int n, dropped;
} sl_bench_stat;
void sl_bench_stat_add(sl_bench_stat *s, double x);
/* Appends every sample of `from` to `into` (what does not fit is counted as dropped). */
void sl_bench_stat_merge(sl_bench_stat *into, const sl_bench_stat *from);
/* The p-th percentile (0 < p <= 100, nearest rank; sorts the samples); NAN when empty. */
double sl_bench_stat_pct(sl_bench_stat *s, double p);
/* The mean; NAN when empty. */
double sl_bench_stat_mean(const sl_bench_stat *s);
/* Segments of a line set (pairs of consecutive vertices of each line). */
size_t sl_bench_segment_count(const sl_dataset *ds);

/* ---- peers: the same file and cameras through what users would otherwise pick ---- */

#define SL_BENCH_MAX_VIEWS 4

typedef struct sl_bench_peer_files {
    char dir[64];         /* a temporary folder holding both files */
    char lines[96];       /* legacy VTK POLYDATA, binary; radii as the point scalar `radius` */
    char cameras[96];     /* "VIEW INDEX ex ey ez tx ty tz ux uy uz fov" per frame (file coordinates) */
} sl_bench_peer_files;

typedef struct sl_bench_view_spec {
    const char *name;                  /* e.g. "far" */
    sl_bench_camera_fn camera;
    const void *ctx;
} sl_bench_view_spec;

/* Writes ds's lines (radii times radius_scale as the point scalar, when the
 * data has radii; normals, 3 floats per vertex, as the point NORMALS when not
 * NULL) and the cameras of every view (warm-up + o->frames each, the very
 * cameras sl_bench_time_frames uses) into a new temporary folder. */
sl_status sl_bench_peer_files_write(const sl_dataset *ds, float radius_scale, const float *normals,
                                    const sl_bench_view_spec *views, int view_count, const sl_bench_options *o,
                                    sl_bench_peer_files *files, sl_err *err);
void sl_bench_peer_files_remove(sl_bench_peer_files *files); /* removes the folder; safe twice */

/* Writes the lines alone (also used to give our own loader the peers' file). */
sl_status sl_bench_write_lines_vtk(const sl_dataset *ds, float radius_scale, const float *normals, const char *path,
                                   sl_err *err);

typedef struct sl_bench_peer_result {
    int ok;
    char reason[256];                   /* why not, when !ok */
    double median_ms[SL_BENCH_MAX_VIEWS], min_ms[SL_BENCH_MAX_VIEWS], max_ms[SL_BENCH_MAX_VIEWS];
    double build_ms;                    /* VTK: tube filter; Embree: BVH build */
    double first_frame_ms;              /* VTK: the first frame, which uploads the mesh */
    double triangles;                   /* VTK: tube or ribbon triangles */
    double mesh_bytes;                  /* VTK: the filter output's memory (vtkDataObject::GetActualMemorySize) */
    double seconds;                     /* the whole run, start-up included */
    char version[32], renderer[128];
} sl_bench_peer_result;

typedef struct sl_bench_tube_peer_desc {
    const sl_bench_peer_files *files;
    const sl_bench_view_spec *views;
    int view_count;
    const sl_bench_options *options;
    double radius;        /* radius where the file has none; ribbons: the half-width */
    int sides, caps;      /* VTK tube filter: tubes_mesh's defaults */
    int threads;          /* Embree: worker threads (the machine's cores) */
} sl_bench_tube_peer_desc;

/* VTK's vtkTubeFilter + vtkPolyDataMapper (bench/vtk_tubes.py under xvfb-run,
 * on the same GL); fills r, r->ok = 0 with a reason when it cannot run. */
void sl_bench_peer_vtk_tubes(const sl_bench_tube_peer_desc *d, sl_bench_peer_result *r);
/* VTK's vtkRibbonFilter (flat ribbons, Width = d->radius, oriented by the
 * file's NORMALS, else VTK's default normals) + vtkPolyDataMapper
 * (bench/vtk_ribbons.py under xvfb-run); sides, caps and threads unused. */
void sl_bench_peer_vtk_ribbons(const sl_bench_tube_peer_desc *d, sl_bench_peer_result *r);
/* Embree 3 round Hermite curves on the CPU (bench/peers/embree_tubes.c,
 * built as peer-embree-tubes next to this program when Embree is installed). */
void sl_bench_peer_embree_tubes(const sl_bench_tube_peer_desc *d, sl_bench_peer_result *r);

#endif
