/* flow_gpu.h — streamline integration in a compute shader (issue 15
 * "Streamlines", paper sec. 5.1 and 5.6: one invocation per streamline,
 * single | mixed | double precision), the same solvers, step rules and
 * stop reasons as the CPU reference sl_flow_trace (sl_flow.h).
 *
 * Precision: single = float everywhere; mixed = double for positions,
 * time and the RK update, the field evaluated in float at local
 * coordinates (cell index and weights found in double, as the paper
 * evaluates in element-local coordinates; an LR field_m does the same per
 * element: element and local coordinates in double, de Casteljau in float);
 * double = double everywhere, the trilinear and the Bézier evaluation
 * included (texel values are floats, converted exactly). Mixed and double need
 * doubles in GLSL (core in 4.50, GL_ARB_gpu_shader_fp64; llvmpipe has them).
 * Regular vector fields as an RGBA32F 3D texture sampled by texelFetch
 * with the CPU's trilinear order of operations (flow_field_regular.glsl);
 * LR-spline volumes of dim 3 as the Bézier blocks and element look-up of
 * lrspline/sl_lr_bezier.h (flow_field_lr.glsl; SSBO bindings 6..12, flow's
 * own 0..2), built from the model once in create or borrowed from the
 * renderer that built them (sl_flow_gpu_create_lr); their heuristic step is
 * per point (the element's min side / 2^degree, as sl_flow_local_size).
 * Render thread only, GL context current. Not done here: drawing (the
 * result goes through sl_flow_result_to_dataset to renderer/tubes).
 */
#ifndef FLOW_GPU_H
#define FLOW_GPU_H

#include <epoxy/gl.h>

#include "../lrspline/sl_lr_bezier.h"
#include "sl_flow.h"

typedef enum sl_flow_precision {
    SL_FLOW_SINGLE = 0, SL_FLOW_MIXED = 1, SL_FLOW_DOUBLE = 2
} sl_flow_precision;
/* "single", "mixed", "double" in sl_flow_precision order, NULL-terminated. */
extern const char *const sl_flow_precision_names[4];
/* "single" | "mixed" | "double"; -1 when unknown. */
int sl_flow_precision_find(const char *name);
const char *sl_flow_precision_name(sl_flow_precision p);

typedef struct sl_flow_gpu sl_flow_gpu;

/* A regular vector field as flow_field_regular.glsl reads it
 * (flow_field_gpu.c, also used by sightline-probe --gpu): its voxels as an
 * RGBA32F 3D texture (nearest; the shader interpolates). SL_ERR_UNSUPPORTED
 * for other field kinds, SL_ERR_NOMEM, SL_ERR_GPU; on failure *texture is 0.
 * The caller deletes the texture (glDeleteTextures). */
sl_status sl_flow_field_texture_create(const sl_flow_field *f, GLuint *texture, sl_err *err);
/* Binds the texture to unit 0 and sets u_field, u_dims, u_origin_f,
 * u_spacing_f (and with doubles u_origin_d, u_spacing_d) on `program`,
 * which must be current. */
void sl_flow_field_texture_bind(GLuint program, const sl_flow_field *f, GLuint texture, int doubles);

/* Uploads the field (LR: builds the Bézier blocks and the look-up, then
 * uploads them). SL_ERR_UNSUPPORTED for analytic fields and LR models not
 * of dim 3 (the message says which), the block build's errors
 * (SL_ERR_NOMEM, SL_ERR_LIMIT), SL_ERR_GPU on GL failure. The field's
 * volume or LR model is borrowed only during the call. */
sl_status sl_flow_gpu_create(const sl_flow_field *f, sl_flow_gpu **out, sl_err *err);
/* An LR field of dim 3 over Bézier blocks and a look-up already built and
 * uploaded by the caller (lr_volume's prepare: any look-up kind), borrowed
 * instead of built again: bz and blocks must outlive the state and stay
 * where they are. Mixed and double traces read the double buffers, which
 * the caller adds first (sl_lr_bezier_upload_double; a trace without them is
 * SL_ERR_INVALID). SL_ERR_INVALID when the blocks are not the field's (element
 * count, dim), SL_ERR_UNSUPPORTED for a field that is not an LR volume of
 * dim 3, SL_ERR_NOMEM. */
sl_status sl_flow_gpu_create_lr(const sl_flow_field *f, const sl_lr_bezier *bz, const sl_lr_bezier_gpu *blocks,
                                sl_flow_gpu **out, sl_err *err);
void sl_flow_gpu_destroy(sl_flow_gpu *g); /* NULL is fine */

/* Traces one line per seed; *out as sl_flow_trace (samples converted to
 * double; `evaluations` is not counted on the GPU). Programs are compiled on
 * first use per precision and kept. compute_ms (may be NULL):
 * wall time of the dispatch to glFinish, without upload, compile or
 * read-back. SL_ERR_INVALID for bad options, SL_ERR_UNSUPPORTED for mixed /
 * double without GL doubles, SL_ERR_LIMIT when the sample buffer would
 * exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE or SL_MAX_VERTICES samples,
 * SL_ERR_GPU on compile or GL errors. */
sl_status sl_flow_gpu_trace(sl_flow_gpu *g, const double *seeds, size_t seed_count,
                            const sl_flow_options *o, sl_flow_precision precision,
                            sl_flow_result *out, double *compute_ms, sl_err *err);

#endif
