/* sl_pipeline.h — dataset + technique + cached prepared state -> frames.
 *
 * The one place that decides how much work a change costs: a camera move
 * only renders; a parameter change re-renders or re-prepares as its schema
 * entry says (sl_params_compare); a new dataset or technique re-prepares.
 * Used by sightline-render, the server's render thread, tests and benchmarks.
 * Runs on the render thread (the one that created the sl_gpu).
 */
#ifndef SL_PIPELINE_H
#define SL_PIPELINE_H

#include <stdint.h>

#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"

typedef struct sl_pipeline sl_pipeline;

typedef struct sl_frame_stats {
    double gpu_ms;        /* GPU time of the technique's render (timer query) */
    double wall_ms;       /* wall time of render + finish */
    double prepare_ms;    /* time of the prepare this frame triggered, or 0 */
    int prepared;         /* 1 when this frame re-ran prepare */
    int prepare_reported; /* 1 when prepare (below) comes from the technique */
    sl_prepare_stats prepare; /* the technique's split of prepare_ms, when prepared */
    size_t gpu_bytes;     /* GPU memory held by the technique's state */
    sl_render_stats render;
} sl_frame_stats;

/* gpu is borrowed and must outlive the pipeline. */
sl_status sl_pipeline_create(sl_gpu *gpu, sl_pipeline **out, sl_err *err);
void sl_pipeline_destroy(sl_pipeline *p); /* NULL is fine */

/* Takes ownership of ds (also on failure); the old dataset is destroyed.
 * The next render re-prepares. */
void sl_pipeline_set_dataset(sl_pipeline *p, sl_dataset *ds);
const sl_dataset *sl_pipeline_dataset(const sl_pipeline *p);

/* Selects the technique and its parameters (params must use t's schema).
 * Fails when t does not accept the current dataset's kind. Cheap: work
 * happens at the next render, and only as much as the change requires. */
sl_status sl_pipeline_set_technique(sl_pipeline *p, const sl_technique *t, const sl_params *params, sl_err *err);

/* Whether the next render would run the technique's prepare (a new dataset
 * or technique, a parameter that invalidates prepared state, or none yet). */
int sl_pipeline_needs_prepare(const sl_pipeline *p);

/* Runs the technique's prepare now when sl_pipeline_needs_prepare says so
 * (else does nothing and returns SL_OK), filling stats' prepare fields, so a
 * caller can tell apart the prepare and the first render (the server reports
 * both). Errors as sl_pipeline_render's prepare: the state stays unprepared. */
sl_status sl_pipeline_prepare(sl_pipeline *p, sl_frame_stats *stats, sl_err *err);

/* Renders one frame of view (width/height taken from view) with the given
 * MSAA samples (0 or 1 = none) and leaves it in the pipeline's target. */
sl_status sl_pipeline_render(sl_pipeline *p, const sl_view *view, int samples,
                             sl_frame_stats *stats, sl_err *err);

/* Writes the technique's derived geometry of the last render to path
 * (sl_technique.export_geometry with the pipeline's params: those of the
 * last render unless set since), so callers never touch the technique's
 * state. SL_ERR_UNSUPPORTED when the technique exports nothing (the message
 * lists the techniques that do), SL_ERR_INVALID when no technique is
 * selected or a prepare is due (render first); else the
 * technique's codes (SL_ERR_IO, SL_ERR_NOMEM, naming the file). */
sl_status sl_pipeline_export(sl_pipeline *p, const char *path, sl_err *err);

/* The target of the last frame (valid until the next render or destroy). */
sl_target *sl_pipeline_target(sl_pipeline *p);

/* Reads the last frame: RGBA8 (top_down or GL's bottom-up rows) into a
 * caller buffer of width*height*4 bytes; distances in world units (0 = no
 * hit), rows top-down, into width*height floats. */
void sl_pipeline_read_rgba(sl_pipeline *p, uint8_t *rgba, int top_down);
void sl_pipeline_read_distance(sl_pipeline *p, const sl_view *view, float *distance);

#endif
