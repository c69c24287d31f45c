// voxel_lines_light.glsl — soft shadows and ambient occlusion from the line
// density LoD (Kanzler et al., Sec. 3.4, 4.1.2, 4.1.3). u_density holds per
// voxel the summed length of its lines (in voxels) with a mip chain of 2^3
// averages (the paper's density octree); times u_extinction (opacity x tube
// diameter in voxels: the share of a voxel's cross-section the lines cover)
// it is an optical depth per voxel. Shadows: one ray towards the light
// sampling ever coarser levels with distance (a cone that subtends about one
// finest voxel per unit distance, starting at level u_shadow_lod). AO:
// precomputed per voxel (voxel_lines_ao.comp.glsl), trilinear one voxel out
// from the hit along the normal (so a tube does not occlude itself).
// Hard shadows (shadow_mode = lines): the shadow ray is tested against the
// one representative line per cell of a coarse level (density_lod.c).
// Both are skipped entirely when off.
layout(std430, binding = 4) readonly buffer sl_voxel_reps { float vx_reps[]; }; // 6 floats per cell
uniform int u_shadow_lines;   // 1: hard shadows from representative lines (Fig. 12c)
uniform ivec3 u_rep_dims;     // cells of the chosen representative level
uniform int u_rep_base;       // its first float in vx_reps
uniform float u_rep_scale;    // finest voxels per cell (2^level)
uniform sampler3D u_density;
uniform sampler3D u_ao;
uniform float u_extinction;
uniform int u_shadows;
uniform float u_shadow_strength;
uniform float u_shadow_lod;
uniform float u_max_lod;
uniform int u_ao_on;
uniform float u_ao_strength;

float vx_shadow(vec3 p, vec3 l)
{
    vec3 inv_dims = 1.0 / vec3(textureSize(u_density, 0));
    float tau = 0.0;
    float s = 1.0; // start one voxel away from the surface (its own lines)
    for (int i = 0; i < 128 && tau < 6.0; i++) {
        vec3 q = p + l * s;
        if (any(lessThan(q, vec3(0.0))) || any(greaterThan(q * inv_dims, vec3(1.0))))
            break;
        float lod = clamp(u_shadow_lod + log2(max(s, 1.0)) - 1.0, u_shadow_lod, u_max_lod);
        float step_len = exp2(lod);
        tau += textureLod(u_density, q * inv_dims, lod).r * u_extinction * step_len;
        s += step_len;
    }
    return exp(-tau);
}

bool capsule(vec3 o, vec3 d, vec3 a, vec3 b, float r, out float t_in, out float t_out, out vec3 n);

// Hard shadow test against the representative lines of a coarse level: a DDA
// through that level's cells towards the light; each cell's one line is a
// tube of the user radius in that level's units (2^level times thicker).
float vx_shadow_lines(vec3 p, vec3 l)
{
    vec3 o = (p + 1.5 * l) / u_rep_scale; // leave the hit's own neighbourhood
    ivec3 cell = ivec3(floor(o));
    if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, u_rep_dims)))
        return 1.0;
    vec3 inv = 1.0 / l;
    ivec3 step_dir = ivec3(sign(l));
    vec3 t_max = mix((vec3(cell) + max(vec3(step_dir), vec3(0.0)) - o) * inv, vec3(1e30), equal(step_dir, ivec3(0)));
    vec3 t_delta = mix(abs(inv), vec3(1e30), equal(step_dir, ivec3(0)));
    float r = min(u_radius_g, 0.5);
    for (int it = 0; it < u_rep_dims.x + u_rep_dims.y + u_rep_dims.z; it++) {
        int base = u_rep_base + 6 * (cell.x + u_rep_dims.x * (cell.y + u_rep_dims.y * cell.z));
        float ax = vx_reps[base];
        if (!isnan(ax)) {
            vec3 a = vec3(cell) + vec3(ax, vx_reps[base + 1], vx_reps[base + 2]);
            vec3 b = vec3(cell) + vec3(vx_reps[base + 3], vx_reps[base + 4], vx_reps[base + 5]);
            float tin, tout;
            vec3 n;
            if (capsule(o, l, a, b, r, tin, tout, n) && tout > 0.0)
                return 0.0;
        }
        if (t_max.x <= t_max.y && t_max.x <= t_max.z) {
            cell.x += step_dir.x;
            t_max.x += t_delta.x;
        } else if (t_max.y <= t_max.z) {
            cell.y += step_dir.y;
            t_max.y += t_delta.y;
        } else {
            cell.z += step_dir.z;
            t_max.z += t_delta.z;
        }
        if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, u_rep_dims)))
            break;
    }
    return 1.0;
}

float vx_light_factor(vec3 p, vec3 n, vec3 l)
{
    float f = 1.0;
    if (u_shadows != 0)
        f *= mix(1.0, u_shadow_lines != 0 ? vx_shadow_lines(p, l) : vx_shadow(p, l), u_shadow_strength);
    if (u_ao_on != 0)
        f *= 1.0 - u_ao_strength * texture(u_ao, (p + n) / vec3(textureSize(u_density, 0))).r; // 1 voxel out
    return f;
}
