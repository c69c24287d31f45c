// ribbons_points.glsl — the per-point storage buffers of ribbons_prep.c (plan §1.3), read by the
// pulling vertex shader and the geometry shader: binding 1 the shared colour scalars
// (sl_line_colors), 2-4 the three packed vec4 per dataset vertex. Needs ribbons_vertex.glsl.
layout(std430, binding = 1) readonly buffer sl_scalars { float scalars[]; };
layout(std430, binding = 2) readonly buffer rb_points { vec4 pos_radius[]; };
layout(std430, binding = 3) readonly buffer rb_frames { vec4 normal_twist[]; };
layout(std430, binding = 4) readonly buffer rb_tangents { vec4 tangent_slope[]; };

RibbonPoint sl_ribbon_fetch(uint point)
{
    return sl_ribbon_point(pos_radius[point], normal_twist[point], tangent_slope[point], scalars[point]);
}
