// particles_visible.glsl — the hidden-surface test of one particle (the
// paper's Algorithm 3, pass 2) as the splats and the contours use it: the
// particle is visible when the id target (particles_hsr.h) holds its id
// (index + 1) at the pixel that contains its projection `clip`.
// Include after gpu/glsl/camera.glsl.
bool pt_hsr_visible(usampler2D ids, vec4 clip, uint id)
{
    vec2 win = (clip.xy / clip.w * 0.5 + 0.5) * sl_viewport.xy;
    ivec2 px = ivec2(floor(win));
    if (any(lessThan(px, ivec2(0))) || any(greaterThanEqual(px, ivec2(sl_viewport.xy))))
        return false;
    return texelFetch(ids, px, 0).r == id;
}
