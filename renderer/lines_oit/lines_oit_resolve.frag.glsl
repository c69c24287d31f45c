// lines_oit_resolve.frag.glsl — sorts each pixel's fragment list by depth and
// blends front to back (premultiplied output for ONE, ONE_MINUS_SRC_ALPHA over
// the cleared background). A pixel whose list lost fragments to the full node
// pool is drawn white; one with more than MAX_SORT fragments is drawn red
// (Kanzler et al., Fig. 17). Writes the reversed-Z depth of the nearest
// fragment.
#include "gpu/glsl/camera.glsl"

#define MAX_SORT 512
#define NIL 0x7fffffffu

layout(r32ui, binding = 0) uniform readonly uimage2D u_heads;
struct sl_oit_node { uint color; float depth; uint next; };
layout(std430, binding = 2) readonly buffer sl_oit_nodes { sl_oit_node oit_nodes[]; };
uniform float u_alpha_stop;

layout(location = 0) out vec4 o_color;

uint idx[MAX_SORT];
float dep[MAX_SORT];

void main()
{
    uint head = imageLoad(u_heads, ivec2(gl_FragCoord.xy)).r;
    bool lost = (head & 0x80000000u) != 0u;
    uint i = head & 0x7fffffffu;
    int count = 0;
    bool too_many = false;
    while (i != NIL) {
        if (count == MAX_SORT) {
            too_many = true;
            break;
        }
        float d = oit_nodes[i].depth;
        int j = count++;
        while (j > 0 && dep[j - 1] > d) {
            dep[j] = dep[j - 1];
            idx[j] = idx[j - 1];
            j--;
        }
        dep[j] = d;
        idx[j] = i;
        i = oit_nodes[i].next;
    }
    if (lost || too_many) {
        o_color = lost ? vec4(1.0) : vec4(1.0, 0.0, 0.0, 1.0);
        gl_FragDepth = count > 0 ? sl_near.x / max(dep[0], 1e-30) : 1.0;
        return;
    }
    if (count == 0)
        discard;
    vec3 acc = vec3(0.0);
    float alpha = 0.0;
    for (int k = 0; k < count && alpha < u_alpha_stop; k++) {
        vec4 c = unpackUnorm4x8(oit_nodes[idx[k]].color);
        acc += (1.0 - alpha) * c.a * c.rgb;
        alpha += (1.0 - alpha) * c.a;
    }
    gl_FragDepth = sl_near.x / max(dep[0], 1e-30);
    o_color = vec4(acc, alpha);
}
