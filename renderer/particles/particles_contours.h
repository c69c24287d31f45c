/* particles_contours.h — contours of `particles` (the paper's sec. 4.2.4;
 * plan sec. 1.9): per frame and set, a compute pass
 * (particles_contours.comp.glsl) selects the visible particles within
 * contour_distance mean spacings of a contour (Kindlmann's thickness-
 * controlled test), moves each onto it and appends one segment of
 * contour_length mean spacings along it; the segments are drawn as quads of
 * constant contour_width pixels (particles_contours.{vert,frag}.glsl) in
 * the set's ink, depth-tested against the set's other marks, not writing
 * depth (overlapping segments blend instead of cutting each other). An
 * indirect draw takes the count: no read-back. No geometry shader. One
 * segment buffer serves every set in turn. Render thread only.
 */
#ifndef PARTICLES_CONTOURS_H
#define PARTICLES_CONTOURS_H

#include <stddef.h>
#include <stdint.h>

#include <epoxy/gl.h>

#include "../core/sl_params.h"
#include "../core/sl_status.h"
#include "particles_frame.h"

typedef struct pt_contours {
    GLuint select, draw;       /* programs */
    GLuint segments, command;  /* pt_segment[capacity]; DrawArraysIndirectCommand */
    uint32_t capacity;         /* segments held: one per particle at most */
} pt_contours;

sl_status pt_contours_init(pt_contours *c, sl_err *err);
void pt_contours_deinit(pt_contours *c); /* zeroed is fine */
/* Selects and draws the contours of one set (records at SSBO binding 1)
 * into the bound target; sigma = the set's repulsion radius (world), for
 * the flat rule. SL_ERR_GPU when the segment buffer cannot grow (nothing
 * drawn). */
sl_status pt_contours_draw(pt_contours *c, const pt_frame *f, const pt_set_view *sv, const sl_params *params,
                           double sigma, sl_err *err);
size_t pt_contours_bytes(const pt_contours *c);

#endif
