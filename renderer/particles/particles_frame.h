/* particles_frame.h — what every drawing pass of `particles` shares in one
 * frame, and the uniforms of particles_record.glsl it sets.
 *
 * A frame draws the sets one after another; per set: hidden-surface removal
 * (particles_hsr.h) fills an id target, then each style the set has on
 * (splats, stipples, hatches, contours) draws from the set's records into
 * the bound target with depth test GREATER and premultiplied blending,
 * depth writes on (contours test depth but do not write it: overlapping
 * segments would cut each other's anti-aliased edges). A style
 * reads the set's records at SSBO binding 1 (bound by the caller), the
 * frame's camera UBO at binding 0 and, with `hsr`, the id texture.
 * Render thread only.
 */
#ifndef PARTICLES_FRAME_H
#define PARTICLES_FRAME_H

#include <epoxy/gl.h>

#include "../core/sl_camera.h"
#include "../core/sl_params.h"
#include "particles_system.h"
#include "particles_tf2d.h"

typedef struct pt_frame {
    const sl_view *view;
    float light_world[3];     /* unit, towards the light (light_direction is eye space) */
    float volume_offset[3];   /* volume origin - view origin */
    float px_per_world;       /* view height / (2 tan(fov_y / 2)) */
    float max_point;          /* GL_POINT_SIZE_RANGE max */
    float focus[4];           /* focus sphere: centre in local world, radius (0 = none) */
} pt_frame;

/* One set as its styles see it. */
typedef struct pt_set_view {
    const pt_set *set;
    int index;                /* 0..3 */
    float ink[3];             /* setK_color */
    int ink_dark;             /* ink darker than the background: tone = 1 - diffuse */
    int hsr;                  /* the id texture holds this set's visibility */
    GLuint id_tex;            /* R32UI, particle index + 1 (0 = none), view sized */
    pt_curvature_lookup curvature; /* the set's 2D transfer function (particles_tf2d.h); zero = off */
} pt_set_view;

void pt_frame_init(pt_frame *f, const sl_view *view, const sl_params *params, sl_vec3 volume_origin,
                   float max_point);
/* u_volume_offset, u_px_per_world, u_max_point, u_focus of `program` (in use). */
void pt_frame_uniforms(GLuint program, const pt_frame *f);

#endif
