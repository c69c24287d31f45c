// lr_lookup.glsl — int lr_find_element(vec3 p): the element containing p
// under the element rule of lrspline/sl_lr.h (half-open boxes, closed at the
// domain's upper face), -1 outside the domain or for NaN. The GPU form of
// sl_lr_lookup (layout, bindings 10..12 and uniforms documented in
// sl_lr_lookup.h, filled by sl_lr_lookup_gpu_bind). Planes are stored as the
// float just at or above their double value, so float points get exactly the
// CPU (double) answer. Kind: LR_LOOKUP_KIND (1 texture, 2 octree, 3 kdtree,
// 4 kdforest) when #defined at program build, else the uniform lr_lookup_kind.
// LR_LOOKUP_HEADS_TEXTURE #defined: the heads are read from the GL_R32UI 3D
// texture on unit 8 (lr_lookup_heads_tex) instead of binding 10, as in the
// paper (measured against the SSBO in bench-lr-lookup).
// Includable (no #version); reads only its own buffers and uniforms.

layout(std430, binding = 10) readonly buffer LrLookupHeads { uint lr_heads[]; };
layout(std430, binding = 11) readonly buffer LrLookupNodes { uint lr_nodes[]; };
layout(std430, binding = 12) readonly buffer LrLookupPlanes { float lr_planes[]; };

// Deeper than any tree sl_lr_lookup builds (k-d: log2 of 8M elements plus
// imbalance; octree: SL_LR_OCTREE_MAX_LEVEL 30).
#define LR_LOOKUP_MAX_DEPTH 64

uniform ivec3 lr_lookup_n;
uniform vec3 lr_lookup_lo;
uniform vec3 lr_lookup_hi;
uniform vec3 lr_lookup_origin;
uniform vec3 lr_lookup_scale;
#ifndef LR_LOOKUP_KIND
uniform int lr_lookup_kind;
#endif
#ifdef LR_LOOKUP_HEADS_TEXTURE
uniform usampler3D lr_lookup_heads_tex;
#endif

// Cell of coordinate x of direction `axis` among its planes (which start at
// lr_planes[base]): an estimate corrected against the planes, so exact.
int lr_lookup_cell(float x, int axis, int base)
{
    int n = lr_lookup_n[axis];
    int c = clamp(int((x - lr_lookup_origin[axis]) * lr_lookup_scale[axis]), 0, n - 1);
    // The estimate is off by at most a cell or two (rounding); bounded loops
    // without early exits (see the k-d traversal below).
    for (int k = 0; k < 4; k++)
        c -= c > 0 && x < lr_planes[base + c] ? 1 : 0;
    for (int k = 0; k < 4; k++)
        c += c < n - 1 && x >= lr_planes[base + c + 1] ? 1 : 0;
    return c;
}

int lr_find_element(vec3 p)
{
    if (!(all(greaterThanEqual(p, lr_lookup_lo)) && all(lessThanEqual(p, lr_lookup_hi))))
        return -1;
#ifdef LR_LOOKUP_KIND
    const int kind = LR_LOOKUP_KIND;
#else
    int kind = lr_lookup_kind;
#endif
    if (kind == 2) { // octree: 11 words per split cell
        uint ref = lr_heads[0];
        for (int level = 0; level <= LR_LOOKUP_MAX_DEPTH && (ref & 0x80000000u) == 0u; level++) {
            uint b = ref * 11u;
            vec3 mid = vec3(uintBitsToFloat(lr_nodes[b]), uintBitsToFloat(lr_nodes[b + 1u]),
                            uintBitsToFloat(lr_nodes[b + 2u]));
            uint c = (p.x >= mid.x ? 1u : 0u) | (p.y >= mid.y ? 2u : 0u) | (p.z >= mid.z ? 4u : 0u);
            ref = lr_nodes[b + 3u + c];
        }
        uint e = ref & 0x7FFFFFFFu;
        return (ref & 0x80000000u) == 0u || e == 0x7FFFFFFFu ? -1 : int(e);
    }
    int cx = lr_lookup_cell(p.x, 0, 0);
    int cy = lr_lookup_cell(p.y, 1, lr_lookup_n.x + 1);
    int cz = lr_lookup_cell(p.z, 2, lr_lookup_n.x + lr_lookup_n.y + 2);
#ifdef LR_LOOKUP_HEADS_TEXTURE
    uint head = texelFetch(lr_lookup_heads_tex, ivec3(cx, cy, cz), 0).r;
#else
    uint head = lr_heads[cx + lr_lookup_n.x * (cy + lr_lookup_n.y * cz)];
#endif
    if (kind == 1) // texture
        return int(head);
    if ((head & 0x80000000u) != 0u) { // a block holding one element
        uint e = head & 0x7FFFFFFFu;
        return e == 0x7FFFFFFFu ? -1 : int(e);
    }
    // Algorithm 1: [0] = axis << 30 | index, [1] = split; right child next.
    // Bounded, one exit after the loop, no dynamic vector index: llvmpipe drew
    // wrong elements with `for (;;)` + return + p[axis] inside lr_volume's march
    // (a line of rays across the image where neighbouring pixels part ways).
    uint i = head, w = lr_nodes[2u * i];
    for (int level = 0; level <= LR_LOOKUP_MAX_DEPTH && (w >> 30) != 3u; level++) {
        uint axis = w >> 30;
        float x = axis == 0u ? p.x : (axis == 1u ? p.y : p.z);
        i = x < uintBitsToFloat(lr_nodes[2u * i + 1u]) ? (w & 0x3FFFFFFFu) : i + 1u;
        w = lr_nodes[2u * i];
    }
    uint e = w & 0x3FFFFFFFu;
    return (w >> 30) != 3u || e == 0x3FFFFFFFu ? -1 : int(e);
}
