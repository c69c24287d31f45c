// flow_real.glsl — the number types of one precision variant (flow_gpu.h):
// SL_PREC 0 single: REAL float, positions and field in float;
// 1 mixed: REAL double for positions, time and the RK update, the field in
// float at local coordinates found in double (field_m);
// 2 double: everything in double (field_d). The field file included after
// this one defines field(vec3), for SL_PREC 1 field_m(dvec3) (float
// evaluation, local coordinates from the double point) and for 2 field_d(dvec3). Doubles
// are core in GLSL 4.50 (GL_ARB_gpu_shader_fp64); the C side checks the GL.
#if SL_PREC == 0
#define REAL float
#define VEC3 vec3
#else
#define REAL double
#define VEC3 dvec3
#endif

// Finite by bits (Mesa may fold isnan/isinf away).
bool flow_finite(float x)
{
    return (floatBitsToUint(x) & 0x7fffffffu) < 0x7f800000u;
}
#if SL_PREC != 0
bool flow_finite(double x)
{
    return (unpackDouble2x32(x).y & 0x7fffffffu) < 0x7ff00000u;
}
#endif
bool flow_finite3(VEC3 v)
{
    return flow_finite(v.x) && flow_finite(v.y) && flow_finite(v.z);
}
