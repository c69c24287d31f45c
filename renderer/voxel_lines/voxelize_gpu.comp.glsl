// voxelize_gpu.comp.glsl — GPU voxelization of curves (Kanzler et al., Sec. 3.3),
// the same model as voxelize_cpu.c, bit for bit: the clipping runs in double
// precision with `precise` arithmetic in the same order as the C code, so the
// quantized endpoints agree; the attribute byte (definition in voxel_grid.h)
// interpolates the per-vertex normalized values the C side uploads (vx_attr)
// at the crossings and rounds their mean with the same double operations.
// One source, five entry points chosen by VX_PASS:
//   1 COUNT   per curve: number of kept (non-degenerate) pieces
//   2 EMIT    per curve: (voxel, code) items at the curve's offset (curve order)
//   3 HISTO   per item: voxel histogram (atomicAdd)
//   4 SCATTER per item: item index into its voxel's segment (any order)
//   5 FINISH  per voxel: sort its segment by item index (= curve order, so the
//             cap keeps the same lines as the CPU), pack the first `cap` codes
//             into the line words (atomicOr: bits of one line are written by
//             one invocation only) and sum their lengths (density).
// The exclusive scans between passes run in gpu/glsl/scan.comp.glsl (sl_gpu_scan.h).
layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer vx_positions { float positions[]; };
layout(std430, binding = 1) readonly buffer vx_line_offsets { uint line_offsets[]; };
layout(std430, binding = 2) buffer vx_curve_counts { uint curve_counts[]; };   // COUNT out, EMIT in (offsets)
layout(std430, binding = 3) buffer vx_items { uvec4 items[]; };                // voxel, code lo, code hi, -
layout(std430, binding = 4) buffer vx_voxel_counts { uint voxel_counts[]; };   // HISTO out / SCATTER fill
layout(std430, binding = 5) readonly buffer vx_voxel_starts { uint voxel_starts[]; }; // uncapped scan
layout(std430, binding = 6) buffer vx_slots { uint slots[]; };
layout(std430, binding = 7) readonly buffer vx_line_starts { uint line_starts[]; };   // capped scan
layout(std430, binding = 8) buffer vx_words { uint words[]; };
layout(std430, binding = 9) buffer vx_density { float density[]; };
layout(std430, binding = 10) readonly buffer vx_attributes { double vx_attr[]; }; // per vertex, normalized

uniform dvec3 u_lo;
uniform double u_h;
uniform ivec3 u_dims;
uniform int u_quant;
uniform int u_k;
uniform uint u_count;        // curves, items or voxels, by pass
uniform uint u_group_base;   // first work group of this dispatch chunk (voxelize_gpu.c: dispatch)
uniform uint u_cap;
uniform int u_line_bits;
uniform bool u_has_attr;     // vx_attr holds the chosen attribute; else every value is 0

uint g_kept;
uint g_out;
uint g_curve;

uint quantize1(double x)
{
    precise double q = floor(x * double(u_quant));
    if (!(q >= 0.0LF))
        return 0u;
    if (q > double(u_quant - 1))
        return uint(u_quant - 1);
    return uint(q);
}

uint quantize(dvec3 u, int face)
{
    int axis = face / 2;
    int s = axis == 0 ? 1 : 0;
    int t = axis == 2 ? 1 : 2;
    return quantize1(u[s]) + uint(u_quant) * quantize1(u[t]);
}

// Normalized attribute of vertex v (voxel_grid.h, step 1: computed on the CPU).
double vertex_attr(uint v)
{
#if VX_PASS == 2
    return u_has_attr ? vx_attr[v] : 0.0LF;
#else
    return 0.0LF; // only EMIT writes attribute bytes
#endif
}

// Attribute byte of a piece (sl_voxel_attr_byte, step 3): round half up of
// 255 x the clamped mean, with the same double operations as the C code.
uint attr_byte(double attr_a, double attr_b)
{
    precise double m = 0.5LF * (attr_a + attr_b);
    if (!(m > 0.0LF))
        m = 0.0LF;
    if (m > 1.0LF)
        m = 1.0LF;
    precise double y = m * 255.0LF;
    precise double q = floor(y);
    precise double frac = y - q;
    return uint(q) + (frac >= 0.5LF ? 1u : 0u);
}

// ORs `value` into the 64-bit record (lo, hi) at bit `shift` (< 64; the
// value's bits above 64 - shift must be 0).
void put_bits(inout uint lo, inout uint hi, uint value, uint shift)
{
    if (shift >= 32u) {
        hi |= value << (shift - 32u);
    } else {
        lo |= value << shift;
        if (shift > 0u)
            hi |= value >> (32u - shift);
    }
}

// State of the walk (as clip_state in voxelize_cpu.c).
ivec3 g_cell;
bool g_have_entry;
dvec3 g_entry;
int g_entry_face;
double g_entry_attr;

void emit_piece(dvec3 p, int exit_face, double attr)
{
    if (!g_have_entry)
        return;
    if (g_entry == p)
        return; // zero length
    dvec3 ua = g_entry - dvec3(g_cell), ub = p - dvec3(g_cell);
    uint ba = quantize(ua, g_entry_face), bb = quantize(ub, exit_face);
    if (g_entry_face == exit_face && ba == bb)
        return; // collapsed by quantization
#if VX_PASS == 2
    uint eb = uint(3 + 2 * u_k);
    // Up to 2 * 19 + 13 = 51 bits: lo word and hi word, packed as
    // sl_voxel_encode_line: face_a bin_a face_b bin_b attr(8) id(5).
    uint lo = 0u, hi = 0u;
    put_bits(lo, hi, uint(g_entry_face) | (ba << 3u), 0u);
    put_bits(lo, hi, uint(exit_face) | (bb << 3u), eb);
    put_bits(lo, hi, attr_byte(g_entry_attr, attr), 2u * eb);
    put_bits(lo, hi, g_curve & ((1u << uint(u_line_bits - 2 * int(eb) - 8)) - 1u), 2u * eb + 8u); // sl_voxel_line_id_bits
    int v = g_cell.x + u_dims.x * (g_cell.y + u_dims.y * g_cell.z);
    items[g_out++] = uvec4(uint(v), lo, hi, 0u);
#endif
    g_kept++;
}

void set_entry(dvec3 p, int face, double attr)
{
    g_have_entry = true;
    g_entry = p;
    g_entry_face = face;
    g_entry_attr = attr;
}

double clampd(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

void clip_segment(dvec3 a, dvec3 b, double attr_a, double attr_b)
{
    precise dvec3 d = b - a;
    bvec3 blocked = bvec3(false);
    for (int guard = 0; guard < 3 * 4096; guard++) {
        double tmin = 1.0e300LF;
        dvec3 plane = dvec3(0.0LF);
        dvec3 t = dvec3(1.0e300LF);
        for (int ax = 0; ax < 3; ax++) {
            if (blocked[ax]) {
                continue;
            } else if (d[ax] > 0.0LF) {
                plane[ax] = double(g_cell[ax] + 1);
                precise double tt = (plane[ax] - a[ax]) / d[ax];
                t[ax] = tt;
            } else if (d[ax] < 0.0LF) {
                plane[ax] = double(g_cell[ax]);
                precise double tt = (plane[ax] - a[ax]) / d[ax];
                t[ax] = tt;
            }
            if (t[ax] < tmin)
                tmin = t[ax];
        }
        if (!(tmin <= 1.0LF))
            return;
        if (tmin < 0.0LF)
            tmin = 0.0LF;
        dvec3 p;
        ivec3 next = g_cell;
        int first_axis = -1;
        bool out_of_grid = false;
        for (int ax = 0; ax < 3; ax++) {
            precise double pa = a[ax] + tmin * d[ax];
            p[ax] = pa;
            if (t[ax] == tmin || (tmin == 0.0LF && t[ax] <= 0.0LF)) {
                p[ax] = plane[ax];
                next[ax] += d[ax] > 0.0LF ? 1 : -1;
                if (next[ax] < 0 || next[ax] >= u_dims[ax]) {
                    out_of_grid = true;
                    blocked[ax] = true;
                    next[ax] = g_cell[ax];
                }
                if (first_axis < 0)
                    first_axis = ax;
            } else {
                p[ax] = clampd(p[ax], double(g_cell[ax]), double(g_cell[ax] + 1));
            }
        }
        // Attribute at the crossing (voxel_grid.h, step 2), as voxelize_cpu.c.
        precise double attr = attr_a + tmin * (attr_b - attr_a);
        bool up = d[first_axis] > 0.0LF;
        emit_piece(p, 2 * first_axis + (up ? 1 : 0), attr);
        if (out_of_grid) {
            g_have_entry = false;
            g_cell = next;
            continue;
        }
        g_cell = next;
        set_entry(p, 2 * first_axis + (up ? 0 : 1), attr);
    }
}

dvec3 grid_point(uint v)
{
    dvec3 p;
    for (int c = 0; c < 3; c++) {
        precise double x = (double(positions[3u * v + uint(c)]) - u_lo[c]) / u_h;
        p[c] = clampd(x, 0.0LF, double(u_dims[c]));
    }
    return p;
}

void clip_curve(uint c)
{
    uint first = line_offsets[c], n = line_offsets[c + 1u] - first;
    g_have_entry = false;
    g_kept = 0u;
    g_curve = c;
    if (n == 0u)
        return;
    dvec3 a = grid_point(first);
    for (int ax = 0; ax < 3; ax++) {
        int cc = int(floor(a[ax]));
        g_cell[ax] = cc >= u_dims[ax] ? u_dims[ax] - 1 : cc;
    }
    for (uint i = 1u; i < n && !g_have_entry; i++) {
        dvec3 d = grid_point(first + i) - a;
        if (d == dvec3(0.0LF))
            continue;
        for (int ax = 0; ax < 3; ax++)
            if (a[ax] == double(g_cell[ax]) && d[ax] > 0.0LF) {
                set_entry(a, 2 * ax, vertex_attr(first));
                break;
            }
        break;
    }
    double attr_a = vertex_attr(first);
    for (uint i = 1u; i < n; i++) {
        dvec3 b = grid_point(first + i);
        double attr_b = vertex_attr(first + i);
        clip_segment(a, b, attr_a, attr_b);
        a = b;
        attr_a = attr_b;
    }
}

float line_length(uint lo, uint hi)
{
    uint eb = uint(3 + 2 * u_k);
    uint ea = lo & ((1u << eb) - 1u);
    uint ebits = (lo >> eb) | (eb > 0u ? hi << (32u - eb) : 0u);
    ebits &= (1u << eb) - 1u;
    vec3 pa, pb;
    for (int e = 0; e < 2; e++) {
        uint x = e == 0 ? ea : ebits;
        uint face = x & 7u, bin = x >> 3u;
        int axis = int(face >> 1u);
        int s = axis == 0 ? 1 : 0;
        int t = axis == 2 ? 1 : 2;
        vec3 u;
        u[axis] = float(face & 1u);
        u[s] = (float(bin % uint(u_quant)) + 0.5) / float(u_quant);
        u[t] = (float(bin / uint(u_quant)) + 0.5) / float(u_quant);
        if (e == 0) pa = u; else pb = u;
    }
    return length(pa - pb);
}

void main()
{
    uint i = (u_group_base + gl_WorkGroupID.x) * 64u + gl_LocalInvocationID.x;
    if (i >= u_count)
        return;
#if VX_PASS == 1
    clip_curve(i);
    curve_counts[i] = g_kept;
#elif VX_PASS == 2
    g_out = curve_counts[i];
    clip_curve(i);
#elif VX_PASS == 3
    atomicAdd(voxel_counts[items[i].x], 1u);
#elif VX_PASS == 4
    uint v = items[i].x;
    uint rank = atomicAdd(voxel_counts[v], 1u);
    slots[voxel_starts[v] + rank] = i;
#elif VX_PASS == 5
    uint start = voxel_starts[i], n = voxel_starts[i + 1u] - start;
    for (uint a = 1u; a < n; a++) { // insertion sort by item index
        uint x = slots[start + a];
        uint b = a;
        while (b > 0u && slots[start + b - 1u] > x) {
            slots[start + b] = slots[start + b - 1u];
            b--;
        }
        slots[start + b] = x;
    }
    uint keep = min(n, u_cap);
    uint out_line = line_starts[i];
    float len = 0.0;
    for (uint a = 0u; a < keep; a++) {
        uvec4 it = items[slots[start + a]];
        // Word and bit from the byte offset: (line * bytes) stays below 2^32
        // for any line buffer the GPU can hold (< 4 GiB), while line * bits
        // would wrap beyond 2^32 bits (~107 M lines of 5 bytes).
        uint byte_pos = (out_line + a) * uint(u_line_bits / 8);
        uint w = byte_pos >> 2u, o = (byte_pos & 3u) * 8u;
        atomicOr(words[w], it.y << o);
        if (o > 0u)
            atomicOr(words[w + 1u], it.y >> (32u - o));
        if (u_line_bits > 32) {
            atomicOr(words[w + 1u], it.z << o);
            if (o > 0u)
                atomicOr(words[w + 2u], it.z >> (32u - o));
        }
        len += line_length(it.y, it.z);
    }
    density[i] = len;
#endif
}
