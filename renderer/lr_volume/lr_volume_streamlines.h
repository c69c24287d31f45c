/* lr_volume_streamlines.h — the streamlines of `lr_volume` (issue 15,
 * "Rendered in the same frame as the volume ... as Hermite spline tubes"):
 * traced on the GPU through renderer/flow (flow_gpu.h) from a seed box,
 * turned into a line set (positions + velocities: Hermite data) and drawn
 * by the `tubes` technique, found through the registry like any other, its
 * parameters set from lr_volume's (radius, colormap; coloured by speed).
 *
 * The trace is derived data cached in the state: it is re-run only when a
 * parameter that shapes the lines changes (seeds, solver, step, tolerance,
 * t_max, max_samples, precision), never on a camera move or a transfer
 * function change; the tube radius and colormap only re-render. After the
 * tubes are drawn their depth is copied (gpu/sl_depth_copy.h) so the
 * volume's rays end at them. Seeds are a box in fractions of the domain
 * (Halton points, deterministic). Vector LR volumes (dim 3) only: a scalar
 * one is refused with a sentence. Render thread only.
 */
#ifndef LR_VOLUME_STREAMLINES_H
#define LR_VOLUME_STREAMLINES_H

#include <stddef.h>

#include "../core/sl_params.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../flow/flow_gpu.h"
#include "../gpu/sl_depth_copy.h"
#include "../gpu/sl_gpu.h"

/* What shapes the lines; a trace is redone when any of it changes. */
typedef struct lrv_trace_key {
    double seed_lo[3], seed_hi[3];  /* fractions of the domain */
    int seed_count;
    int solver, precision;
    double step, tol, t_max;
    int max_samples;
} lrv_trace_key;

typedef struct lrv_streamlines {
    sl_gpu *gpu;                    /* borrowed */
    const sl_dataset *dataset;      /* borrowed: the LR volume */
    sl_flow_gpu *flow;              /* made at the first trace */
    int traced;                     /* key and lines are valid */
    lrv_trace_key key;
    sl_dataset *lines;              /* owned; NULL when no line has 2 samples */
    const sl_technique *tubes;
    void *tubes_state;              /* tubes prepared on lines */
    sl_params tube_params;
    sl_depth_copy depth;
    size_t line_count, sample_count;
    double trace_ms;                /* the last trace, dispatch to read-back */
    unsigned traces;                /* traces run since init (tests) */
} lrv_streamlines;

void lrv_streamlines_init(lrv_streamlines *s, sl_gpu *gpu, const sl_dataset *dataset);
void lrv_streamlines_deinit(lrv_streamlines *s);   /* zeroed is fine */

/* Traces again when the key from params differs from the last trace's and
 * prepares the tubes on the new lines; *rebuild_ms gets the time that took
 * (0 when the cache held). SL_ERR_INVALID for a scalar volume or bad
 * options (the flow module's sentence), the flow and tubes errors. */
sl_status lrv_streamlines_update(lrv_streamlines *s, const sl_params *params, double *rebuild_ms, sl_err *err);

/* Draws the tubes into target (bound and cleared by the caller) and copies
 * their depth into s->depth (target bound again on return). Nothing to draw
 * when no line was traced: then the copy holds no depth. */
sl_status lrv_streamlines_draw(lrv_streamlines *s, const sl_view *view, const sl_params *params, sl_target *target,
                               sl_render_stats *stats, sl_err *err);

size_t lrv_streamlines_gpu_bytes(const lrv_streamlines *s);

#endif
