/* voxel_cast_cpu.h — the CPU execution of `voxel_lines`: the ray caster of
 * voxel_lines.frag.glsl written in C, over the same voxel model.
 *
 * One ray per pixel (the pixel centre, as gl_FragCoord), the same steps in
 * the same order in float: the 3D DDA front to back with empty-space
 * skipping over the occupancy pyramid (voxel_occupancy.h), the neighbour
 * search of (2R+1)^3 blocks tested once per voxel (read from per-voxel reach
 * lists, the same lines, instead of sliding the block), capsule intersection,
 * the sorted pending list of MAX_HITS hits with joint merging per local id,
 * the open-interval memory of MAX_OPEN slots, shading (sl_line_shade.h,
 * the GLSL's lighting and colormap), soft shadows from the density mip
 * chain, hard shadows from the representative lines, ambient occlusion,
 * front-to-back blending with early termination at alpha_stop. The result
 * is premultiplied colour and the reversed-Z depth of the first composited
 * hit in an sl_host_frame (rows bottom-up), blended into the GL target as
 * the shader's output is (ONE, ONE_MINUS_SRC_ALPHA).
 *
 * The model keeps the lines decoded (endpoints as floats relative to the
 * voxel and in grid coordinates with half the length, the reach walk's
 * bounding sphere: 60 bytes a line instead of 5-7, with the attribute and
 * local id): decoding once per build, not once per ray and line,
 * is what makes the CPU walk fast; the values are the GLSL's exactly (bin
 * centres are exact in float). Density levels and the AO field are copies
 * of what the GL passes computed (read back once per change).
 *
 * Threads: sl_voxel_cast_render runs 16x16 tiles on sl_parallel_run
 * (SIGHTLINE_THREADS overrides); everything else is the caller's thread.
 * No GL here.
 */
#ifndef SL_VOXEL_CAST_CPU_H
#define SL_VOXEL_CAST_CPU_H

#include <stddef.h>
#include <stdint.h>

#include "../core/sl_camera.h"
#include "../core/sl_status.h"
#include "../gpu/sl_host_frame.h"
#include "../line_style/sl_line_shade.h"
#include "voxel_grid.h"
#include "voxel_occupancy.h"

#define SL_VOXEL_CAST_MAX_LEVELS 12
#define SL_VOXEL_CAST_SPAN 8 /* floats per line of abs_ab: 32 bytes, two lines a cache line */

typedef struct sl_voxel_cast_model {
    int dims[3];
    uint32_t *first;          /* per voxel: its first line */
    uint8_t *count;           /* per voxel: its number of lines */
    size_t line_count;
    float *ab;                /* 6 floats per line: a, b relative to the voxel's corner */
    uint32_t *key;            /* per line: attribute byte << 16 | local id */
    /* SL_VOXEL_CAST_SPAN floats per line: a, b in grid coordinates (corner + ab, as the
     * walk adds them), half of |b - a| (the reach walk's bounding sphere), one unused. */
    float *abs_ab;
    /* The reach lists (sl_voxel_cast_model_reach) of tubes of radius reach_radius with the
     * neighbour search R = reach_r: per voxel, every line of the voxels within R whose tube's
     * box, grown by the walk's reach, overlaps it: voxel v's are reach_line[reach_first[v]
     * .. reach_first[v + 1] - 1]. reach_valid 0: none built. reach_occupancy is the
     * pyramid of the non-empty lists (undilated: a list holds its neighbours' lines), which
     * the reach walk skips by, so it steps through no voxel whose list is empty but one
     * lying alone between voxels whose lists are not. */
    int reach_valid, reach_r;
    float reach_radius;
    uint32_t *reach_first, *reach_line;
    sl_voxel_occupancy reach_occupancy;
    /* Density mip chain (level 0 = dims) and AO field, copied from the GL passes. */
    int density_levels;
    int density_dims[SL_VOXEL_CAST_MAX_LEVELS][3];
    float *density[SL_VOXEL_CAST_MAX_LEVELS];
    int ao_dims[3];
    uint8_t *ao;              /* unorm8, as the R8 texture */
} sl_voxel_cast_model;

/* Decodes grid's lines and copies its headers; *m is zeroed first. */
sl_status sl_voxel_cast_model_build(sl_voxel_cast_model *m, const sl_voxel_grid *grid, sl_err *err);
/* Gives level `level` of the density chain dims d (the buffer is made here, filled by the caller). */
float *sl_voxel_cast_density_level(sl_voxel_cast_model *m, int level, const int d[3], sl_err *err);
uint8_t *sl_voxel_cast_ao(sl_voxel_cast_model *m, const int d[3], sl_err *err);
void sl_voxel_cast_model_deinit(sl_voxel_cast_model *m); /* zeroed is fine */
/* Builds the reach lists for tubes of radius_g voxels and neighbour search R (1 or 2), when
 * they are not built for these already. With them a still frame's walk reads one list per
 * voxel instead of testing the (2R+1)^3 neighbours' boxes, and marks each line it tested
 * (per worker and ray), so every line within reach is tested once a ray, as in the
 * neighbour search: the same hits, composited in the same order. */
sl_status sl_voxel_cast_model_reach(sl_voxel_cast_model *m, float radius_g, int R, sl_err *err);

/* The frame's uniforms, as voxel_lines.c sets them for the shader. */
typedef struct sl_voxel_cast_params {
    float eye_g[3];           /* eye in grid coordinates */
    float inv_h;              /* 1 / voxel size */
    float radius_g;           /* tube radius in voxels */
    float opacity, alpha_stop;
    int neighbors;            /* R: 0, 1 or 2 */
    int opacity_by_distance, opacity_ramp;
    float attr_range[2];      /* colormap t of attribute bytes 0 and 255 */
    int skip_levels;          /* coarsest occupancy level used; < 0 = no skipping */
    const sl_voxel_occupancy *occupancy; /* borrowed; needed when skip_levels >= 0 */
    float extinction;
    int shadows, shadow_lines, ao_on;
    float shadow_strength, shadow_lod, max_lod, ao_strength;
    const float *reps;        /* representative lines of the shadow level (6 floats per cell), borrowed */
    int rep_dims[3];
    float rep_scale;
    const sl_line_shader *shader; /* colormap (range 0..1: t), colour, light, material */
    int reach_lists;          /* neighbors > 0: walk the model's reach lists (built for radius_g, neighbors) */
} sl_voxel_cast_params;

typedef struct sl_voxel_cast_stats {
    int threads;              /* workers that cast tiles */
    double rays, voxels, lines_tested, hits; /* per frame, summed over rays */
    double cast_ms;
} sl_voxel_cast_stats;

/* Casts view into frame's host buffers (frame must have the view's size: sl_host_frame_resize,
 * on the GL thread, before); SL_ERR_INVALID otherwise. */
sl_status sl_voxel_cast_render(const sl_voxel_cast_model *m, const sl_voxel_cast_params *p, const sl_view *view,
                               sl_host_frame *frame, sl_voxel_cast_stats *stats, sl_err *err);

#endif
