/* volume_bricks.c — the min-max brick grid, its visible-brick mask and runs (see sl_volume.h); the counters.
 *
 * The grid is one CPU pass over the voxels at create (brick b spans voxels
 * [8b, 8b + 8]: the overlap voxel makes every trilinear sample in the brick
 * depend on that brick's voxels only), kept in memory so that a new
 * transfer function only re-derives the 1-byte-per-brick mask from it, its
 * runs (volume_brick_runs.c), and uploads those. NaN voxels are left out of min/max (a brick of NaN only has
 * min > max and is never visible). Render thread only (GL, counters).
 */
#include "sl_volume.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../gpu/sl_gpu.h"

sl_volume_counters sl_volume_counters_now; /* render thread only */

void sl_volume_get_counters(sl_volume_counters *out)
{
    *out = sl_volume_counters_now;
}

void sl_volume_bricks_destroy(sl_volume_bricks *b)
{
    if (!b)
        return;
    if (b->minmax_tex)
        glDeleteTextures(1, &b->minmax_tex);
    if (b->runs_tex)
        glDeleteTextures(1, &b->runs_tex);
    free(b->minmax);
    free(b->mask);
    free(b->runs);
    memset(b, 0, sizeof *b);
}

/* One voxel's value (vector fields: magnitude), as the texture holds it. */
static double voxel(const sl_volume *vol, size_t i)
{
    if (vol->components == 3) {
        const float *v = (const float *)vol->data + 3 * i;
        return sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    switch (vol->type) {
    case SL_VOXEL_U8: return ((const uint8_t *)vol->data)[i];
    case SL_VOXEL_U16: return ((const uint16_t *)vol->data)[i];
    case SL_VOXEL_S16: return ((const int16_t *)vol->data)[i];
    case SL_VOXEL_F32: return ((const float *)vol->data)[i];
    }
    return 0.0;
}

sl_status sl_volume_bricks_create(const sl_volume *vol, sl_volume_bricks *b, sl_err *err)
{
    memset(b, 0, sizeof *b);
    const int B = SL_VOLUME_BRICK;
    for (int a = 0; a < 3; a++)
        b->dims[a] = vol->dims[a] > 1 ? (vol->dims[a] - 2) / B + 1 : 1;
    size_t n = (size_t)b->dims[0] * (size_t)b->dims[1] * (size_t)b->dims[2];
    b->minmax = malloc(n * 2 * sizeof *b->minmax);
    b->mask = malloc(n);
    b->runs = malloc(n);
    if (!b->minmax || !b->mask || !b->runs) {
        sl_volume_bricks_destroy(b);
        return sl_err_set(err, SL_ERR_NOMEM, "volume: out of memory for %zu bricks", n);
    }
    for (size_t i = 0; i < n; i++) {
        b->minmax[2 * i] = INFINITY;
        b->minmax[2 * i + 1] = -INFINITY;
    }
    /* Each voxel goes into every brick that holds it (1, or up to 8 on the
     * overlap planes). */
    const int *d = vol->dims;
    size_t idx = 0;
    for (int z = 0; z < d[2]; z++)
        for (int y = 0; y < d[1]; y++)
            for (int x = 0; x < d[0]; x++, idx++) {
                double v = voxel(vol, idx);
                if (isnan(v))
                    continue;
                int lo[3], hi[3], c[3] = {x, y, z};
                for (int a = 0; a < 3; a++) {
                    hi[a] = c[a] / B < b->dims[a] ? c[a] / B : b->dims[a] - 1;
                    lo[a] = c[a] % B == 0 && c[a] > 0 ? c[a] / B - 1 : hi[a];
                }
                for (int bz = lo[2]; bz <= hi[2]; bz++)
                    for (int by = lo[1]; by <= hi[1]; by++)
                        for (int bx = lo[0]; bx <= hi[0]; bx++) {
                            float *mm = b->minmax + 2 * (((size_t)bz * b->dims[1] + by) * b->dims[0] + bx);
                            float fv = (float)v;
                            if (fv < mm[0]) mm[0] = fv;
                            if (fv > mm[1]) mm[1] = fv;
                        }
            }
    memset(b->mask, 1, n);
    memset(b->runs, SL_VOLUME_RUN_VISIBLE + 1, n);
    glCreateTextures(GL_TEXTURE_3D, 1, &b->minmax_tex);
    glTextureStorage3D(b->minmax_tex, 1, GL_RG32F, b->dims[0], b->dims[1], b->dims[2]);
    glTextureSubImage3D(b->minmax_tex, 0, 0, 0, 0, b->dims[0], b->dims[1], b->dims[2], GL_RG, GL_FLOAT, b->minmax);
    glCreateTextures(GL_TEXTURE_3D, 1, &b->runs_tex);
    glTextureStorage3D(b->runs_tex, 1, GL_R8UI, b->dims[0], b->dims[1], b->dims[2]);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage3D(b->runs_tex, 0, 0, 0, 0, b->dims[0], b->dims[1], b->dims[2], GL_RED_INTEGER,
                        GL_UNSIGNED_BYTE, b->runs); /* all visible, runs of 1 */
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    GLuint texs[2] = {b->minmax_tex, b->runs_tex};
    for (int k = 0; k < 2; k++) {
        glTextureParameteri(texs[k], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(texs[k], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    b->bytes = n * 9;
    sl_volume_counters_now.minmax_builds++;
    sl_status st = sl_gl_check_errors("volume: uploading the brick grid", err);
    if (st != SL_OK)
        sl_volume_bricks_destroy(b);
    return st;
}

size_t sl_volume_bricks_update_mask(sl_volume_bricks *b, sl_volume_mask_rule rule, const sl_volume_tf_table *table,
                                    double iso)
{
    size_t n = (size_t)b->dims[0] * (size_t)b->dims[1] * (size_t)b->dims[2], visible = 0;
    for (size_t i = 0; i < n; i++) {
        double lo = b->minmax[2 * i], hi = b->minmax[2 * i + 1];
        int v = 0;
        switch (rule) {
        case SL_VOLUME_MASK_TF: v = sl_volume_tf_table_visible(table, lo, hi); break;
        case SL_VOLUME_MASK_ISO: v = lo <= iso && iso <= hi; break;
        case SL_VOLUME_MASK_FINITE: v = lo <= hi; break;
        }
        b->mask[i] = (uint8_t)v;
        visible += (size_t)v;
    }
    if (sl_volume_brick_runs(b->mask, b->dims, b->runs) != 0)
        for (size_t i = 0; i < n; i++)
            b->runs[i] = (uint8_t)(b->mask[i] ? SL_VOLUME_RUN_VISIBLE + 1 : 1);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage3D(b->runs_tex, 0, 0, 0, 0, b->dims[0], b->dims[1], b->dims[2], GL_RED_INTEGER,
                        GL_UNSIGNED_BYTE, b->runs);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    sl_volume_counters_now.mask_builds++;
    return visible;
}
