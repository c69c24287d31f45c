/* particles_stipple.h — stippling (the paper's sec. 4.2.2): one round dot per
 * visible particle, its area growing with the ink its tone wants
 * (particles_marks.*.glsl). Render thread only.
 */
#ifndef PARTICLES_STIPPLE_H
#define PARTICLES_STIPPLE_H

#include <epoxy/gl.h>

#include "../core/sl_params.h"
#include "../core/sl_status.h"
#include "particles_frame.h"

typedef struct pt_stipple {
    GLuint program;
} pt_stipple;

sl_status pt_stipple_init(pt_stipple *s, sl_err *err);
void pt_stipple_deinit(pt_stipple *s); /* zeroed is fine */
/* Draws the stipples of one set (records at SSBO binding 1) into the bound
 * target; returns the particles issued. */
double pt_stipple_draw(pt_stipple *s, const pt_frame *f, const pt_set_view *sv, const sl_params *params);

#endif
