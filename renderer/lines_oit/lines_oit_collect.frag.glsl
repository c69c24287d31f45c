// lines_oit_collect.frag.glsl — stores every front-facing tube fragment in a
// per-pixel linked list (Yang et al. 2010; the baseline of Kanzler et al.,
// Sec. 5.3): node = RGBA8 colour with the line's opacity in alpha, eye distance along
// F, next index. A fragment that finds the node pool full is dropped and its
// pixel flagged (head's top bit), so the resolve pass can mark it (Fig. 17).
// Only the front half of each tube (normal towards the eye) is stored, so
// every tube crossing a pixel contributes exactly one fragment, like the
// ray caster's one entry point per tube.
#include "gpu/glsl/camera.glsl"
#include "gpu/glsl/lighting.glsl"
#include "gpu/glsl/colormap.glsl"

layout(early_fragment_tests) in;

in vec3 v_position;
in vec3 v_normal;
in float v_scalar;

layout(r32ui, binding = 0) uniform coherent uimage2D u_heads;
layout(binding = 0, offset = 0) uniform atomic_uint u_node_counter;
struct sl_oit_node { uint color; float depth; uint next; };
layout(std430, binding = 2) buffer sl_oit_nodes { sl_oit_node oit_nodes[]; };

uniform uint u_capacity;
#include "gpu/glsl/line_style.glsl"
uniform float u_opacity;
uniform int u_opacity_ramp;

void main()
{
    vec3 v = normalize(sl_eye.xyz - v_position);
    vec3 n = normalize(v_normal);
    if (dot(n, v) < 0.0)
        discard; // back half of the tube
    vec3 base = u_use_colormap != 0 ? sl_colormap(u_colormap, v_scalar, u_scalar_range) : u_color;
    vec3 l = normalize(u_light_eye.x * sl_right.xyz + u_light_eye.y * sl_up.xyz - u_light_eye.z * sl_forward.xyz);
    sl_material m = sl_material(u_material.x, u_material.y, u_material.z, u_material.w);
    vec3 c = clamp(sl_shade(base, n, l, v, m), 0.0, 1.0);
    uint index = atomicCounterIncrement(u_node_counter);
    ivec2 px = ivec2(gl_FragCoord.xy);
    if (index >= u_capacity) {
        imageAtomicOr(u_heads, px, 0x80000000u);
        return;
    }
    float span = u_scalar_range.y - u_scalar_range.x;
    float t = span != 0.0 ? clamp((v_scalar - u_scalar_range.x) / span, 0.0, 1.0) : 0.5; // as sl_colormap
    oit_nodes[index].color = packUnorm4x8(vec4(c, u_opacity_ramp != 0 ? u_opacity * t : u_opacity));
    oit_nodes[index].depth = dot(v_position - sl_eye.xyz, sl_forward.xyz);
    uint prev = imageAtomicExchange(u_heads, px, index);
    // Keep the overflow flag if another fragment set it meanwhile.
    if ((prev & 0x80000000u) != 0u) {
        imageAtomicOr(u_heads, px, 0x80000000u);
        prev &= 0x7fffffffu;
    }
    oit_nodes[index].next = prev;
}
