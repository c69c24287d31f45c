/* lr_volume_streamlines.h — the streamlines of `lr_volume` (issue 15,
 * "Rendered in the same frame as the volume ... as Hermite spline tubes"):
 * traced on the GPU through renderer/flow over lr_volume's own Bézier blocks
 * and look-up (sl_flow_gpu_create_lr: borrowed, not built again) from a seed
 * box, turned into a line set (positions + velocities: Hermite data) and
 * drawn by the `tubes` technique, found through the registry like any
 * other, its parameters set from lr_volume's (radius, colormap; coloured by
 * speed). After the tubes are drawn their depth is copied
 * (gpu/sl_depth_copy.h) so the volume's rays end at them.
 *
 * Invariant: a state traces at most once. What shapes the lines (seeds,
 * solver, step, tolerance, t_max, max_samples, precision) is PREPARED level
 * in lr_volume's schema, so another value means another prepared state;
 * camera, transfer function, tube radius and colormap only re-render. Seeds:
 * Halton points in a box in fractions of the domain (deterministic). Vector
 * LR volumes (dim 3) only: a scalar one is refused with a sentence. Render
 * thread only.
 */
#ifndef LR_VOLUME_STREAMLINES_H
#define LR_VOLUME_STREAMLINES_H

#include <stddef.h>

#include "../core/sl_params.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_depth_copy.h"
#include "../gpu/sl_gpu.h"
#include "../lrspline/sl_lr_bezier.h"

typedef struct lrv_streamlines {
    sl_gpu *gpu;                    /* borrowed */
    const sl_dataset *dataset;      /* borrowed: the LR volume */
    const sl_lr_bezier *bz;         /* borrowed: lr_volume's blocks and look-up */
    sl_lr_bezier_gpu *blocks;       /* borrowed: their buffers; a mixed or double trace adds the double ones */
    int traced;                     /* the trace ran (lines may still be NULL) */
    sl_dataset *lines;              /* owned; NULL when no line has 2 samples */
    const sl_technique *tubes;
    void *tubes_state;              /* tubes prepared on lines */
    sl_params tube_params;
    sl_depth_copy depth;
    size_t line_count, sample_count;
    double trace_ms;                /* sl_flow_gpu_trace: compile, dispatch, read-back */
    double compute_ms;              /* its dispatch to glFinish */
    double tubes_ms;                /* the tubes' prepare on the lines */
} lrv_streamlines;

void lrv_streamlines_init(lrv_streamlines *s, sl_gpu *gpu, const sl_dataset *dataset, const sl_lr_bezier *bz,
                          sl_lr_bezier_gpu *blocks);
void lrv_streamlines_deinit(lrv_streamlines *s);   /* zeroed is fine */

/* Traces the lines of params (its seed_*, solver, flow_step, flow_tol,
 * t_max, max_samples, precision) and prepares the tubes on them; nothing
 * when this state has traced already. SL_ERR_INVALID for a scalar volume or
 * bad options (the flow module's sentence), the flow and tubes errors; on
 * failure nothing is kept and the next call tries again. */
sl_status lrv_streamlines_trace(lrv_streamlines *s, const sl_params *params, sl_err *err);

/* Draws the tubes into target (bound and cleared by the caller) and copies
 * their depth into s->depth (target bound again on return). Nothing to draw
 * when no line was traced: then the copy holds no depth. */
sl_status lrv_streamlines_draw(lrv_streamlines *s, const sl_view *view, const sl_params *params, sl_target *target,
                               sl_render_stats *stats, sl_err *err);

size_t lrv_streamlines_gpu_bytes(const lrv_streamlines *s);

#endif
