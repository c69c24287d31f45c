// particles_tf2d.glsl — the 2D curvature transfer function of `particles`
// (particles_tf2d.h; the paper's sec. 4.2.5, Fig. 9) for any style: include
// it, set its uniforms with pt_tf2d_uniforms (C) and call
//     vec3 c = pt_curvature_color(ink, k1, k2);
// with the set's ink and the principal curvatures in 1/world units (k1 >= k2,
// e.g. r.n_k1.w and r.e1_k2.w of a pt_record). Off (u_tf2d_on 0): the ink.
// On: the set's baked table at (k1, k2) · min_spacing over [-range, range]²,
// linearly filtered, clamped at the edges (the table already holds the ink
// under the widgets, so `ink` is not read then).
uniform sampler2D u_tf2d;          // RGBA8, x = k1 per voxel, y = k2 per voxel
uniform float u_tf2d_range;        // half width of the table, per voxel
uniform float u_tf2d_min_spacing;  // world units per voxel
uniform int u_tf2d_on;

vec3 pt_curvature_color(vec3 ink, float k1, float k2)
{
    if (u_tf2d_on == 0)
        return ink;
    vec2 k = vec2(k1, k2) * u_tf2d_min_spacing;
    return texture(u_tf2d, k / (2.0 * u_tf2d_range) + 0.5).rgb;
}
