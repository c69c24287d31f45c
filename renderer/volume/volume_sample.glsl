// volume_sample.glsl — the data value at a voxel coordinate (volume/sl_volume.h: voxel
// (i,j,k) is texel (i,j,k); value = texel * u_value_map.x + u_value_map.y). Linear:
// the texture unit's trilinear filter (clamped to the edge voxels); nearest: the
// voxel at floor(p + 0.5). NaN voxels stay NaN (callers treat NaN as transparent).
uniform sampler3D u_volume;
uniform vec3 u_dims;            // voxels per axis
uniform vec2 u_value_map;       // scale, offset
uniform int u_nearest;

// NaN by its bits: a compiler may fold isnan(x) (x != x) away.
bool sl_is_nan(float x)
{
    return (floatBitsToUint(x) & 0x7fffffffu) > 0x7f800000u;
}

float sl_volume_value(vec3 p)
{
    float t;
    if (u_nearest != 0)
        t = texelFetch(u_volume, clamp(ivec3(floor(p + 0.5)), ivec3(0), ivec3(u_dims) - 1), 0).r;
    else
        t = texture(u_volume, (p + 0.5) / u_dims).r;
    return t * u_value_map.x + u_value_map.y;
}

// Gradient in voxel units by central differences (one voxel either side).
vec3 sl_volume_gradient(vec3 p)
{
    return 0.5 * vec3(sl_volume_value(p + vec3(1, 0, 0)) - sl_volume_value(p - vec3(1, 0, 0)),
                      sl_volume_value(p + vec3(0, 1, 0)) - sl_volume_value(p - vec3(0, 1, 0)),
                      sl_volume_value(p + vec3(0, 0, 1)) - sl_volume_value(p - vec3(0, 0, 1)));
}
