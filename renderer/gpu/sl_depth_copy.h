/* sl_depth_copy.h — a target's depth as a texture that a ray marcher may read
 * while it draws into that same target (it must not sample the attachment it
 * writes): opaque geometry is drawn first, its depth copied here, and the
 * volume's rays end at it (volume_dvr's focus in `particles`, the streamline
 * tubes of `lr_volume`).
 *
 * Single-sample targets: a blit into a DEPTH_COMPONENT32F texture.
 * Multisampled: a pass that keeps the nearest sample per pixel into an R32F
 * texture (a blit would resolve one sample, implementation-defined; Mesa:
 * sample 0). Either way the texture holds reversed-Z depth in .r, 0 where
 * nothing was drawn; read it with texelFetch at level 0. The texture and the
 * resolve program are made at the first copy and kept while the target's
 * size and sample count stay. Render thread only.
 */
#ifndef SL_DEPTH_COPY_H
#define SL_DEPTH_COPY_H

#include <stddef.h>

#include <epoxy/gl.h>

#include "sl_gpu.h"

typedef struct sl_depth_copy {
    GLuint texture;               /* the copy: DEPTH_COMPONENT32F or R32F (MSAA) */
    GLuint fbo;                   /* texture attached */
    GLuint resolve_program, vao;  /* MSAA only, made at the first MSAA copy */
    int width, height, msaa;      /* what texture was made for */
} sl_depth_copy;

/* Copies target's depth into dc->texture, then binds target->fbo again
 * with the full-target viewport; depth test and blending are left off.
 * SL_ERR_GPU (an incomplete framebuffer, a shader log). */
sl_status sl_depth_copy_update(sl_depth_copy *dc, const sl_target *target, sl_err *err);
void sl_depth_copy_deinit(sl_depth_copy *dc);   /* zeroed is fine */
size_t sl_depth_copy_bytes(const sl_depth_copy *dc);

#endif
