/* particles_splat.h — splats of `particles` (the paper's Fig. 10a: the
 * hidden-surface cones drawn shaded): each visible particle's tangent disk
 * of radius cone_radius x mean spacing, the cone sprite of the id pass
 * (particles_cone.glsl), opaque, Lambert-shaded in the set's ink, writing
 * colour and depth. Neighbouring disks overlap (cone_radius >= 0.58 closes a
 * hexagonal covering), so the set reads as a closed surface. It shades one
 * normal per particle: no interpolation across disks. Render thread only.
 */
#ifndef PARTICLES_SPLAT_H
#define PARTICLES_SPLAT_H

#include <epoxy/gl.h>

#include "../core/sl_params.h"
#include "../core/sl_status.h"
#include "particles_frame.h"

typedef struct pt_splat {
    GLuint program;
} pt_splat;

sl_status pt_splat_init(pt_splat *s, sl_err *err);
void pt_splat_deinit(pt_splat *s); /* zeroed is fine */
/* Draws the splats of one set (records at SSBO binding 1) into the bound
 * target, disks of radius cone_radius (world); returns the particles
 * issued. */
double pt_splat_draw(pt_splat *s, const pt_frame *f, const pt_set_view *sv, double cone_radius);

#endif
