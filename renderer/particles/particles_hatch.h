/* particles_hatch.h — hatching of `particles` (the paper's sec. 4.2.3, Fig. 6-8;
 * docs/particles_plan.md §1.8): per particle a stroke of `hatch_segments`
 * segments centred on it along its hatch direction — `hatch_direction`
 * projected into the tangent plane, or the reliability-weighted smoothed main
 * principal direction of its neighbours — and, with cross-hatching, a second
 * one at `cross_angle`; drawn as screen-space quads of constant pixel width
 * for the visible particles whose tone asks for them.
 *
 * The strokes are a cache per set (particles_hatch.comp.glsl), rebuilt inside
 * render only when a parameter they depend on changes (never for a camera
 * move; pt_debug_hatch_builds counts the builds). Tones, width, ink and
 * visibility are per frame (particles_stroke.*.glsl). No geometry shader.
 * Render thread only.
 */
#ifndef PARTICLES_HATCH_H
#define PARTICLES_HATCH_H

#include <epoxy/gl.h>

#include "../core/sl_params.h"
#include "../core/sl_status.h"
#include "particles_frame.h"
#include "particles_system.h"

#define PT_HATCH_SETS 4

/* What a set's strokes were built from; a build is due when it changes. */
typedef struct pt_hatch_key {
    int mode;                    /* 0 curvature, 1 fixed */
    float direction[3];
    double length;               /* world */
    int segments;
    int cross;                   /* 1: a cross stroke per particle too */
    double cross_angle;          /* deg */
    double eps;                  /* flat curvature, 1/world */
    double sigma;                /* smoothing radius, world */
} pt_hatch_key;

typedef struct pt_hatch_cache {
    GLuint strokes;              /* vec4 (x local world, packHalf2x16(k1, k2)) per vertex */
    uint32_t particles;
    pt_hatch_key key;
} pt_hatch_cache;

typedef struct pt_hatch {
    GLuint build_program, draw_program;
    pt_field field;              /* borrowed texture; copied geometry */
    pt_hatch_cache cache[PT_HATCH_SETS];
} pt_hatch;

/* field is what the sets live on (its texture is borrowed and must outlive
 * h). Compiles nothing: the two programs are made at the first draw, so a
 * prepare without hatching does not pay for them. */
void pt_hatch_init(pt_hatch *h, const pt_field *field);
void pt_hatch_deinit(pt_hatch *h); /* zeroed is fine */
/* Bytes of the stroke caches. */
size_t pt_hatch_bytes(const pt_hatch *h);

/* Draws the hatches of one set (records at SSBO binding 1) into the bound
 * target, building its strokes first when its key changed (iso: the set's
 * isovalue, for the reprojection onto the surface). Adds the stroke
 * segments issued to *drawn. SL_ERR_GPU when a program does not compile
 * (with the info log) or the build fails (the cache is then empty and
 * nothing is drawn). */
sl_status pt_hatch_draw(pt_hatch *h, const pt_frame *f, const pt_set_view *sv, double iso, const sl_params *params,
                        double *drawn, sl_err *err);

#endif
