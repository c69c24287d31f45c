/* volume_gradient.c — the precomputed gradient texture (see sl_volume.h).
 *
 * The alternative to central differences in the shader: one filtered fetch
 * per shaded sample instead of six, at 4 bytes per voxel and one CPU pass
 * when first needed. Differences of the voxel values (not of the trilinear
 * field), one-sided at the volume's edges, in world units (divided by the
 * spacing), normalized into RGBA8_SNORM; zero where the difference is zero
 * or not finite. Render thread only (GL, counters).
 */
#include "sl_volume.h"

#include <math.h>
#include <stdlib.h>

#include "../gpu/sl_gpu.h"

extern sl_volume_counters sl_volume_counters_now; /* volume_bricks.c */

static double value(const sl_volume *vol, int x, int y, int z)
{
    if (vol->components == 3) {
        size_t i = ((size_t)z * vol->dims[1] + y) * vol->dims[0] + x;
        const float *v = (const float *)vol->data + 3 * i;
        return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
    }
    return sl_volume_value(vol, (size_t)x, (size_t)y, (size_t)z, 0);
}

static signed char snorm8(double v)
{
    double s = v * 127.0;
    return (signed char)(s > 127.0 ? 127 : (s < -127.0 ? -127 : lrint(s)));
}

sl_status sl_volume_gradient_create(const sl_volume *vol, GLuint *tex, size_t *bytes, sl_err *err)
{
    *tex = 0;
    const int *d = vol->dims;
    size_t n = (size_t)d[0] * d[1] * d[2];
    signed char *g = malloc(n * 4);
    if (!g)
        return sl_err_set(err, SL_ERR_NOMEM, "volume: out of memory for a %zu-voxel gradient", n);
    size_t i = 0;
    for (int z = 0; z < d[2]; z++)
        for (int y = 0; y < d[1]; y++)
            for (int x = 0; x < d[0]; x++, i++) {
                int c[3] = {x, y, z};
                double gr[3], len = 0.0;
                for (int a = 0; a < 3; a++) {
                    int lo[3] = {x, y, z}, hi[3] = {x, y, z};
                    lo[a] = c[a] > 0 ? c[a] - 1 : c[a];
                    hi[a] = c[a] < d[a] - 1 ? c[a] + 1 : c[a];
                    double span = (hi[a] - lo[a]) * vol->spacing[a];
                    gr[a] = span > 0.0 ? (value(vol, hi[0], hi[1], hi[2]) - value(vol, lo[0], lo[1], lo[2])) / span : 0.0;
                    len += gr[a] * gr[a];
                }
                len = sqrt(len);
                int ok = len > 0.0 && isfinite(len);
                for (int a = 0; a < 3; a++)
                    g[4 * i + a] = ok ? snorm8(gr[a] / len) : 0;
                g[4 * i + 3] = 0;
            }
    glCreateTextures(GL_TEXTURE_3D, 1, tex);
    glTextureStorage3D(*tex, 1, GL_RGBA8_SNORM, d[0], d[1], d[2]);
    glTextureSubImage3D(*tex, 0, 0, 0, 0, d[0], d[1], d[2], GL_RGBA, GL_BYTE, g);
    free(g);
    glTextureParameteri(*tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(*tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    *bytes = n * 4;
    sl_volume_counters_now.gradient_builds++;
    sl_status st = sl_gl_check_errors("volume: uploading the gradient texture", err);
    if (st != SL_OK) {
        glDeleteTextures(1, tex);
        *tex = 0;
    }
    return st;
}
