// voxel_lines_grid.glsl — access to the voxel model uploaded by voxel_lines.c:
// per-voxel headers (32-bit offset, 8-bit count packed four per word) and the
// bit-packed lines (voxel_grid.h: face_a(3) bin_a(2k) face_b(3) bin_b(2k)
// attr(8) id(the rest of the record's bits, sl_voxel_line_id_bits), least
// significant bit first, line_bits per line).
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

// Bits [p, p + n) of the 64-bit value hi:lo (n < 32; a shift by 32 is
// written as two shifts, since GLSL leaves it undefined).
uint vx_field(uint lo, uint hi, uint p, uint n)
{
    uint v = p >= 32u ? hi >> (p - 32u) : (lo >> p) | ((hi << 1u) << (31u - p));
    return v & ((1u << n) - 1u);
}

// Endpoint on face `face` (axis = face / 2, side = face & 1) at bin `bin`
// (s + N t) of the N x N subdivision: bin centres, exact since N = 2^k.
vec3 vx_dequantize(uint face, uint bin)
{
    uint k = uint(u_quant_bits);
    float inv_n = 1.0 / float(u_quant);
    vec2 st = (vec2(float(bin & ((1u << k) - 1u)), float(bin >> k)) + 0.5) * inv_n;
    float side = float(face & 1u);
    uint axis = face >> 1u;
    return axis == 0u ? vec3(side, st.x, st.y) : (axis == 1u ? vec3(st.x, side, st.y) : vec3(st.x, st.y, side));
}

// Line `index`: endpoints relative to its voxel's corner, attribute byte and
// id. A record (<= 56 bits, byte aligned) lies in three consecutive words
// (the line buffer has 8 zero bytes of padding after the last record).
void vx_line(uint index, out vec3 a, out vec3 b, out uint attr, out uint id)
{
    // Word and bit from the byte offset (index * bytes < 2^32 for any buffer
    // below 4 GiB, which voxel_lines.c checks; index * bits would wrap).
    uint byte_pos = index * uint(u_line_bits >> 3);
    uint w = byte_pos >> 2u, o = (byte_pos & 3u) * 8u;
    uint w0 = vx_words[w], w1 = vx_words[w + 1u], w2 = vx_words[w + 2u];
    uint lo = (w0 >> o) | ((w1 << 1u) << (31u - o));
    uint hi = (w1 >> o) | ((w2 << 1u) << (31u - o));
    uint k2 = uint(2 * u_quant_bits);
    uint eb = 3u + k2;
    a = vx_dequantize(lo & 7u, vx_field(lo, hi, 3u, k2));
    b = vx_dequantize(vx_field(lo, hi, eb, 3u), vx_field(lo, hi, eb + 3u, k2));
    attr = vx_field(lo, hi, 2u * eb, 8u);
    id = vx_field(lo, hi, 2u * eb + 8u, uint(u_line_bits) - 2u * eb - 8u);
}
