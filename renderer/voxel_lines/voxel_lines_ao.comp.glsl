// voxel_lines_ao.comp.glsl — per-voxel spherical ambient occlusion from the
// line density (Kanzler et al., Sec. 4.1.3, Fig. 14c/d): from each AO cell
// centre, u_rays directions (a Fibonacci sphere) are marched in steps of one
// finest voxel up to u_radius voxels; each ray accumulates optical depth
// (density x u_extinction) and is blocked at 1, as in the paper; the cell's
// occlusion is the mean over rays. The AO grid may be coarser than the line
// grid (u_ao_dims), sampled trilinearly at render time.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(r8, binding = 0) uniform writeonly image3D u_out;
uniform sampler3D u_density;
uniform ivec3 u_ao_dims;
uniform int u_rays;
uniform float u_radius;
uniform float u_extinction;

void main()
{
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(id, u_ao_dims)))
        return;
    vec3 dims = vec3(textureSize(u_density, 0));
    vec3 p = (vec3(id) + 0.5) / vec3(u_ao_dims) * dims; // finest-grid coordinates
    float occlusion = 0.0;
    const float golden = 2.39996323;
    for (int r = 0; r < u_rays; r++) {
        float z = 1.0 - (2.0 * float(r) + 1.0) / float(u_rays);
        float rad = sqrt(max(0.0, 1.0 - z * z));
        float phi = golden * float(r);
        vec3 dir = vec3(rad * cos(phi), rad * sin(phi), z);
        float tau = 0.0;
        for (float s = 1.0; s <= u_radius && tau < 1.0; s += 1.0) {
            vec3 q = p + dir * s;
            if (any(lessThan(q, vec3(0.0))) || any(greaterThan(q, dims)))
                break;
            tau += textureLod(u_density, q / dims, 0.0).r * u_extinction;
        }
        occlusion += min(tau, 1.0);
    }
    imageStore(u_out, id, vec4(occlusion / float(u_rays)));
}
