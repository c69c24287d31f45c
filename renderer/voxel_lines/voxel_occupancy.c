/* voxel_occupancy.c — voxel_occupancy.h: separable max over 2 dilate + 1 voxels, then 2^3 maxima per level. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "voxel_occupancy.h"

void sl_voxel_occupancy_deinit(sl_voxel_occupancy *o)
{
    if (!o)
        return;
    for (int L = 0; L < SL_VOXEL_OCCUPANCY_MAX_LEVELS; L++)
        free(o->level[L]);
    *o = (sl_voxel_occupancy){0};
}

sl_status sl_voxel_occupancy_build(const int dims[3], const uint8_t *counts, int dilate, sl_voxel_occupancy *out,
                                   sl_err *err)
{
    *out = (sl_voxel_occupancy){0};
    if (dilate < 0 || dilate > 2)
        return sl_err_set(err, SL_ERR_INVALID, "voxel_lines: occupancy dilation %d (0..2)", dilate);
    size_t n = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    int maxdim = dims[0] > dims[1] ? dims[0] : dims[1];
    maxdim = maxdim > dims[2] ? maxdim : dims[2];
    out->levels = 1;
    while (out->levels < SL_VOXEL_OCCUPANCY_MAX_LEVELS && (1 << out->levels) <= maxdim)
        out->levels++;
    uint8_t *a = malloc(n ? n : 1), *b = malloc(n ? n : 1);
    if (!a || !b) {
        free(a);
        free(b);
        return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines: out of memory for the occupancy of %zu voxels", n);
    }
    for (size_t v = 0; v < n; v++)
        a[v] = counts[v] != 0;
    size_t stride[3] = {1, (size_t)dims[0], (size_t)dims[0] * (size_t)dims[1]};
    for (int ax = 0; ax < 3 && dilate > 0; ax++) {
        for (size_t v = 0; v < n; v++) {
            int c = (int)(v / stride[ax] % (size_t)dims[ax]);
            uint8_t m = 0;
            for (int k = -dilate; k <= dilate; k++)
                if (c + k >= 0 && c + k < dims[ax])
                    m |= a[(size_t)((ptrdiff_t)v + (ptrdiff_t)k * (ptrdiff_t)stride[ax])];
            b[v] = m;
        }
        uint8_t *t = a;
        a = b;
        b = t;
    }
    free(b);
    out->level[0] = a;
    memcpy(out->dims[0], dims, sizeof out->dims[0]);
    for (int L = 1; L < out->levels; L++) {
        const int *w = out->dims[L - 1];
        int *gw = out->dims[L];
        for (int c = 0; c < 3; c++)
            gw[c] = w[c] / 2 > 1 ? w[c] / 2 : 1;
        uint8_t *next = calloc((size_t)gw[0] * gw[1] * gw[2], 1);
        if (!next) {
            sl_voxel_occupancy_deinit(out);
            return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines: out of memory for occupancy level %d", L);
        }
        const uint8_t *prev = out->level[L - 1];
        for (int z = 0; z < w[2]; z++)
            for (int y = 0; y < w[1]; y++)
                for (int x = 0; x < w[0]; x++) {
                    int X = x / 2 < gw[0] ? x / 2 : gw[0] - 1, Y = y / 2 < gw[1] ? y / 2 : gw[1] - 1,
                        Z = z / 2 < gw[2] ? z / 2 : gw[2] - 1;
                    next[(size_t)X + (size_t)gw[0] * ((size_t)Y + (size_t)gw[1] * Z)] |=
                        prev[(size_t)x + (size_t)w[0] * ((size_t)y + (size_t)w[1] * z)];
                }
        out->level[L] = next;
    }
    return SL_OK;
}
