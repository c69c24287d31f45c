// tubes_mesh.frag.glsl — Lambert + Blinn-Phong shading of the tessellated tubes,
// coloured through a colormap on a scalar (or a constant colour). Output is
// premultiplied: opacity 1 is opaque; below 1 (blended by tubes_mesh.c, draw
// order, unsorted) only the front half of each tube is drawn, so a tube
// crossing a pixel adds one layer, as in lines_oit.
#include "gpu/glsl/camera.glsl"
#include "gpu/glsl/lighting.glsl"
#include "gpu/glsl/colormap.glsl"

in vec3 v_position;
in vec3 v_normal;
in float v_scalar;

#include "gpu/glsl/line_style.glsl"
uniform float u_opacity;         // 1: opaque

layout(location = 0) out vec4 o_color;

void main()
{
    vec3 base = u_use_colormap != 0 ? sl_colormap(u_colormap, v_scalar, u_scalar_range) : u_color;
    vec3 l = normalize(u_light_eye.x * sl_right.xyz + u_light_eye.y * sl_up.xyz - u_light_eye.z * sl_forward.xyz);
    vec3 v = normalize(sl_eye.xyz - v_position);
    vec3 n = normalize(v_normal);
    if (u_opacity < 1.0 && dot(n, v) < 0.0)
        discard; // back half of a translucent tube
    sl_material m = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);
    o_color = vec4(sl_shade(base, n, l, v, m) * u_opacity, u_opacity);
}
