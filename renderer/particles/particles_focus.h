/* particles_focus.h — focus + context of `particles` (docs/particles_plan.md
 * §1.11; the paper's sec. 6 and Fig. 10): inside a sphere (focus_center,
 * focus_radius, world) the volume is drawn by the shared ray marcher
 * (volume/sl_volume.h, focus variant) with focus_transfer_function at
 * focus_step; outside it the marks. Particles inside the sphere are culled
 * by the cone and mark shaders themselves (pt_in_focus, particles_record.glsl;
 * u_focus from pt_frame). One frame, one depth: after every set's marks the
 * target's depth is copied into a texture (single-sample: a blit; MSAA: the
 * nearest mark among each pixel's samples), the marcher ends each ray there
 * and writes the nearer of mark and volume. Not here: the marks (the styles draw them).
 * Nothing is built before the first frame with a focus (bricks, marcher
 * programs, the depth copy), so prepares without one cost nothing.
 * Render thread only.
 */
#ifndef PARTICLES_FOCUS_H
#define PARTICLES_FOCUS_H

#include <stddef.h>

#include <epoxy/gl.h>

#include "../core/sl_camera.h"
#include "../core/sl_params.h"
#include "../core/sl_technique.h"
#include "../gpu/sl_depth_copy.h"
#include "../gpu/sl_gpu.h"
#include "../volume/sl_volume.h"

typedef struct pt_focus {
    const sl_volume *data;        /* borrowed */
    const sl_volume_texture *volume; /* borrowed: the technique's exact-value texture */
    const sl_volume_geometry *geom;  /* borrowed */
    int ready;                    /* bricks and marcher built (first focus frame) */
    sl_volume_bricks bricks;
    sl_volume_marcher marcher;
    sl_depth_copy depth;          /* the marks' depth, target sized (first focus frame) */
} pt_focus;

/* Remembers what the marcher will read; no GL, cannot fail. */
void pt_focus_init(pt_focus *f, const sl_volume *data, const sl_volume_texture *volume,
                   const sl_volume_geometry *geom);
void pt_focus_deinit(pt_focus *f); /* zeroed is fine */

/* After all marks: nothing when focus_radius is 0; else copies target's
 * depth and draws the marcher into target (bound on return, viewport the
 * view's). Adds the marcher's samples to stats. SL_ERR_NOMEM, SL_ERR_GPU
 * (a shader log, an incomplete depth copy), SL_ERR_INVALID (the marcher's). */
sl_status pt_focus_draw(pt_focus *f, const sl_view *view, const sl_params *params, const sl_target *target,
                        sl_render_stats *stats, sl_err *err);
size_t pt_focus_bytes(const pt_focus *f);

#endif
