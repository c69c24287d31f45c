// particles_bins.glsl — the bin grid of the neighbour search: cube bins of
// side u_bin_size (>= the repulsion radius, so the 27 bins around a
// particle's bin hold every particle within that radius): the part of the
// grid over the volume box (from the local-world origin) that starts at bin
// u_bin_origin, u_bin_dims per axis, u_bins in all (the dead key). Clamping
// into the edge bins is 1-Lipschitz, so the search stays exact for
// positions outside that part too.
uniform float u_bin_size;
uniform ivec3 u_bin_origin;
uniform ivec3 u_bin_dims;
uniform uint u_bins;

ivec3 pt_bin_of(vec3 x)
{
    return clamp(ivec3(floor(x / u_bin_size)) - u_bin_origin, ivec3(0), u_bin_dims - 1);
}

uint pt_bin_index(ivec3 b)
{
    return (uint(b.z) * uint(u_bin_dims.y) + uint(b.y)) * uint(u_bin_dims.x) + uint(b.x);
}
