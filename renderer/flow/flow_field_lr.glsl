// flow_field_lr.glsl — an LR-spline vector field (dim 3) for the integrator:
// the element from lr_find_element (lrspline/lr_find.glsl: the look-up and
// the Bézier blocks of sl_lr_bezier.h, bindings 6..12), its block evaluated
// by de Casteljau. field() in float (lr_value_jacobian); field_m() (mixed):
// the element-local coordinates u = (p - lo) / (hi - lo) from the double
// point and the double box (LR_DOUBLE 1), the block evaluated in float at u,
// so the float rounding is of u, not of the world position; field_d():
// the double Bézier path (lr_value_jacobian_d). The look-up is in float;
// for mixed / double the element is then checked against the double box
// under the element rule (half-open, closed at the domain's upper face) and
// the float point nudged by an ulp towards p once if it missed, so the
// double path uses the CPU's element. flow_local_size(): the heuristic
// size of flow_field.c, min element side / 2^degree (degree = the largest,
// at least 1). Callers test the domain first; outside, field() is NaN.
// Defaults for a build without sl_lr_bezier_defines (shaders-check): vector
// blocks, and the double buffers whenever the precision needs them.
#ifndef LR_DIM
#define LR_DIM 3
#endif
#if SL_PREC != 0
#ifndef LR_DOUBLE
#define LR_DOUBLE 1
#endif
#endif
#include "lrspline/lr_find.glsl"
#if LR_DIM != 3
#error "streamlines need an LR-spline volume of dim 3"
#endif
#if SL_PREC != 0 && !LR_DOUBLE
#error "mixed and double LR fields need LR_DOUBLE 1 (the double boxes)"
#endif

const int FLOW_LR_DEGREE = max(max(max(LR_O0, LR_O1), LR_O2) - 1, 1);

float flow_nan()
{
    return uintBitsToFloat(0x7fc00000u);
}

// The look-up at a point the integrator found inside its domain box (finite):
// clamped to the look-up's float box, which lies inside the double domain
// (float_up / float_down of its bounds, lr_lookup_gpu.c), so a point on a
// face that is not a float (x = 0.9, or a rounded u_lo) still finds its
// element rather than -1.
int flow_lr_find(vec3 q)
{
    return lr_find_element(clamp(q, lr_lookup_lo, lr_lookup_hi));
}

vec3 field(vec3 p)
{
    int e = flow_lr_find(p);
    if (e < 0)
        return vec3(flow_nan());
    mat3 J;
    return lr_value_jacobian(e, p, J);
}

#if SL_PREC != 0
// The element rule of sl_lr.h in double on axis a: -1 below the box, 1 at or
// above its upper side (unless that side is the domain's upper face), else 0.
int flow_lr_side(int e, dvec3 p, int a)
{
    double lo = lr_box_data_d[e].lo[a], hi = lr_box_data_d[e].hi[a];
    if (p[a] < lo)
        return -1;
    if (p[a] >= hi && !(p[a] == hi && hi == double(u_lr_domain_hi[a])))
        return 1;
    return 0;
}

// One ulp of the float x towards direction s (+1 / -1).
float flow_ulp_step(float x, int s)
{
    if (x == 0.0)
        return s > 0 ? uintBitsToFloat(1u) : -uintBitsToFloat(1u);
    uint b = floatBitsToUint(x);
    return uintBitsToFloat((x > 0.0) == (s > 0) ? b + 1u : b - 1u);
}

// The element of the double point p: the float look-up, checked in double.
int flow_lr_element_d(dvec3 p)
{
    vec3 q = vec3(p);
    int e = flow_lr_find(q);
    if (e < 0)
        return -1;
    bool moved = false;
    for (int a = 0; a < 3; a++) {
        int s = flow_lr_side(e, p, a);
        if (s != 0) {
            q[a] = flow_ulp_step(q[a], s);
            moved = true;
        }
    }
    if (moved) {
        int e2 = flow_lr_find(q);
        if (e2 >= 0)
            e = e2;
    }
    return e;
}

// The block of element e at local coordinates u (float de Casteljau).
vec3 flow_lr_block(int e, vec3 u)
{
    int base = e * LR_STRIDE;
    vec3 vz[LR_O2], dz[LR_O2];
    for (int k = 0; k < LR_O2; k++) {
        vec3 vy[LR_O1], dy[LR_O1];
        for (int j = 0; j < LR_O1; j++) {
            vec3 w[LR_O0];
            for (int i = 0; i < LR_O0; i++)
                w[i] = LR_FETCH(base + ((k * LR_O1 + j) * LR_O0 + i) * LR_DIM);
            lr_dc0(w, u.x, vy[j], dy[j]);
        }
        lr_dc1(vy, u.y, vz[k], dz[k]);
    }
    vec3 value, d;
    lr_dc2(vz, u.z, value, d);
    return value;
}

vec3 field_m(dvec3 p)
{
    int e = flow_lr_element_d(p);
    if (e < 0)
        return vec3(flow_nan());
    dvec3 lo = lr_box_data_d[e].lo.xyz, hi = lr_box_data_d[e].hi.xyz;
    return flow_lr_block(e, vec3((p - lo) / (hi - lo)));
}
#endif

#if SL_PREC == 2
dvec3 field_d(dvec3 p)
{
    int e = flow_lr_element_d(p);
    if (e < 0)
        return dvec3(double(flow_nan()));
    dmat3 J;
    return lr_value_jacobian_d(e, p, J);
}
#endif

// The heuristic local size at p (0 outside the domain); u_step holds H.
REAL flow_local_size(VEC3 p)
{
#if SL_PREC == 0
    int e = flow_lr_find(p);
    if (e < 0)
        return REAL(0);
    vec3 s = lr_box_data[e].hi.xyz - lr_box_data[e].lo.xyz;
#else
    int e = flow_lr_element_d(p);
    if (e < 0)
        return REAL(0);
    dvec3 s = lr_box_data_d[e].hi.xyz - lr_box_data_d[e].lo.xyz;
#endif
    return min(min(s.x, s.y), s.z) / REAL(1 << FLOW_LR_DEGREE);
}
