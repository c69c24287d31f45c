/* volume_texture.c — a scalar volume as a 3D texture holding exact data values (see sl_volume.h).
 *
 * u8 goes up as R16 (u8 · 257: value = texel · 255), u16 as R16 (value =
 * texel · 65535); s16 is
 * shifted by 32768 into R16 on the CPU (a normalized signed format would
 * fold -32768 onto -32767); f32 as R32F, NaN kept (the shaders treat it as
 * transparent); vector fields as their R32F magnitude. One upload per
 * volume, counted. Render thread only.
 */
#include "sl_volume.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../gpu/sl_gpu.h"

extern sl_volume_counters sl_volume_counters_now; /* volume_bricks.c */

void sl_volume_texture_destroy(sl_volume_texture *t)
{
    if (t && t->tex)
        glDeleteTextures(1, &t->tex);
    if (t)
        memset(t, 0, sizeof *t);
}

void sl_volume_texture_set_filter(const sl_volume_texture *t, int linear)
{
    GLint f = linear ? GL_LINEAR : GL_NEAREST;
    glTextureParameteri(t->tex, GL_TEXTURE_MIN_FILTER, f);
    glTextureParameteri(t->tex, GL_TEXTURE_MAG_FILTER, f);
}

sl_status sl_volume_texture_create(const sl_volume *vol, sl_volume_texture *t, sl_err *err)
{
    memset(t, 0, sizeof *t);
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    for (int a = 0; a < 3; a++)
        if (vol->dims[a] > max3d)
            return sl_err_set(err, SL_ERR_UNSUPPORTED, "volume: %d voxels along axis %d exceed this GPU's 3D texture "
                              "limit of %d", vol->dims[a], a, (int)max3d);
    size_t n = (size_t)vol->dims[0] * (size_t)vol->dims[1] * (size_t)vol->dims[2];
    GLenum internal = GL_R32F, type = GL_FLOAT;
    const void *pixels = vol->data;
    void *converted = NULL;
    size_t texel = 4;
    t->value_scale = 1.0f;
    t->value_offset = 0.0f;
    if (vol->components == 3) {
        float *m = malloc(n * sizeof *m);
        if (!m)
            return sl_err_set(err, SL_ERR_NOMEM, "volume: out of memory for %zu magnitudes", n);
        const float *v = vol->data;
        for (size_t i = 0; i < n; i++)
            m[i] = sqrtf(v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2]);
        pixels = converted = m;
    } else {
        switch (vol->type) {
        case SL_VOXEL_U8: {
            /* As R16 (v · 257, so texel = v / 255 exactly): llvmpipe filters
             * 8-bit textures with 8-bit weights (measured on ch2: max 2/255 in
             * mip, isosurface hits off by 11 % of the diagonal), 16-bit ones
             * in float. */
            uint16_t *u = malloc(n * sizeof *u);
            if (!u)
                return sl_err_set(err, SL_ERR_NOMEM, "volume: out of memory for %zu voxels", n);
            const uint8_t *s = vol->data;
            for (size_t i = 0; i < n; i++)
                u[i] = (uint16_t)(s[i] * 257u);
            pixels = converted = u;
            internal = GL_R16, type = GL_UNSIGNED_SHORT, texel = 2, t->value_scale = 255.0f;
            break;
        }
        case SL_VOXEL_U16:
            internal = GL_R16, type = GL_UNSIGNED_SHORT, texel = 2, t->value_scale = 65535.0f;
            break;
        case SL_VOXEL_S16: {
            uint16_t *u = malloc(n * sizeof *u);
            if (!u)
                return sl_err_set(err, SL_ERR_NOMEM, "volume: out of memory for %zu voxels", n);
            const int16_t *s = vol->data;
            for (size_t i = 0; i < n; i++)
                u[i] = (uint16_t)((int32_t)s[i] + 32768);
            pixels = converted = u;
            internal = GL_R16, type = GL_UNSIGNED_SHORT, texel = 2;
            t->value_scale = 65535.0f;
            t->value_offset = -32768.0f;
            break;
        }
        case SL_VOXEL_F32:
            break;
        }
    }
    glCreateTextures(GL_TEXTURE_3D, 1, &t->tex);
    glTextureStorage3D(t->tex, 1, internal, vol->dims[0], vol->dims[1], vol->dims[2]);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage3D(t->tex, 0, 0, 0, 0, vol->dims[0], vol->dims[1], vol->dims[2], GL_RED, type, pixels);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    free(converted);
    glTextureParameteri(t->tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t->tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t->tex, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    sl_volume_texture_set_filter(t, 1);
    t->bytes = n * texel;
    sl_volume_counters_now.texture_uploads++;
    sl_status st = sl_gl_check_errors("volume: uploading the 3D texture", err);
    if (st != SL_OK)
        sl_volume_texture_destroy(t);
    return st;
}
