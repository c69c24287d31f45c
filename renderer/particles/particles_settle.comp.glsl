// particles_settle.comp.glsl — after the last redistribution step, every
// alive particle is moved back onto the trilinear isosurface
// (particles_project.glsl pt_polish: Newton steps, then a bracketed
// bisection along the gradient line). A particle that stays farther than
// u_max_offset (world) from it to first order, |f - iso| / |grad f|, has
// lost its surface (pushed off the end of a feature thinner than the
// lattice, or the surface there vanished between two lattice edges): it is
// marked dead, so it is dropped and counted, never drawn or exported.
// In place, one invocation per particle.
layout(local_size_x = 256) in;

#include "particles/particles_common.glsl"
#include "particles/particles_field.glsl"
#include "particles/particles_project.glsl"

layout(std430, binding = 1) buffer pt_io { pt_particle pt_src[]; };

uniform uint u_count;
uniform float u_sigma;
uniform float u_max_offset;
uniform vec3 u_box_world;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count)
        return;
    pt_particle q = pt_src[i];
    if (!pt_alive(q))
        return;
    vec3 p = q.p.xyz;
    pt_polish(p, 0.5 * u_sigma, u_box_world);
    vec3 gu;
    float f = pt_trilinear(p / u_spacing, gu);
    vec3 g = pt_world_gradient(gu);
    float gl = length(g);
    bool on_surface = gl > 0.0 && pt_finite(f) && pt_finite(gl) && abs(f - u_iso) <= u_max_offset * gl;
    q.p = vec4(p, on_surface ? q.p.w : PT_DEAD);
    pt_src[i] = q;
}
