/* flow_trace.c — the CPU double-precision reference integrator (sl_flow.h:
 * step modes, error control, boundary clipping, stop reasons) and the
 * error metric of Eq. 7. Every loop is bounded: samples by max_samples,
 * rejections per step by the factor 0.2 down to h_min (then accepted),
 * boundary bisection by 64 halvings, so no input makes it hang.
 * Any thread; no GL; the field is only read.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sl_flow.h"

const char *sl_flow_stop_name(sl_flow_stop s)
{
    switch (s) {
    case SL_FLOW_STOP_NONE: return "none";
    case SL_FLOW_STOP_TIME: return "t_max";
    case SL_FLOW_STOP_BOUNDARY: return "boundary";
    case SL_FLOW_STOP_SAMPLES: return "max_samples";
    case SL_FLOW_STOP_STAGNANT: return "stagnant";
    case SL_FLOW_STOP_NAN: return "nan";
    case SL_FLOW_STOP_SEED_OUTSIDE: return "seed_outside";
    }
    return "unknown";
}

sl_status sl_flow_options_check(const sl_flow_options *o, sl_err *err)
{
    if ((int)o->solver < 0 || o->solver >= SL_FLOW_SOLVER_COUNT)
        return sl_err_set(err, SL_ERR_INVALID, "unknown solver %d", (int)o->solver);
    const sl_flow_method *m = &sl_flow_methods[o->solver];
    if (!(isfinite(o->t_max) && o->t_max > 0.0))
        return sl_err_set(err, SL_ERR_INVALID, "t_max must be a positive number (got %g)", o->t_max);
    if (o->mode == SL_FLOW_STEP_ADAPTIVE) {
        if (m->embedded_order == 0)
            return sl_err_set(err, SL_ERR_INVALID,
                              "solver %s has a fixed step: give a step, not a tolerance "
                              "(adaptive solvers: he, bs, rkf45)", m->name);
        if (!(isfinite(o->tol) && o->tol > 0.0))
            return sl_err_set(err, SL_ERR_INVALID, "tol must be a positive number (got %g)", o->tol);
        if (!(isfinite(o->step) && o->step >= 0.0))
            return sl_err_set(err, SL_ERR_INVALID, "the first step must be >= 0 (got %g)", o->step);
        if (!(isfinite(o->h_min) && o->h_min >= 0.0 && isfinite(o->h_max) && o->h_max >= 0.0) ||
            (o->h_min > 0.0 && o->h_max > 0.0 && o->h_min > o->h_max))
            return sl_err_set(err, SL_ERR_INVALID, "h_min %g and h_max %g must be >= 0 with h_min <= h_max",
                              o->h_min, o->h_max);
    } else if (o->mode == SL_FLOW_STEP_FIXED || o->mode == SL_FLOW_STEP_HEURISTIC) {
        if (m->embedded_order != 0)
            return sl_err_set(err, SL_ERR_INVALID,
                              "solver %s is adaptive: give a tolerance, not a step", m->name);
        if (!(isfinite(o->step) && o->step > 0.0))
            return sl_err_set(err, SL_ERR_INVALID, "step must be a positive number (got %g)", o->step);
    } else {
        return sl_err_set(err, SL_ERR_INVALID, "unknown step mode %d", (int)o->mode);
    }
    if (!(o->min_speed >= 0.0))
        return sl_err_set(err, SL_ERR_INVALID, "min_speed must be >= 0");
    return SL_OK;
}

double sl_flow_step_root(double r, int n)
{
    if (n <= 1)
        return r;
    if (n == 2)
        return sqrt(r);
    int e;
    double m = frexp(r, &e);             /* r = m 2^e, m in [0.5, 1) */
    int k = e >= 0 ? e / n : -((n - 1 - e) / n); /* floor(e / n) */
    m = ldexp(m, e - n * k);             /* in [0.5, 2^(n-1)) */
    double y = 2.0;                      /* above every root of such m */
    for (int it = 0; it < 12; it++) {
        double y1 = y;
        for (int j = 2; j < n; j++)
            y1 = y1 * y;                 /* y^(n-1) */
        y = y - (y1 * y - m) / ((double)n * y1);
    }
    return ldexp(y, k);
}

static int finite3(const double v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

static double norm3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* One RK step of length h from x, k0 = field(x). 0: xn (and *err_norm for
 * embedded methods) filled; -1: a stage point or the result is outside;
 * -2: the field gave a non-finite value. */
static int rk_step(const sl_flow_field *f, const sl_flow_method *m, sl_flow_cursor *cur,
                   const double x[3], const double k0[3], double h, double xn[3],
                   double *err_norm, size_t *evals)
{
    double k[SL_FLOW_MAX_STAGES][3];
    memcpy(k[0], k0, sizeof k[0]);
    for (int i = 1; i < m->stages; i++) {
        double p[3];
        for (int c = 0; c < 3; c++) {
            double s = 0.0;
            for (int j = 0; j < i; j++)
                s += m->a[i][j] * k[j][c];
            p[c] = x[c] + h * s;
        }
        (*evals)++;
        if (sl_flow_sample(f, p, cur, k[i]) != 0)
            return -1;
        if (!finite3(k[i]))
            return -2;
    }
    double d[3];
    for (int c = 0; c < 3; c++) {
        double s = 0.0, e = 0.0;
        for (int i = 0; i < m->stages; i++) {
            s += m->b[i] * k[i][c];
            e += (m->b[i] - m->e[i]) * k[i][c];
        }
        xn[c] = x[c] + h * s;
        d[c] = h * e;
    }
    if (err_norm)
        *err_norm = m->embedded_order ? norm3(d) : 0.0;
    return sl_flow_inside(f, xn) ? 0 : -1;
}

typedef struct line_builder {
    sl_flow_line *line;
    size_t capacity, max;
    size_t *total;                 /* samples of all lines so far */
} line_builder;

/* 0 ok, -1 no memory, -2 over the global limit. */
static int push(line_builder *b, double t, const double x[3], const double v[3])
{
    sl_flow_line *l = b->line;
    if (*b->total >= SL_MAX_VERTICES)
        return -2;
    if (l->count == b->capacity) {
        size_t cap = b->capacity ? 2 * b->capacity : 64;
        if (cap > b->max)
            cap = b->max;
        double *nt = realloc(l->t, cap * sizeof *nt);
        if (!nt)
            return -1;
        l->t = nt;
        double *nx = realloc(l->x, 3 * cap * sizeof *nx);
        if (!nx)
            return -1;
        l->x = nx;
        double *nv = realloc(l->v, 3 * cap * sizeof *nv);
        if (!nv)
            return -1;
        l->v = nv;
        b->capacity = cap;
    }
    l->t[l->count] = t;
    memcpy(l->x + 3 * l->count, x, 3 * sizeof *x);
    memcpy(l->v + 3 * l->count, v, 3 * sizeof *v);
    l->count++;
    (*b->total)++;
    return 0;
}

/* Euler distance along v from x (inside) to the first face of the box; the
 * face coordinate is set exactly. Returns the time s (>= 0), or -1 when v is
 * zero. */
static double to_boundary(const sl_flow_field *f, const double x[3], const double v[3], double xb[3])
{
    double s = INFINITY;
    int axis = -1;
    for (int a = 0; a < 3; a++) {
        if (v[a] == 0.0)
            continue;
        double face = v[a] > 0.0 ? f->hi[a] : f->lo[a];
        double sa = (face - x[a]) / v[a];
        if (sa < 0.0)
            sa = 0.0;
        if (sa < s) {
            s = sa;
            axis = a;
        }
    }
    if (axis < 0)
        return -1.0;
    for (int a = 0; a < 3; a++) {
        xb[a] = x[a] + s * v[a];
        if (xb[a] < f->lo[a])
            xb[a] = f->lo[a];
        if (xb[a] > f->hi[a])
            xb[a] = f->hi[a];
    }
    xb[axis] = v[axis] > 0.0 ? f->hi[axis] : f->lo[axis];
    return s;
}

/* Traces one line; returns 0, or the push failure (-1 memory, -2 limit). */
static int trace_line(const sl_flow_field *f, const double seed[3], const sl_flow_options *o,
                      sl_flow_line *l, size_t *total)
{
    const sl_flow_method *m = &sl_flow_methods[o->solver];
    size_t max_samples = o->max_samples ? o->max_samples : 10000;
    double min_speed = o->min_speed > 0.0 ? o->min_speed : 1e-300;
    double h_max = o->h_max > 0.0 ? o->h_max : o->t_max;
    double h_min = o->h_min > 0.0 ? o->h_min : 1e-9 * o->t_max;
    if (h_min > h_max)
        h_min = h_max;
    line_builder b = {l, 0, max_samples, total};
    sl_flow_cursor cur = {-1};
    double x[3] = {seed[0], seed[1], seed[2]}, v[3], t = 0.0;
    int r;

    if (!sl_flow_inside(f, x)) {
        l->stop = SL_FLOW_STOP_SEED_OUTSIDE;
        return 0;
    }
    l->evaluations++;
    if (sl_flow_sample(f, x, &cur, v) != 0) {
        l->stop = SL_FLOW_STOP_SEED_OUTSIDE;
        return 0;
    }
    if (!finite3(v)) {
        l->stop = SL_FLOW_STOP_NAN;
        return 0;
    }
    if ((r = push(&b, t, x, v)) != 0)
        return r;

    double h_adapt = o->step > 0.0 ? o->step
                                   : pow(o->tol, 1.0 / (double)(m->embedded_order + 1));
    if (m->embedded_order) {
        if (h_adapt > h_max)
            h_adapt = h_max;
        if (h_adapt < h_min)
            h_adapt = h_min;
    }
    for (;;) {
        if (l->count >= max_samples) {
            l->stop = SL_FLOW_STOP_SAMPLES;
            return 0;
        }
        if (norm3(v) < min_speed) {
            l->stop = SL_FLOW_STOP_STAGNANT;
            return 0;
        }
        double h;
        if (o->mode == SL_FLOW_STEP_FIXED)
            h = o->step;
        else if (o->mode == SL_FLOW_STEP_HEURISTIC)
            h = o->step * sl_flow_local_size(f, x, &cur);
        else
            h = h_adapt;
        double remaining = o->t_max - t;
        int last = 0;
        if (h >= remaining) {
            h = remaining;
            last = 1;
        }
        double xn[3], e = 0.0;
        int boundary = 0;
        for (;;) {
            int s = rk_step(f, m, &cur, x, v, h, xn, &e, &l->evaluations);
            if (s == -2) {
                l->stop = SL_FLOW_STOP_NAN;
                return 0;
            }
            if (s == -1) {
                boundary = 1;
                break;
            }
            if (o->mode != SL_FLOW_STEP_ADAPTIVE)
                break;
            double ratio = e > 0.0 ? o->tol / e : 1e10;
            ratio = ratio < 1e-10 ? 1e-10 : ratio > 1e10 ? 1e10 : ratio; /* fac is clamped below anyway */
            double fac = e > 0.0 ? 0.9 * sl_flow_step_root(ratio, m->embedded_order + 1) : 5.0;
            if (fac < 0.2)
                fac = 0.2;
            if (fac > 5.0)
                fac = 5.0;
            double hn = h * fac;
            if (hn > h_max)
                hn = h_max;
            if (hn < h_min)
                hn = h_min;
            if (e <= o->tol || h <= h_min) {
                if (e > o->tol)
                    l->forced++;
                if (!last || hn < h_adapt)
                    h_adapt = hn;
                break;
            }
            l->rejected++;
            h = hn;
            last = 0;
        }
        if (boundary) {
            /* The longest h in [0, h) whose stages and result stay inside. */
            double lo = 0.0, hi = h, xl[3] = {x[0], x[1], x[2]};
            for (int it = 0; it < 64 && hi - lo > 1e-13 * h; it++) {
                double mid = 0.5 * (lo + hi), xm[3];
                int s = rk_step(f, m, &cur, x, v, mid, xm, NULL, &l->evaluations);
                if (s == -2) {
                    l->stop = SL_FLOW_STOP_NAN;
                    return 0;
                }
                if (s == 0) {
                    lo = mid;
                    memcpy(xl, xm, sizeof xl);
                } else {
                    hi = mid;
                }
            }
            if (lo > 0.0) {
                memcpy(x, xl, sizeof x);
                t += lo;
                l->evaluations++;
                sl_flow_sample(f, x, &cur, v);
                if (!finite3(v)) {
                    l->stop = SL_FLOW_STOP_NAN;
                    return 0;
                }
                if (l->count >= max_samples) {
                    l->stop = SL_FLOW_STOP_SAMPLES;
                    return 0;
                }
                if ((r = push(&b, t, x, v)) != 0)
                    return r;
            }
            double xb[3];
            double s = to_boundary(f, x, v, xb);
            l->stop = SL_FLOW_STOP_BOUNDARY;
            if (s <= 0.0 || l->count >= max_samples)
                return 0;          /* already on the face, or no room */
            if (t + s > o->t_max) {
                s = o->t_max - t;
                for (int c = 0; c < 3; c++)
                    xb[c] = x[c] + s * v[c];
                if (!sl_flow_inside(f, xb))
                    return 0;
                l->stop = SL_FLOW_STOP_TIME;
            }
            double vb[3];
            l->evaluations++;
            sl_flow_sample(f, xb, &cur, vb);
            if (!finite3(vb)) {
                l->stop = SL_FLOW_STOP_NAN;
                return 0;
            }
            t = l->stop == SL_FLOW_STOP_TIME ? o->t_max : t + s;
            return push(&b, t, xb, vb);
        }
        memcpy(x, xn, sizeof x);
        t = last ? o->t_max : t + h;
        l->evaluations++;
        sl_flow_sample(f, x, &cur, v);
        if (!finite3(v)) {
            l->stop = SL_FLOW_STOP_NAN;
            return 0;
        }
        if ((r = push(&b, t, x, v)) != 0)
            return r;
        if (last) {
            l->stop = SL_FLOW_STOP_TIME;
            return 0;
        }
    }
}

void sl_flow_result_free(sl_flow_result *r)
{
    if (!r)
        return;
    for (size_t i = 0; i < r->line_count; i++) {
        free(r->lines[i].t);
        free(r->lines[i].x);
        free(r->lines[i].v);
    }
    free(r->lines);
    memset(r, 0, sizeof *r);
}

sl_status sl_flow_trace(const sl_flow_field *f, const double *seeds, size_t seed_count,
                        const sl_flow_options *o, sl_flow_result *out, sl_err *err)
{
    memset(out, 0, sizeof *out);
    sl_status st = sl_flow_options_check(o, err);
    if (st != SL_OK)
        return st;
    if (seed_count > SL_FLOW_MAX_SEEDS)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu seeds exceed the limit of %u", seed_count,
                          (unsigned)SL_FLOW_MAX_SEEDS);
    sl_flow_result r = {0};
    r.lines = calloc(seed_count ? seed_count : 1, sizeof *r.lines);
    if (!r.lines)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu streamlines", seed_count);
    r.line_count = seed_count;
    size_t total = 0;
    for (size_t i = 0; i < seed_count; i++) {
        int rc = trace_line(f, seeds + 3 * i, o, &r.lines[i], &total);
        if (rc != 0) {
            sl_flow_result_free(&r);
            if (rc == -2)
                return sl_err_set(err, SL_ERR_LIMIT,
                                  "streamline samples exceed the limit of %u in all (line %zu)",
                                  (unsigned)SL_MAX_VERTICES, i);
            return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the samples of streamline %zu", i);
        }
    }
    *out = r;
    return SL_OK;
}

/* Reference position at time t: cubic Hermite on the reference's samples. */
static void ref_at(const sl_flow_line *ref, double t, double x[3])
{
    size_t n = ref->count;
    if (t >= ref->t[n - 1] || n == 1) {
        memcpy(x, ref->x + 3 * (n - 1), 3 * sizeof *x);
        return;
    }
    if (t <= ref->t[0]) {
        memcpy(x, ref->x, 3 * sizeof *x);
        return;
    }
    size_t lo = 0, hi = n - 1;       /* t[lo] <= t < t[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (ref->t[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    double dt = ref->t[hi] - ref->t[lo];
    double s = (t - ref->t[lo]) / dt, s2 = s * s, s3 = s2 * s;
    double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
    for (int c = 0; c < 3; c++)
        x[c] = h00 * ref->x[3 * lo + c] + h10 * dt * ref->v[3 * lo + c] +
               h01 * ref->x[3 * hi + c] + h11 * dt * ref->v[3 * hi + c];
}

double sl_flow_line_error(const sl_flow_line *y, const sl_flow_line *ref,
                          sl_flow_exact_fn exact, void *user, size_t line)
{
    double sum = 0.0;
    if (!exact && (!ref || ref->count == 0))
        return y->count > 1 ? INFINITY : 0.0;
    for (size_t i = 1; i < y->count; i++) {
        double xr[3], d[3];
        if (exact)
            exact(user, line, y->t[i], xr);
        else
            ref_at(ref, y->t[i], xr);
        for (int c = 0; c < 3; c++)
            d[c] = xr[c] - y->x[3 * i + c];
        sum += (y->t[i] - y->t[i - 1]) * norm3(d);
    }
    return sum;
}

double sl_flow_error(const sl_flow_result *y, const sl_flow_result *ref,
                     sl_flow_exact_fn exact, void *user)
{
    double e = 0.0;
    for (size_t j = 0; j < y->line_count; j++) {
        const sl_flow_line *rl = ref && j < ref->line_count ? &ref->lines[j] : NULL;
        double ej = sl_flow_line_error(&y->lines[j], rl, exact, user, j);
        if (!(ej <= e))
            e = ej;
    }
    return e;
}
