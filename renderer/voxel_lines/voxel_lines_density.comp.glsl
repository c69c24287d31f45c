// voxel_lines_density.comp.glsl — the per-voxel line density of the density
// LoD (Kanzler et al., Sec. 3.4, eq. 1: rho = sum of length x opacity), from
// the uploaded voxel model (voxel_lines_grid.glsl): per voxel the sum over its
// lines of the dequantized length (voxel units) times the line's weight under
// the opacity transfer function — 1 for a constant opacity, else the ramp
// clamp(t, 0, 1) of the line's colormap coordinate t, computed from its
// attribute byte exactly as voxel_lines.frag.glsl does. The constant
// `opacity` multiplies in at render time (u_extinction), so only a change of
// the transfer function, the attribute or the scalar range re-runs this pass
// (voxel_lines.c; the lines are not re-voxelized). Writes level 0 of the
// density texture; the C side rebuilds the mip chain (the octree).
// Does not: look at neighbours, or weight by opacity_by_distance.
#include "voxel_lines/voxel_lines_grid.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(r32f, binding = 0) uniform writeonly image3D u_out;
uniform int u_opacity_ramp;    // 1: weight = ramp of the colormap coordinate; 0: weight 1
uniform vec2 u_attr_range;     // colormap t of attribute bytes 0 and 255

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, u_dims)))
        return;
    int v = vx_index(c);
    uint count = vx_count(v), first = vx_offsets[v];
    float rho = 0.0;
    for (uint l = 0u; l < count; l++) {
        vec3 a, b;
        uint attr, id;
        vx_line(first + l, a, b, attr, id);
        float w = 1.0;
        if (u_opacity_ramp != 0)
            w = clamp(mix(u_attr_range.x, u_attr_range.y, float(attr) / 255.0), 0.0, 1.0);
        rho += length(b - a) * w;
    }
    imageStore(u_out, c, vec4(rho));
}
