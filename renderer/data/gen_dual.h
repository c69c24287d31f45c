/* gen_dual.h — forward-mode dual numbers with three partials, for exact field Jacobians.
 *
 * A sl_dual3 carries a value and its gradient with respect to (x, y, z);
 * evaluating a field formula on duals gives the field and its exact
 * derivatives (the chain rule applied per operation, not finite differences).
 * The value part is computed with the same operations in the same order as
 * plain double code, so `.v` is bit-identical to the double formula.
 * Non-smooth operations (fabs, fmax, branches) take the derivative of the
 * branch picked by value; at a kink either one-sided derivative is returned.
 * The SL_NUM_* macros spell each operation once for both double and
 * sl_dual3 (C11 _Generic on the first operand), so one formula can be
 * compiled as plain double code and as dual code (gen_tornado_field.h).
 * Header-only, static inline, no state; any thread. Internal to data/.
 */
#ifndef SL_GEN_DUAL_H
#define SL_GEN_DUAL_H

#include <math.h>

typedef struct sl_dual3 {
    double v;    /* value */
    double d[3]; /* partial derivatives d/dx, d/dy, d/dz */
} sl_dual3;

/* A constant: zero gradient. */
static inline sl_dual3 sl_dual_const(double v)
{
    return (sl_dual3){v, {0.0, 0.0, 0.0}};
}

/* The independent variable `axis` (0..2) with value v. */
static inline sl_dual3 sl_dual_var(double v, int axis)
{
    sl_dual3 r = {v, {0.0, 0.0, 0.0}};
    r.d[axis] = 1.0;
    return r;
}

static inline sl_dual3 sl_dual_add(sl_dual3 a, sl_dual3 b)
{
    return (sl_dual3){a.v + b.v, {a.d[0] + b.d[0], a.d[1] + b.d[1], a.d[2] + b.d[2]}};
}

static inline sl_dual3 sl_dual_sub(sl_dual3 a, sl_dual3 b)
{
    return (sl_dual3){a.v - b.v, {a.d[0] - b.d[0], a.d[1] - b.d[1], a.d[2] - b.d[2]}};
}

static inline sl_dual3 sl_dual_mul(sl_dual3 a, sl_dual3 b)
{
    sl_dual3 r = {a.v * b.v, {0.0, 0.0, 0.0}};
    for (int k = 0; k < 3; k++)
        r.d[k] = a.d[k] * b.v + a.v * b.d[k];
    return r;
}

/* a / b; b.v == 0 gives what double division gives (inf or nan). */
static inline sl_dual3 sl_dual_div(sl_dual3 a, sl_dual3 b)
{
    sl_dual3 r = {a.v / b.v, {0.0, 0.0, 0.0}};
    for (int k = 0; k < 3; k++)
        r.d[k] = (a.d[k] - r.v * b.d[k]) / b.v;
    return r;
}

/* s * a for a plain double s (same value as s * a.v). */
static inline sl_dual3 sl_dual_scale(double s, sl_dual3 a)
{
    return (sl_dual3){s * a.v, {s * a.d[0], s * a.d[1], s * a.d[2]}};
}

/* sqrt. At a.v == 0 the gradient is taken as 0: on the sums of squares it is
 * used for (a distance) that is the cone point, and 0 its symmetric
 * subgradient, so a point on an axis gets finite derivatives, not 0 / 0. */
static inline sl_dual3 sl_dual_sqrt(sl_dual3 a)
{
    double s = sqrt(a.v);
    sl_dual3 r = {s, {0.0, 0.0, 0.0}};
    for (int k = 0; s > 0.0 && k < 3; k++)
        r.d[k] = a.d[k] / (2.0 * s);
    return r;
}

static inline sl_dual3 sl_dual_sin(sl_dual3 a)
{
    double c = cos(a.v);
    return (sl_dual3){sin(a.v), {c * a.d[0], c * a.d[1], c * a.d[2]}};
}

static inline sl_dual3 sl_dual_cos(sl_dual3 a)
{
    double s = -sin(a.v);
    return (sl_dual3){cos(a.v), {s * a.d[0], s * a.d[1], s * a.d[2]}};
}

/* |a|; at a.v == 0 the derivative of +a is returned. */
static inline sl_dual3 sl_dual_fabs(sl_dual3 a)
{
    return a.v < 0.0 ? sl_dual_scale(-1.0, a) : a;
}

/* The larger by value (a on a tie), with its own gradient; like fmax, a NaN
 * loses to a number. */
static inline sl_dual3 sl_dual_fmax(sl_dual3 a, sl_dual3 b)
{
    return b.v > a.v || isnan(a.v) ? b : a;
}

/* Plain-double counterparts of the operations above, for the SL_NUM_* macros. */
static inline double sl_real_const(double v)
{
    return v;
}

static inline double sl_real_var(double v, int axis)
{
    (void)axis;
    return v;
}

static inline double sl_real_value(double a)
{
    return a;
}

static inline double sl_dual_value(sl_dual3 a)
{
    return a.v;
}

static inline double sl_real_add(double a, double b)
{
    return a + b;
}

static inline double sl_real_sub(double a, double b)
{
    return a - b;
}

static inline double sl_real_mul(double a, double b)
{
    return a * b;
}

static inline double sl_real_div(double a, double b)
{
    return a / b;
}

static inline double sl_real_scale(double s, double a)
{
    return s * a;
}

/* T is `double` or `sl_dual3`; every other operand of one call has the type
 * of the first (mix in plain numbers through SL_NUM_CONST or SL_NUM_SCALE). */
#define SL_NUM_CONST(T, c) _Generic((T){0}, sl_dual3: sl_dual_const, default: sl_real_const)(c)
#define SL_NUM_VAR(T, v, axis) _Generic((T){0}, sl_dual3: sl_dual_var, default: sl_real_var)(v, axis)
#define SL_NUM_VALUE(a) _Generic((a), sl_dual3: sl_dual_value, default: sl_real_value)(a)
#define SL_NUM_ADD(a, b) _Generic((a), sl_dual3: sl_dual_add, default: sl_real_add)(a, b)
#define SL_NUM_SUB(a, b) _Generic((a), sl_dual3: sl_dual_sub, default: sl_real_sub)(a, b)
#define SL_NUM_MUL(a, b) _Generic((a), sl_dual3: sl_dual_mul, default: sl_real_mul)(a, b)
#define SL_NUM_DIV(a, b) _Generic((a), sl_dual3: sl_dual_div, default: sl_real_div)(a, b)
#define SL_NUM_SCALE(s, a) _Generic((a), sl_dual3: sl_dual_scale, default: sl_real_scale)(s, a)
#define SL_NUM_SQRT(a) _Generic((a), sl_dual3: sl_dual_sqrt, default: sqrt)(a)
#define SL_NUM_SIN(a) _Generic((a), sl_dual3: sl_dual_sin, default: sin)(a)
#define SL_NUM_COS(a) _Generic((a), sl_dual3: sl_dual_cos, default: cos)(a)
#define SL_NUM_FABS(a) _Generic((a), sl_dual3: sl_dual_fabs, default: fabs)(a)
#define SL_NUM_FMAX(a, b) _Generic((a), sl_dual3: sl_dual_fmax, default: fmax)(a, b)

#endif
