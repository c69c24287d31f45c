/* particles_tf2d.h — the 2D curvature transfer function of `particles`
 * (the paper's sec. 4.2.5 and Fig. 9; plan §1.10): a sl_transfer_function_2d
 * over (κ̃1, κ̃2) = (κ1, κ2) · min_spacing (curvature per voxel) composited
 * over a set's ink, baked into a PT_TF2D_SIZE² RGBA8 table that the styles
 * sample through particles_tf2d.glsl.
 *
 * Rule, per widget in order: q = |(κ̃1, κ̃2) − centre| / radius,
 * w = a · max(0, 1 − q²)², c = mix(c, rgb, w), starting from the ink.
 * Texel (i, j) is column i = κ̃1, row j = κ̃2, centred at −range + (i + ½) ·
 * 2 range / PT_TF2D_SIZE. The unreachable half κ̃2 > κ̃1 holds the value at
 * the point's projection onto the diagonal, so linear filtering near the
 * diagonal never mixes in garbage; beyond ±range the table clamps to its
 * edge. Does not: evaluate per particle on the CPU, or keep a histogram.
 * pt_tf2d_eval / pt_tf2d_bake: any thread, no GL. pt_tf2d (one texture per
 * set, rebaked only when the function or that set's ink changes): render
 * thread only.
 */
#ifndef PARTICLES_TF2D_H
#define PARTICLES_TF2D_H

#include <stdint.h>

#include <epoxy/gl.h>

#include "../core/sl_params.h"
#include "../core/sl_status.h"

#define PT_TF2D_SIZE 64
#define PT_TF2D_SETS 4

/* The rule at one point (κ̃1, κ̃2), in 0..1 per channel (no quantization). */
void pt_tf2d_eval(const sl_transfer_function_2d *tf, const float ink[3], double k1, double k2, double out[3]);
/* κ̃ of texel centre i (0 .. PT_TF2D_SIZE - 1) at `range`. */
double pt_tf2d_texel_center(double range, int i);
/* The table: PT_TF2D_SIZE² RGBA8 texels, row j (κ̃2) after row j - 1, alpha 255. */
void pt_tf2d_bake(const sl_transfer_function_2d *tf, const float ink[3], uint8_t rgba[PT_TF2D_SIZE * PT_TF2D_SIZE * 4]);

/* What a style's program needs for particles_tf2d.glsl; zero = colouring off. */
typedef struct pt_curvature_lookup {
    GLuint table;         /* borrowed from pt_tf2d */
    float range;          /* the function's range, per voxel */
    float min_spacing;    /* world units per voxel */
    int on;
} pt_curvature_lookup;

typedef struct pt_tf2d {
    GLuint tex[PT_TF2D_SETS];
    int baked[PT_TF2D_SETS];                 /* tex[k] holds tf[k] over ink[k] */
    sl_transfer_function_2d tf[PT_TF2D_SETS];
    float ink[PT_TF2D_SETS][3];
    int bakes;                               /* tables baked so far (a count, for tests) */
} pt_tf2d;

/* Creates the textures (PT_TF2D_SETS × 16 KiB); SL_ERR_GL on failure, t
 * then safe to deinit. */
sl_status pt_tf2d_init(pt_tf2d *t, sl_err *err);
void pt_tf2d_deinit(pt_tf2d *t); /* zeroed is fine */
/* The lookup of set k (0 .. PT_TF2D_SETS - 1): off when `on` is 0 (no bake);
 * else the set's table, rebaked and uploaded first when tf or ink differ
 * from what it holds. */
pt_curvature_lookup pt_tf2d_lookup(pt_tf2d *t, int k, int on, const sl_transfer_function_2d *tf, const float ink[3],
                                   double min_spacing);
/* The uniforms of particles_tf2d.glsl of `program` (in use); binds the table
 * to texture unit `unit` when on. */
void pt_tf2d_uniforms(GLuint program, const pt_curvature_lookup *c, GLuint unit);

#endif
