/* sl_technique.h — the one seam between a rendering technique and everything else.
 *
 * A technique is a static table: a name, a parameter schema and three
 * functions. The server, the CLIs and the benchmarks drive techniques only
 * through this table (sl_technique_find / sl_technique_list) and never branch
 * on a name.
 *
 *   prepare(gpu, dataset, params) -> state   uploads and preprocessing; kept
 *                                            across frames
 *   render(state, view, params, target)      one frame into a bound target
 *   release(state)                           frees GL objects and memory
 *
 * Lifecycle: prepare is called again (after release) only when a parameter
 * whose schema entry says SL_INVALIDATE_PREPARED (or DATASET) changed, or the
 * dataset changed — a camera move only calls render. All three run on the
 * render thread with the GL context current. render sets every piece of GL
 * state it relies on, draws into the already bound and cleared target
 * (sl_target_begin: reversed-Z depth, GL_GREATER), writes correct depth for
 * opaque surfaces, and leaves the target bound. Errors fill err; a failed
 * prepare leaves *state NULL and nothing allocated. Optional members (NULL =
 * not offered) are left out of a designated initializer.
 */
#ifndef SL_TECHNIQUE_H
#define SL_TECHNIQUE_H

#include <stddef.h>

#include "sl_backend.h"
#include "sl_camera.h"
#include "sl_params.h"
#include "sl_status.h"

typedef struct sl_gpu sl_gpu;
typedef struct sl_dataset sl_dataset;
typedef struct sl_target sl_target;

/* What a render reports (fill what applies; zero is fine). */
typedef struct sl_render_stats {
    double primitives;       /* triangles, boxes or rays issued */
    double culled;           /* primitives skipped by culling */
    double dropped;          /* pieces of data the technique could not draw
                                (voxel_lines: lines beyond the per-voxel cap) */
    double samples;          /* ray marchers: samples evaluated */
    double samples_skipped;  /* ray marchers: samples jumped over by empty-space skipping */
    double rebuild_ms;       /* derived data this render built because a FRAME-level
                                parameter asked for it (lr_volume: the streamline trace and
                                its tubes when `streamlines` is turned on after the
                                prepare; tubes on Embree: the BVH after a radius
                                change); 0 when the technique's cache held */
    const char *backend;     /* techniques with two executions (core/sl_backend.h): the
                                one that drew this frame, "gl" or the CPU one's name
                                ("embree"); NULL for techniques with one */
    int threads;             /* CPU executions: worker threads that drew this frame */
} sl_render_stats;

/* A named number of a technique's own ("set0.particles"), so callers can
 * show technique-specific results without branching on its name. */
#define SL_STATS_EXTRA_MAX 48
typedef struct sl_stat_value {
    char name[32];           /* NUL-terminated */
    double value;
} sl_stat_value;

/* Where the time of the last prepare went (fill what applies; zero is fine).
 * preprocess_ms + upload_ms need not add up to the pipeline's prepare_ms,
 * which also counts what neither covers. */
typedef struct sl_prepare_stats {
    double preprocess_ms;    /* CPU work: building meshes, nodes, voxel grids */
    double upload_ms;        /* creating and filling buffers and textures, to a glFinish */
    double gpu_ms;           /* GPU compute passes of the prepare (timer query) */
    int extra_count;         /* 0 .. SL_STATS_EXTRA_MAX entries of extra in use */
    sl_stat_value extra[SL_STATS_EXTRA_MAX]; /* fill with sl_prepare_stats_add */
} sl_prepare_stats;

/* Appends {name, value} to s->extra (technique_stats.c). The name is cut to
 * 31 bytes; past SL_STATS_EXTRA_MAX entries the value is dropped silently
 * (a technique's fixed set of names fits, so this is a guard, not a mode). */
void sl_prepare_stats_add(sl_prepare_stats *s, const char *name, double value);

typedef struct sl_technique {
    const char *name;
    const char *description;          /* one line, with the paper where there is one */
    unsigned dataset_kinds;           /* bit set of sl_dataset_kind it accepts */
    const sl_param_def *params;
    int param_count;

    sl_status (*prepare)(sl_gpu *gpu, const sl_dataset *dataset, const sl_params *params,
                         void **state, sl_err *err);
    sl_status (*render)(void *state, const sl_view *view, const sl_params *params,
                        sl_target *target, sl_render_stats *stats, sl_err *err);
    void (*release)(void *state);     /* NULL state is fine */
    size_t (*gpu_bytes)(const void *state); /* GPU memory held; may be NULL */
    /* Timings of the prepare that made state; may be NULL (not reported). */
    void (*prepare_stats)(const void *state, sl_prepare_stats *out);

    /* Derived geometry (DESIGN.md "derived data"): the file extension this
     * technique exports (".csv") and the writer, run on the render thread
     * after a render (it may read GPU buffers back) with that render's
     * params. Both NULL: exports nothing (sl_technique_exports). Returns
     * SL_ERR_IO (cannot write) or SL_ERR_NOMEM; the message names the file. */
    const char *export_ext;
    sl_status (*export_geometry)(void *state, const sl_params *params, const char *path, sl_err *err);

    /* Techniques with two executions (core/sl_backend.h; their schema has `backend`):
     * describes the CPU one, so callers can say what `auto` picks here. NULL: one only. */
    void (*backend_cpu)(sl_backend_cpu *out);
} sl_technique;

/* The registry (sl_registry.c holds the one table). */
const sl_technique *sl_technique_find(const char *name);
const sl_technique *const *sl_technique_list(int *count);

/* 1 when t offers export_geometry (with its export_ext), else 0. */
int sl_technique_exports(const sl_technique *t);
/* "a, b" (registry order) of the techniques that export, or "none yet";
 * cut to size, which must be > 0. */
void sl_technique_exporters(char *list, size_t size);

#endif
