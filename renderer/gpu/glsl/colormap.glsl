// colormap.glsl — sample a 256-texel colormap texture (core/sl_colormap.h) with a scalar range.
// range.x maps to the map's start and range.y to its end, so x > y inverts the map;
// an empty range (x == y) gives the middle colour.
vec3 sl_colormap(sampler2D map, float value, vec2 range)
{
    float span = range.y - range.x;
    float t = span != 0.0 ? clamp((value - range.x) / span, 0.0, 1.0) : 0.5;
    if (isnan(t)) t = 0.0;
    return texture(map, vec2((t * 255.0 + 0.5) / 256.0, 0.5)).rgb;
}
