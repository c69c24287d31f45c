// volume_tf.glsl — the baked transfer function (volume/sl_volume.h, volume_tf.c) and the
// opacity correction. Texel k holds the function at lo + k (hi - lo) / (N - 1); a value
// is interpolated linearly between its two texels (exact arithmetic, not the filter
// unit), constant beyond the ends. u_tf_map = (lo, (N - 1) / (hi - lo)).
uniform sampler1D u_tf;
uniform vec2 u_tf_map;
const int SL_TF_TEXELS = 4096;

vec4 sl_volume_tf(float v)
{
    float u = clamp((v - u_tf_map.x) * u_tf_map.y, 0.0, float(SL_TF_TEXELS - 1));
    int i = min(int(u), SL_TF_TEXELS - 2);
    return mix(texelFetch(u_tf, i, 0), texelFetch(u_tf, i + 1, 0), u - float(i));
}

// alpha' = 1 - (1 - alpha)^(step / step_ref): the opacity of a segment `k` reference
// steps long, for a transfer function defined per reference step.
float sl_volume_opacity_correct(float alpha, float k)
{
    return alpha >= 1.0 ? 1.0 : 1.0 - pow(1.0 - alpha, k);
}
