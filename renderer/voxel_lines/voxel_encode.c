/* voxel_encode.c — face quantization and bit packing of per-voxel lines
 * (Kanzler et al., Sec. 3.2 and 5.2).
 *
 * An endpoint is a 3-bit face id plus a bin of an N x N face subdivision
 * (2 log2 N bits); a line adds an attribute byte and a local line id of at
 * least 5 bits, and is stored in the fewest whole bytes: 4, 5 and 6 bytes for
 * N = 4..8, 16..32 and 64..128, as in the paper; the id takes the bits left. Pure functions; any thread; no GL.
 * The GLSL decoder (voxel_lines_common.glsl) mirrors sl_voxel_decode_line.
 */
#include "voxel_grid.h"

#include <assert.h>
#include <math.h>

int sl_voxel_quant_bits(int n)
{
    for (int k = 1; k <= 8; k++)
        if (n == (1 << k))
            return k;
    return -1;
}

int sl_voxel_line_bytes(int k)
{
    return (2 * (3 + 2 * k) + 8 + SL_VOXEL_LINE_ID_MIN_BITS + 7) / 8;
}

int sl_voxel_line_bits(int k)
{
    return 8 * sl_voxel_line_bytes(k);
}

int sl_voxel_line_id_bits(int k)
{
    return sl_voxel_line_bits(k) - 2 * (3 + 2 * k) - 8;
}

static void face_axes(int face, int *s, int *t)
{
    int axis = face / 2;
    *s = axis == 0 ? 1 : 0;
    *t = axis == 2 ? 1 : 2;
}

static uint32_t quantize1(double x, int n)
{
    double q = floor(x * n);
    if (!(q >= 0.0))
        return 0;
    if (q > n - 1)
        return (uint32_t)(n - 1);
    return (uint32_t)q;
}

uint32_t sl_voxel_quantize(const double u[3], int face, int n)
{
    int s, t;
    face_axes(face, &s, &t);
    return quantize1(u[s], n) + (uint32_t)n * quantize1(u[t], n);
}

void sl_voxel_dequantize(int face, uint32_t bin, int n, double u[3])
{
    int s, t;
    face_axes(face, &s, &t);
    int axis = face / 2;
    u[axis] = (double)(face & 1);
    u[s] = ((double)(bin % (uint32_t)n) + 0.5) / n;
    u[t] = ((double)(bin / (uint32_t)n) + 0.5) / n;
}

uint64_t sl_voxel_encode_line(int k, const sl_voxel_line *l)
{
    assert(k >= 1 && k <= 8);
    assert(l->face_a >= 0 && l->face_a < 6 && l->face_b >= 0 && l->face_b < 6);
    assert(l->bin_a < (1u << (2 * k)) && l->bin_b < (1u << (2 * k)));
    assert(l->attr < 256 && l->id < (1u << sl_voxel_line_id_bits(k)));
    int eb = 3 + 2 * k;
    uint64_t a = (uint64_t)l->face_a | ((uint64_t)l->bin_a << 3);
    uint64_t b = (uint64_t)l->face_b | ((uint64_t)l->bin_b << 3);
    return a | (b << eb) | ((uint64_t)l->attr << (2 * eb)) | ((uint64_t)l->id << (2 * eb + 8));
}

void sl_voxel_decode_line(int k, uint64_t code, sl_voxel_line *l)
{
    int eb = 3 + 2 * k;
    uint64_t emask = (1ull << eb) - 1;
    uint64_t a = code & emask, b = (code >> eb) & emask;
    l->face_a = (int)(a & 7);
    l->bin_a = (uint32_t)(a >> 3);
    l->face_b = (int)(b & 7);
    l->bin_b = (uint32_t)(b >> 3);
    l->attr = (uint32_t)((code >> (2 * eb)) & 0xff);
    l->id = (uint32_t)((code >> (2 * eb + 8)) & ((1u << sl_voxel_line_id_bits(k)) - 1));
}
