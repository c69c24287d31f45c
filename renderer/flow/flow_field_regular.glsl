// flow_field_regular.glsl — a regular vector field for the integrator:
// texel (i,j,k) of u_field (RGBA32F, exact voxel values) = voxel (i,j,k) at
// origin + (i,j,k) spacing. The trilinear interpolation of flow_field.c,
// same operations in the same order (q = (p - origin) / spacing, i =
// clamp(floor(q), 0, dims - 2), lerp x, then y, then z; one-voxel axes
// constant), by texelFetch rather than the filter unit so the weights are
// full precision. field() in float; field_m() (mixed) the cell and local
// weights in double, the lerps in float; field_d() in double (the texel
// values are floats, converted exactly). Callers test the domain first.
// flow_local_size() is 1: the local size is a constant here, and u_step
// holds H times it for the heuristic mode (times 1 is exact).
uniform sampler3D u_field;
uniform ivec3 u_dims;
uniform vec3 u_origin_f, u_spacing_f;
#if SL_PREC != 0
uniform dvec3 u_origin_d, u_spacing_d;
#endif

// The float trilinear on cell i0..i1 at local weights w.
vec3 field_cell(ivec3 i0, ivec3 i1, vec3 w)
{
    vec3 c00 = texelFetch(u_field, ivec3(i0.x, i0.y, i0.z), 0).xyz;
    vec3 c10 = texelFetch(u_field, ivec3(i1.x, i0.y, i0.z), 0).xyz;
    vec3 c01 = texelFetch(u_field, ivec3(i0.x, i1.y, i0.z), 0).xyz;
    vec3 c11 = texelFetch(u_field, ivec3(i1.x, i1.y, i0.z), 0).xyz;
    vec3 d00 = texelFetch(u_field, ivec3(i0.x, i0.y, i1.z), 0).xyz;
    vec3 d10 = texelFetch(u_field, ivec3(i1.x, i0.y, i1.z), 0).xyz;
    vec3 d01 = texelFetch(u_field, ivec3(i0.x, i1.y, i1.z), 0).xyz;
    vec3 d11 = texelFetch(u_field, ivec3(i1.x, i1.y, i1.z), 0).xyz;
    vec3 y0 = (c00 + w.x * (c10 - c00));
    vec3 y1 = (c01 + w.x * (c11 - c01));
    vec3 z0 = y0 + w.y * (y1 - y0);
    y0 = (d00 + w.x * (d10 - d00));
    y1 = (d01 + w.x * (d11 - d01));
    vec3 z1 = y0 + w.y * (y1 - y0);
    return z0 + w.z * (z1 - z0);
}

vec3 field(vec3 p)
{
    vec3 q = (p - u_origin_f) / u_spacing_f;
    ivec3 i0 = ivec3(0), i1 = ivec3(0);
    vec3 w = vec3(0.0);
    for (int a = 0; a < 3; a++) {
        if (u_dims[a] == 1)
            continue;
        float fl = clamp(floor(q[a]), 0.0, float(u_dims[a] - 2));
        i0[a] = int(fl);
        i1[a] = i0[a] + 1;
        w[a] = q[a] - fl;
    }
    return field_cell(i0, i1, w);
}

#if SL_PREC != 0
// Mixed precision: the cell and the local weights from the double point
// (as the paper evaluates a spline in element-local coordinates), the
// interpolation in float; so the float rounding is of the local weight
// (~6e-8 of a voxel), not of the world position.
vec3 field_m(dvec3 p)
{
    dvec3 q = (p - u_origin_d) / u_spacing_d;
    ivec3 i0 = ivec3(0), i1 = ivec3(0);
    vec3 w = vec3(0.0);
    for (int a = 0; a < 3; a++) {
        if (u_dims[a] == 1)
            continue;
        double fl = clamp(floor(q[a]), 0.0lf, double(u_dims[a] - 2));
        i0[a] = int(fl);
        i1[a] = i0[a] + 1;
        w[a] = float(q[a] - fl);
    }
    return field_cell(i0, i1, w);
}
#endif

#if SL_PREC == 2
dvec3 field_d(dvec3 p)
{
    dvec3 q = (p - u_origin_d) / u_spacing_d;
    ivec3 i0 = ivec3(0), i1 = ivec3(0);
    dvec3 w = dvec3(0.0);
    for (int a = 0; a < 3; a++) {
        if (u_dims[a] == 1)
            continue;
        double fl = clamp(floor(q[a]), 0.0lf, double(u_dims[a] - 2));
        i0[a] = int(fl);
        i1[a] = i0[a] + 1;
        w[a] = q[a] - fl;
    }
    dvec3 c00 = dvec3(texelFetch(u_field, ivec3(i0.x, i0.y, i0.z), 0).xyz);
    dvec3 c10 = dvec3(texelFetch(u_field, ivec3(i1.x, i0.y, i0.z), 0).xyz);
    dvec3 c01 = dvec3(texelFetch(u_field, ivec3(i0.x, i1.y, i0.z), 0).xyz);
    dvec3 c11 = dvec3(texelFetch(u_field, ivec3(i1.x, i1.y, i0.z), 0).xyz);
    dvec3 d00 = dvec3(texelFetch(u_field, ivec3(i0.x, i0.y, i1.z), 0).xyz);
    dvec3 d10 = dvec3(texelFetch(u_field, ivec3(i1.x, i0.y, i1.z), 0).xyz);
    dvec3 d01 = dvec3(texelFetch(u_field, ivec3(i0.x, i1.y, i1.z), 0).xyz);
    dvec3 d11 = dvec3(texelFetch(u_field, ivec3(i1.x, i1.y, i1.z), 0).xyz);
    dvec3 y0 = (c00 + w.x * (c10 - c00));
    dvec3 y1 = (c01 + w.x * (c11 - c01));
    dvec3 z0 = y0 + w.y * (y1 - y0);
    y0 = (d00 + w.x * (d10 - d00));
    y1 = (d01 + w.x * (d11 - d01));
    dvec3 z1 = y0 + w.y * (y1 - y0);
    return z0 + w.z * (z1 - z0);
}
#endif

REAL flow_local_size(VEC3 p)
{
    return REAL(1);
}
