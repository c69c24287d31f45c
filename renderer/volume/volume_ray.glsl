// volume_ray.glsl — a ray against an axis-aligned box (volume or brick, voxel coordinates).
// Returns (t_enter, t_exit) along ro + t rd; t_enter >= t_exit means a miss. A zero
// direction component is replaced by a tiny one of the same sign, so a ray parallel
// to a face gives +-huge slab distances instead of 0 * inf = NaN.
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
