// flow_integrate.glsl — the streamline integrator of flow_trace.c on the GPU,
// one invocation per streamline (sl_flow.h states the rules: step modes,
// error control, boundary bisection and the Euler step to the face, stop
// reasons). Expects REAL, VEC3, flow_finite3 (flow_real.glsl) and field()
// / field_m() / field_d() / flow_local_size() before it. The tableau and the step mode are
// uniforms (so one program per precision, and shaders-check compiles it
// without defines). The step factor's root is root_n, the CPU's
// sl_flow_step_root operation for operation, so double steps are the CPU's.
// Inexact constants are written as double literals (0.9lf), so double
// variants use the same numbers as the C code.
// Output per sample: 8 REAL (t, x, y, z, vx, vy, vz, 0) at
// (line * max_samples + i) * 8; per line 4 uint (count, stop, rejected, forced).
layout(local_size_x = 64) in;

layout(std430, binding = 0) writeonly buffer flow_samples { REAL s_out[]; };
layout(std430, binding = 1) writeonly buffer flow_info { uint s_info[]; };
layout(std430, binding = 2) readonly buffer flow_seeds { REAL s_seed[]; };

uniform uint u_group_base;
uniform uint u_lines;
uniform uint u_max_samples;
uniform VEC3 u_lo, u_hi;
uniform REAL u_step, u_tol, u_h_min, u_h_max, u_t_max, u_min_speed, u_h0;

#if SL_PREC == 0
#define FIELD(p) field(p)
#elif SL_PREC == 1
#define FIELD(p) dvec3(field_m(p))
#else
#define FIELD(p) field_d(p)
#endif

// The Butcher tableau (sl_flow_methods): a row-major 6 x 6, b, and d = b - e
// (subtracted in C), zero-padded; stages, embedded order (0: fixed step)
// and step mode (0 fixed, 1 heuristic = fixed h = step * local size, a
// constant on a regular field (u_step holds the product, its
// flow_local_size is 1), per point on an LR field (flow_local_size(x) the
// element's; u_step holds H), 2 adaptive).
#define SL_MAX_STAGES 6
uniform REAL u_a[SL_MAX_STAGES * SL_MAX_STAGES];
uniform REAL u_b[SL_MAX_STAGES];
uniform REAL u_d[SL_MAX_STAGES];
uniform int u_stages, u_embedded, u_mode;

uint g_line, g_count;

void emit(REAL t, VEC3 x, VEC3 v)
{
    uint o = (g_line * u_max_samples + g_count) * 8u;
    s_out[o] = t;
    s_out[o + 1u] = x.x;
    s_out[o + 2u] = x.y;
    s_out[o + 3u] = x.z;
    s_out[o + 4u] = v.x;
    s_out[o + 5u] = v.y;
    s_out[o + 6u] = v.z;
    s_out[o + 7u] = REAL(0);
    g_count++;
}

bool inside(VEC3 p)
{
    return p.x >= u_lo.x && p.y >= u_lo.y && p.z >= u_lo.z &&
           p.x <= u_hi.x && p.y <= u_hi.y && p.z <= u_hi.z && flow_finite3(p);
}

REAL norm3(VEC3 v)
{
    return sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
}

// 0: xn (and err_norm) set; -1 a stage or the result outside; -2 non-finite field.
int rk_step(VEC3 x, VEC3 k0, REAL h, out VEC3 xn, out REAL err_norm)
{
    VEC3 k[SL_MAX_STAGES];
    k[0] = k0;
    xn = x;
    err_norm = REAL(0);
    for (int i = 1; i < u_stages; i++) {
        VEC3 s = VEC3(0);
        for (int j = 0; j < i; j++)
            s += u_a[i * SL_MAX_STAGES + j] * k[j];
        VEC3 p = x + h * s;
        if (!inside(p))
            return -1;
        k[i] = FIELD(p);
        if (!flow_finite3(k[i]))
            return -2;
    }
    VEC3 s = VEC3(0), e = VEC3(0);
    for (int i = 0; i < u_stages; i++) {
        s += u_b[i] * k[i];
        e += u_d[i] * k[i];
    }
    xn = x + h * s;
    err_norm = u_embedded != 0 ? norm3(h * e) : REAL(0);
    return inside(xn) ? 0 : -1;
}

// r^(1/n) for r in [1e-10, 1e10]: sl_flow_step_root of flow_trace.c, the
// same operations in the same order (exponent reduction by frexp, 12 Newton
// rounds on y^n = m from y = 2, ldexp back), so double gives the CPU's bits.
REAL root_n(REAL r, int n)
{
    if (n <= 1)
        return r;
    if (n == 2)
        return sqrt(r);
    int e;
    REAL m = frexp(r, e);
    int k = e >= 0 ? e / n : -((n - 1 - e) / n);
    m = ldexp(m, e - n * k);
    REAL y = REAL(2);
    for (int it = 0; it < 12; it++) {
        REAL y1 = y;
        for (int j = 2; j < n; j++)
            y1 = y1 * y;
        y = y - (y1 * y - m) / (REAL(n) * y1);
    }
    return ldexp(y, k);
}

// Time along v from x to the first face (coordinate set exactly); -1: v = 0.
REAL to_boundary(VEC3 x, VEC3 v, out VEC3 xb)
{
    REAL s = REAL(-1);
    int axis = -1;
    for (int a = 0; a < 3; a++) {
        if (v[a] == REAL(0))
            continue;
        REAL face = v[a] > REAL(0) ? u_hi[a] : u_lo[a];
        REAL sa = max((face - x[a]) / v[a], REAL(0));
        if (axis < 0 || sa < s) {
            s = sa;
            axis = a;
        }
    }
    xb = x;
    if (axis < 0)
        return REAL(-1);
    xb = clamp(x + s * v, u_lo, u_hi);
    xb[axis] = v[axis] > REAL(0) ? u_hi[axis] : u_lo[axis];
    return s;
}

// Stop codes as sl_flow_stop.
#define STOP_TIME 1
#define STOP_BOUNDARY 2
#define STOP_SAMPLES 3
#define STOP_STAGNANT 4
#define STOP_NAN 5
#define STOP_SEED_OUTSIDE 6

int trace(out uint rejected, out uint forced)
{
    rejected = 0u;
    forced = 0u;
    VEC3 x = VEC3(s_seed[3u * g_line], s_seed[3u * g_line + 1u], s_seed[3u * g_line + 2u]);
    REAL t = REAL(0);
    if (!inside(x))
        return STOP_SEED_OUTSIDE;
    VEC3 v = FIELD(x);
    if (!flow_finite3(v))
        return STOP_NAN;
    emit(t, x, v);
    REAL h_adapt = u_h0;
    // Bounded: every pass emits a sample or returns; the inner loops are bounded too.
    for (uint guard = 0u; guard <= u_max_samples; guard++) {
        if (g_count >= u_max_samples)
            return STOP_SAMPLES;
        if (norm3(v) < u_min_speed)
            return STOP_STAGNANT;
        REAL h = u_mode == 2 ? h_adapt : u_step;
        if (u_mode == 1) // the field's local size at x (regular: 1, u_step holds the product)
            h = u_step * flow_local_size(x);
        REAL remaining = u_t_max - t;
        bool last = false;
        if (h >= remaining) {
            h = remaining;
            last = true;
        }
        VEC3 xn;
        REAL e;
        bool boundary = false;
        for (int tries = 0; tries < 200; tries++) {
            int s = rk_step(x, v, h, xn, e);
            if (s == -2)
                return STOP_NAN;
            if (s == -1) {
                boundary = true;
                break;
            }
            if (u_mode != 2)
                break;
            REAL fac = e > REAL(0) ? REAL(0.9lf) * root_n(clamp(u_tol / e, REAL(1e-10lf), REAL(1e10lf)), u_embedded + 1)
                                   : REAL(5);
            fac = clamp(fac, REAL(0.2lf), REAL(5));
            REAL hn = clamp(h * fac, u_h_min, u_h_max);
            if (e <= u_tol || h <= u_h_min) {
                if (e > u_tol)
                    forced++;
                if (!last || hn < h_adapt)
                    h_adapt = hn;
                break;
            }
            rejected++;
            h = hn;
            last = false;
        }
        if (boundary) {
            REAL lo = REAL(0), hi = h;
            VEC3 xl = x;
            for (int it = 0; it < 64 && hi - lo > REAL(1e-13lf) * h; it++) {
                REAL mid = REAL(0.5) * (lo + hi), em;
                VEC3 xm;
                int s = rk_step(x, v, mid, xm, em);
                if (s == -2)
                    return STOP_NAN;
                if (s == 0) {
                    lo = mid;
                    xl = xm;
                } else {
                    hi = mid;
                }
            }
            if (lo > REAL(0)) {
                x = xl;
                t += lo;
                v = FIELD(x);
                if (!flow_finite3(v))
                    return STOP_NAN;
                if (g_count >= u_max_samples)
                    return STOP_SAMPLES;
                emit(t, x, v);
            }
            VEC3 xb;
            REAL s = to_boundary(x, v, xb);
            if (s <= REAL(0) || g_count >= u_max_samples)
                return STOP_BOUNDARY;
            int stop = STOP_BOUNDARY;
            if (t + s > u_t_max) {
                s = u_t_max - t;
                xb = x + s * v;
                if (!inside(xb))
                    return STOP_BOUNDARY;
                stop = STOP_TIME;
            }
            VEC3 vb = FIELD(xb);
            if (!flow_finite3(vb))
                return STOP_NAN;
            emit(stop == STOP_TIME ? u_t_max : t + s, xb, vb);
            return stop;
        }
        x = xn;
        t = last ? u_t_max : t + h;
        v = FIELD(x);
        if (!flow_finite3(v))
            return STOP_NAN;
        emit(t, x, v);
        if (last)
            return STOP_TIME;
    }
    return STOP_SAMPLES;
}

void main()
{
    g_line = (gl_WorkGroupID.x + u_group_base) * 64u + gl_LocalInvocationID.x;
    if (g_line >= u_lines)
        return;
    g_count = 0u;
    uint rejected, forced;
    int stop = trace(rejected, forced);
    s_info[4u * g_line] = g_count;
    s_info[4u * g_line + 1u] = uint(stop);
    s_info[4u * g_line + 2u] = rejected;
    s_info[4u * g_line + 3u] = forced;
}
