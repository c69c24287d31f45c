/* particles_hsr.h — hidden-surface removal of `particles` by cone splatting
 * (the paper's Algorithm 3, sec. 4.2.1): every alive particle of a set is
 * drawn as a cone sprite (particles_cone.*.glsl) into a view-sized R32UI id
 * + depth target; a particle is visible where its own id won its pixel,
 * which the styles test per particle (u_ids). Each set gets its own pass, so
 * one surface never hides another wrongly. Render thread only.
 */
#ifndef PARTICLES_HSR_H
#define PARTICLES_HSR_H

#include <stddef.h>

#include <epoxy/gl.h>

#include "../core/sl_status.h"
#include "particles_frame.h"

typedef struct pt_hsr {
    GLuint program;
    GLuint fbo, ids, depth;
    int width, height;
} pt_hsr;

sl_status pt_hsr_init(pt_hsr *h, sl_err *err);
void pt_hsr_deinit(pt_hsr *h); /* zeroed is fine */
/* Fills h->ids for the `count` records bound at SSBO binding 1, cones of
 * radius cone_radius (world). Binds its own framebuffer and leaves it bound:
 * the caller binds its target again. */
sl_status pt_hsr_draw(pt_hsr *h, const pt_frame *f, GLsizei count, double cone_radius, sl_err *err);
size_t pt_hsr_bytes(const pt_hsr *h);

#endif
