// particles_field.glsl — the scalar field the particle system lives on and the
// derivatives it draws with (renderer/particles/README.md "The model").
//
// Voxel coordinates u: voxel (i,j,k) sits at u = (i,j,k) (sl_volume.h). Values
// are data values: texel * u_value_map.x + u_value_map.y, fetched with
// texelFetch (exact, no filter-weight rounding), clamped to the edge voxels
// like the texture. Derivatives are per voxel unit; callers convert to world
// with the spacing (pt_world_gradient, pt_world_hessian).
//   pt_trilinear: the trilinear field (8 fetches) and its analytic gradient —
//                 the surface particles are placed on and kept on;
//   pt_bspline:   the uniform cubic B-spline (approximating) field, gradient
//                 and Hessian from the same 64 fetches — normals and curvature;
//   pt_curvature: principal curvatures and the first direction from a world
//                 gradient and Hessian (Kindlmann et al. 2003): n = -g/|g|,
//                 kappa1 >= kappa2, a bright ball of radius R gives +1/R.
// NaN voxels make the result NaN; callers test with pt_finite.
// Included by every particles compute pass and by the probe test.
uniform sampler3D u_volume;
uniform ivec3 u_voxel_dims;          // voxels per axis
uniform vec2 u_value_map;      // scale, offset
uniform vec3 u_spacing;        // world units per voxel, per axis

float pt_fetch(ivec3 i)
{
    return texelFetch(u_volume, clamp(i, ivec3(0), u_voxel_dims - 1), 0).r * u_value_map.x + u_value_map.y;
}

bool pt_finite(float x)
{
    return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u;
}

bool pt_finite3(vec3 v)
{
    return pt_finite(v.x) && pt_finite(v.y) && pt_finite(v.z);
}

// Trilinear value and gradient (per voxel unit) at u; u is clamped to the
// voxel centres' box first, so the field is constant beyond the edge voxels.
float pt_trilinear(vec3 u, out vec3 grad)
{
    vec3 c = clamp(u, vec3(0.0), vec3(u_voxel_dims - 1));
    ivec3 i0 = min(ivec3(floor(c)), max(u_voxel_dims - 2, ivec3(0)));
    vec3 t = c - vec3(i0);
    // An axis with one voxel: i0 = 0, t = 0, both taps the same voxel.
    float v000 = pt_fetch(i0);
    float v100 = pt_fetch(i0 + ivec3(1, 0, 0));
    float v010 = pt_fetch(i0 + ivec3(0, 1, 0));
    float v110 = pt_fetch(i0 + ivec3(1, 1, 0));
    float v001 = pt_fetch(i0 + ivec3(0, 0, 1));
    float v101 = pt_fetch(i0 + ivec3(1, 0, 1));
    float v011 = pt_fetch(i0 + ivec3(0, 1, 1));
    float v111 = pt_fetch(i0 + ivec3(1, 1, 1));
    float x00 = mix(v000, v100, t.x), x10 = mix(v010, v110, t.x);
    float x01 = mix(v001, v101, t.x), x11 = mix(v011, v111, t.x);
    float y0 = mix(x00, x10, t.y), y1 = mix(x01, x11, t.y);
    float dx0 = mix(v100 - v000, v110 - v010, t.y), dx1 = mix(v101 - v001, v111 - v011, t.y);
    grad = vec3(mix(dx0, dx1, t.z), mix(x10 - x00, x11 - x01, t.z), y1 - y0);
    // Beyond the box along an axis (clamped) the field does not change there.
    grad *= vec3(greaterThanEqual(u, vec3(0.0))) * vec3(lessThanEqual(u, vec3(u_voxel_dims - 1)));
    grad *= vec3(greaterThan(u_voxel_dims, ivec3(1)));
    return mix(y0, y1, t.z);
}

// Cubic B-spline weights of the taps floor(u)-1 .. floor(u)+2 at fraction t:
// orders 0, 1 and 2 (value, first and second derivative).
void pt_bspline_weights(float t, out vec4 w, out vec4 d, out vec4 dd)
{
    float s = 1.0 - t, t2 = t * t, t3 = t2 * t;
    w = vec4(s * s * s, 3.0 * t3 - 6.0 * t2 + 4.0, -3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0, t3) / 6.0;
    d = vec4(-0.5 * s * s, 1.5 * t2 - 2.0 * t, -1.5 * t2 + t + 0.5, 0.5 * t2);
    dd = vec4(s, 3.0 * t - 2.0, -3.0 * t + 1.0, t);
}

// B-spline value, gradient and Hessian (per voxel unit) at u, summed
// separably: x first over 16 rows, then y, then z.
float pt_bspline(vec3 u, out vec3 grad, out mat3 hess)
{
    vec3 c = clamp(u, vec3(0.0), vec3(u_voxel_dims - 1));
    ivec3 base = ivec3(floor(c));
    vec3 t = c - vec3(base);
    vec4 wx, dx, ddx, wy, dy, ddy, wz, dz, ddz;
    pt_bspline_weights(t.x, wx, dx, ddx);
    pt_bspline_weights(t.y, wy, dy, ddy);
    pt_bspline_weights(t.z, wz, dz, ddz);
    // Per (y,z) row: value, d/dx, d2/dx2 of the x sum.
    float f = 0.0, fx = 0.0, fy = 0.0, fz = 0.0;
    float fxx = 0.0, fyy = 0.0, fzz = 0.0, fxy = 0.0, fxz = 0.0, fyz = 0.0;
    for (int k = 0; k < 4; k++) {
        float ry = 0.0, ryx = 0.0, ryxx = 0.0, ryy = 0.0, ryyy = 0.0, ryxy = 0.0;
        for (int j = 0; j < 4; j++) {
            float r = 0.0, rx = 0.0, rxx = 0.0;
            for (int i = 0; i < 4; i++) {
                float v = pt_fetch(base + ivec3(i - 1, j - 1, k - 1));
                r += wx[i] * v;
                rx += dx[i] * v;
                rxx += ddx[i] * v;
            }
            ry += wy[j] * r;
            ryx += wy[j] * rx;
            ryxx += wy[j] * rxx;
            ryy += dy[j] * r;
            ryyy += ddy[j] * r;
            ryxy += dy[j] * rx;
        }
        f += wz[k] * ry;
        fx += wz[k] * ryx;
        fy += wz[k] * ryy;
        fz += dz[k] * ry;
        fxx += wz[k] * ryxx;
        fyy += wz[k] * ryyy;
        fzz += ddz[k] * ry;
        fxy += wz[k] * ryxy;
        fxz += dz[k] * ryx;
        fyz += dz[k] * ryy;
    }
    grad = vec3(fx, fy, fz);
    hess = mat3(fxx, fxy, fxz, fxy, fyy, fyz, fxz, fyz, fzz);
    // An axis with one voxel has no derivative along it.
    vec3 has = vec3(greaterThan(u_voxel_dims, ivec3(1)));
    grad *= has;
    hess = mat3(hess[0] * has * has.x, hess[1] * has * has.y, hess[2] * has * has.z);
    return f;
}

vec3 pt_world_gradient(vec3 grad_u)
{
    return grad_u / u_spacing;
}

mat3 pt_world_hessian(mat3 hess_u)
{
    vec3 inv = 1.0 / u_spacing;
    return mat3(hess_u[0] * inv * inv.x, hess_u[1] * inv * inv.y, hess_u[2] * inv * inv.z);
}

// An orthonormal basis (t1, t2) of the plane orthogonal to unit n (Duff et
// al. 2017's branchless construction).
void pt_tangent_basis(vec3 n, out vec3 t1, out vec3 t2)
{
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    t1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    t2 = vec3(b, s + n.y * n.y * a, -n.y);
}

// Principal curvatures k1 >= k2 and the direction e1 of k1 from a world
// gradient g (|g| > 0) and Hessian H; n = -g/|g| is returned too. The shape
// operator G = -P H P / |g| is restricted to the tangent plane and its 2x2
// eigen-pair taken in closed form.
void pt_curvature(vec3 g, mat3 H, out vec3 n, out float k1, out float k2, out vec3 e1)
{
    float gl = length(g);
    n = -g / gl;
    vec3 t1, t2;
    pt_tangent_basis(n, t1, t2);
    vec3 Ht1 = H * t1, Ht2 = H * t2;
    float m11 = -dot(t1, Ht1) / gl, m12 = -dot(t1, Ht2) / gl, m22 = -dot(t2, Ht2) / gl;
    float mean = 0.5 * (m11 + m22), half_diff = 0.5 * (m11 - m22);
    float r = sqrt(half_diff * half_diff + m12 * m12);
    k1 = mean + r;
    k2 = mean - r;
    float theta = 0.5 * atan(2.0 * m12, m11 - m22);
    e1 = cos(theta) * t1 + sin(theta) * t2;
}

// Koenderink's shape index with kappa1 >= kappa2, in [-1, 1] (a convex
// sphere -1, a cup +1, a ridge -1/2, a valley +1/2, a symmetric saddle 0);
// 0 for a flat point.
float pt_shape_index(float k1, float k2)
{
    if (abs(k1) + abs(k2) == 0.0)
        return 0.0;
    if (k1 == k2)
        return -sign(k1);
    return 0.63661977 * atan((k2 + k1) / (k2 - k1));
}

// The paper's reliability of the principal directions (sec. 4.2.3): 0 at
// flat points (both |kappa| < eps), umbilics and symmetric saddles, 1 on
// cylinder-like points.
float pt_reliability(float k1, float k2, float eps)
{
    if (abs(k1) < eps && abs(k2) < eps)
        return 0.0;
    return 1.0 - abs(2.0 * (abs(pt_shape_index(k1, k2)) - 0.5));
}
