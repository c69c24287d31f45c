// voxel_lines_grid.glsl — access to the voxel model uploaded by voxel_lines.c:
// per-voxel headers (32-bit offset, 8-bit count packed four per word) and the
// bit-packed lines (voxel_grid.h: face_a(3) bin_a(2k) face_b(3) bin_b(2k)
// attr(8) id(5), least significant bit first, line_bits per line).
// Mirrors sl_voxel_decode_line / sl_voxel_dequantize. Grid coordinates:
// voxel (x, y, z) spans [x, x+1] x [y, y+1] x [z, z+1].
layout(std430, binding = 1) readonly buffer sl_voxel_offsets { uint vx_offsets[]; };
layout(std430, binding = 2) readonly buffer sl_voxel_counts { uint vx_counts[]; };
layout(std430, binding = 3) readonly buffer sl_voxel_lines { uint vx_words[]; };

uniform ivec3 u_dims;
uniform int u_quant;      // N
uniform int u_quant_bits; // k = log2 N
uniform int u_line_bits;  // 8 * bytes per line

int vx_index(ivec3 c) { return c.x + u_dims.x * (c.y + u_dims.y * c.z); }

uint vx_count(int v) { return (vx_counts[v >> 2] >> uint((v & 3) * 8)) & 255u; }

// n < 32 bits starting at bit pos; a field spans at most two words.
uint vx_bits(uint pos, uint n)
{
    uint w = pos >> 5u, o = pos & 31u;
    uint v = vx_words[w] >> o;
    if (o + n > 32u)
        v |= vx_words[w + 1u] << (32u - o);
    return v & ((1u << n) - 1u);
}

vec3 vx_dequantize(uint face, uint bin)
{
    int axis = int(face >> 1u);
    int s = axis == 0 ? 1 : 0;
    int t = axis == 2 ? 1 : 2;
    uint n = uint(u_quant);
    vec3 u;
    u[axis] = float(face & 1u);
    u[s] = (float(bin % n) + 0.5) / float(n);
    u[t] = (float(bin / n) + 0.5) / float(n);
    return u;
}

// Line `index`: endpoints relative to its voxel's corner, attribute byte and id.
void vx_line(uint index, out vec3 a, out vec3 b, out uint attr, out uint id)
{
    uint pos = index * uint(u_line_bits);
    uint k2 = uint(2 * u_quant_bits);
    uint eb = 3u + k2;
    a = vx_dequantize(vx_bits(pos, 3u), vx_bits(pos + 3u, k2));
    b = vx_dequantize(vx_bits(pos + eb, 3u), vx_bits(pos + eb + 3u, k2));
    attr = vx_bits(pos + 2u * eb, 8u);
    id = vx_bits(pos + 2u * eb + 8u, 5u);
}
