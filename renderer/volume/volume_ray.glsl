// volume_ray.glsl — a ray against an axis-aligned box (volume or brick, voxel coordinates).
// Returns (t_enter, t_exit) along ro + t rd; t_enter >= t_exit means a miss. A zero
// direction component is replaced by a tiny one of the same sign, so a ray parallel
// to a face gives +-huge slab distances instead of 0 * inf = NaN. And the per-pixel
// offset of a ray's samples against wood-grain (sl_volume_jitter), shared by the marchers.
vec3 sl_volume_safe_inverse(vec3 rd)
{
    vec3 s = mix(vec3(1e-30), rd, greaterThan(abs(rd), vec3(1e-30)));
    return 1.0 / s;
}

vec2 sl_volume_ray_box(vec3 ro, vec3 inv_rd, vec3 lo, vec3 hi)
{
    vec3 ta = (lo - ro) * inv_rd, tb = (hi - ro) * inv_rd;
    vec3 tmin = min(ta, tb), tmax = max(ta, tb);
    return vec2(max(max(tmin.x, tmin.y), tmin.z), min(min(tmax.x, tmax.y), tmax.z));
}

// The offset in [0, 1) of a pixel's samples within their step: interleaved gradient noise
// (Jimenez 2014) of the pixel centre, a fixed function of the pixel, so a frame repeats
// exactly (the `still` quality's promise) while neighbouring pixels sample at other depths.
float sl_volume_jitter(vec2 pixel)
{
    return fract(52.9829189 * fract(dot(pixel, vec2(0.06711056, 0.00583715))));
}
