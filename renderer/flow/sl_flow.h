/* sl_flow.h — streamline integration shared by every vector-field kind
 * (issue 15 "Streamlines"; Fuchs, Barrowclough, Hjelmervik, Dahl, paper 003,
 * sec. 5, Eq. 5-6, the heuristic step of Eq. 4).
 *
 * Why a folder of its own: the same integrators serve regular vector
 * volumes (trilinear), LR-spline vector volumes and analytic test fields,
 * and feed sightline-trace, the benchmarks and the streamline tubes of
 * lr_volume; none of those owns them.
 *
 * Pieces: sl_flow_field (sampling, CPU, double), the Runge-Kutta table
 * sl_flow_methods (one Butcher tableau per solver, also handed to the
 * compute shader so both paths run the same coefficients), sl_flow_trace
 * (the CPU double reference integrator), seeds, and the result as an
 * sl_lines (positions + velocities = Hermite data for renderer/tubes).
 * The GPU path is flow_gpu.h. Any thread for everything here; no GL. A
 * field borrows its dataset, which must outlive it.
 */
#ifndef SL_FLOW_H
#define SL_FLOW_H

#include <stddef.h>

#include "../core/sl_status.h"
#include "../data/sl_dataset.h"
#include "../lrspline/sl_lr.h"

/* ---- fields ------------------------------------------------------------ */

typedef enum sl_flow_field_kind {
    SL_FLOW_FIELD_REGULAR = 1,  /* SL_DATASET_VECTORS, trilinear */
    SL_FLOW_FIELD_LR = 2,       /* LR-spline volume of dim 3, sl_lr_eval */
    SL_FLOW_FIELD_HELIX = 3,    /* analytic v = (-w y, w x, c) */
} sl_flow_field_kind;

/* A vector field on a closed box domain [lo, hi] (world units).
 *
 * Regular: voxel (i,j,k) sits at origin + (i,j,k) * spacing (the voxel-centre
 * convention of renderer/volume); the domain spans the centres, [origin,
 * origin + (dims - 1) * spacing] (an axis of one voxel: a slab half a spacing
 * either side, the field constant along it). Trilinear between the 8
 * surrounding centres: q = (p - origin) / spacing, i = clamp(floor(q), 0,
 * dims - 2), f = q - i, the value lerped x, then y, then z (the compute
 * shader does the same operations in the same order).
 * LR: the parameter domain, sl_lr_eval on the element of the element rule.
 * Helix: an analytic rotation about the z axis at angular speed omega with
 * axial speed c, on the given box; x(t) = (r cos(w t + phi), r sin(w t +
 * phi), z0 + c t) exactly. */
typedef struct sl_flow_field {
    sl_flow_field_kind kind;
    double lo[3], hi[3];
    /* regular */
    const sl_volume *volume;      /* borrowed, f32 x 3 */
    double origin[3], spacing[3];
    int dims[3];
    /* LR */
    const sl_lr_volume *lr;       /* borrowed, dim 3 */
    /* helix */
    double omega, axial;
} sl_flow_field;

/* From a dataset: SL_DATASET_VECTORS or SL_DATASET_LR of dim 3.
 * SL_ERR_INVALID for any other kind (the message names it). */
sl_status sl_flow_field_from_dataset(sl_flow_field *f, const sl_dataset *ds, sl_err *err);
/* The helix field on box [lo, hi]. */
void sl_flow_field_helix(sl_flow_field *f, double omega, double axial, const double lo[3],
                         const double hi[3]);
/* Exact helix streamline from seed x0 at time t (the field's omega, axial). */
void sl_flow_helix_exact(const sl_flow_field *f, const double x0[3], double t, double x[3]);

/* Per-trace look-up state (the LR element last found, tried first). */
typedef struct sl_flow_cursor {
    long element;                 /* -1: none */
} sl_flow_cursor;

/* 1 when p is finite and inside the closed domain box. */
int sl_flow_inside(const sl_flow_field *f, const double p[3]);
/* v = field(p). Returns 0 inside, -1 outside (v zeroed). cursor may be NULL. */
int sl_flow_sample(const sl_flow_field *f, const double p[3], sl_flow_cursor *cursor, double v[3]);
/* The paper's heuristic local size at p (Eq. 4, used as the step unit):
 * LR: min side of p's element / 2^d, d = the largest degree of the spline
 * (max order - 1; at least 1, so a degree-0 piece still halves);
 * regular: min spacing / 2 (trilinear = degree 1, the voxel is the element);
 * helix: min box side / 64 (a stand-in: the field has no elements).
 * 0 when p is outside. */
double sl_flow_local_size(const sl_flow_field *f, const double p[3], sl_flow_cursor *cursor);

/* ---- solvers ----------------------------------------------------------- */

#define SL_FLOW_MAX_STAGES 6

typedef enum sl_flow_solver {
    SL_FLOW_RK1 = 0, SL_FLOW_RK2, SL_FLOW_RK3, SL_FLOW_RK4, SL_FLOW_RK4_38, SL_FLOW_RKF5,
    SL_FLOW_HE, SL_FLOW_BS, SL_FLOW_RKF45,
    SL_FLOW_SOLVER_COUNT
} sl_flow_solver;

/* An explicit Runge-Kutta method: k_i = f(x + h sum_j a[i][j] k_j),
 * x' = x + h sum_i b[i] k_i; adaptive methods also have the embedded
 * weights e[i] of a solution of order `embedded_order`, the error
 * estimate is h * |sum_i (b[i] - e[i]) k_i|. (c_i = sum_j a[i][j]: the
 * field is steady, so c is not needed.) */
typedef struct sl_flow_method {
    const char *name;             /* "rk1" ... "rkf45" */
    const char *description;
    int stages;
    int order;                    /* of the propagated solution */
    int embedded_order;           /* 0: fixed step */
    double a[SL_FLOW_MAX_STAGES][SL_FLOW_MAX_STAGES];
    double b[SL_FLOW_MAX_STAGES];
    double e[SL_FLOW_MAX_STAGES];
} sl_flow_method;

/* The table, indexed by sl_flow_solver:
 * rk1 Euler; rk2 the explicit midpoint rule; rk3 Kutta's third order; rk4
 * the classic; rk4_38 the 3/8 rule; rkf5 Fehlberg's 6-stage pair, its 5th
 * order solution with a fixed step; he Heun-Euler 2(1); bs Bogacki-Shampine
 * 3(2) (FSAL not exploited: 4 evaluations a step); rkf45 Fehlberg 4(5)
 * propagating the 5th-order solution (local extrapolation). */
extern const sl_flow_method sl_flow_methods[SL_FLOW_SOLVER_COUNT];
/* The solvers' names in sl_flow_solver order, NULL-terminated (for
 * parameter schemas; each equals sl_flow_methods[i].name). */
extern const char *const sl_flow_solver_names[SL_FLOW_SOLVER_COUNT + 1];
/* By name (case-sensitive, "rk4-38" also accepted); -1 when unknown. */
int sl_flow_solver_find(const char *name);

/* ---- tracing ----------------------------------------------------------- */

typedef enum sl_flow_step_mode {
    SL_FLOW_STEP_FIXED = 0,       /* h = step */
    SL_FLOW_STEP_HEURISTIC = 1,   /* h = step * sl_flow_local_size(x) (fixed-step solvers only) */
    SL_FLOW_STEP_ADAPTIVE = 2,    /* embedded error control with tol (adaptive solvers) */
} sl_flow_step_mode;

typedef enum sl_flow_stop {
    SL_FLOW_STOP_NONE = 0,
    SL_FLOW_STOP_TIME = 1,        /* t reached t_max */
    SL_FLOW_STOP_BOUNDARY = 2,    /* left the domain: last sample on the boundary */
    SL_FLOW_STOP_SAMPLES = 3,     /* max_samples written */
    SL_FLOW_STOP_STAGNANT = 4,    /* speed below min_speed */
    SL_FLOW_STOP_NAN = 5,         /* the field gave a non-finite value */
    SL_FLOW_STOP_SEED_OUTSIDE = 6,/* the seed is outside the domain or not finite: no samples */
} sl_flow_stop;
const char *sl_flow_stop_name(sl_flow_stop s);

/* Zero = default where stated.
 * Adaptive step control (he, bs, rkf45): err = |x_high - x_low|_2 (absolute,
 * world units, the Euclidean norm of the difference of the two solutions);
 * a step is accepted when err <= tol; either way the next step is
 * h * clamp(0.9 (tol / err)^(1 / (embedded_order + 1)), 0.2, 5) (the root
 * by sl_flow_step_root, tol / err clamped to [1e-10, 1e10]), then
 * clamped to [h_min, h_max]; a step already at h_min is accepted whatever
 * err (counted in `forced`), so the trace always advances. The first step is
 * `step` when given, else min(h_max, tol^(1/(q+1))) with q the embedded order.
 * Boundary: a step whose result or any stage point leaves the domain is
 * shortened by bisection on h (at most 64 halvings, to 1e-13 h) to the
 * longest h whose stages and result stay inside; from that point one Euler
 * step along the local velocity to the first face it reaches, that
 * coordinate set exactly to the face; the trace stops there (BOUNDARY). A
 * step is also clipped so t never passes t_max. */
typedef struct sl_flow_options {
    sl_flow_solver solver;
    sl_flow_step_mode mode;
    double step;                  /* fixed: h; heuristic: the factor H; adaptive: first h (0 = auto) */
    double tol;                   /* adaptive, > 0 */
    double h_min, h_max;          /* adaptive; 0 = 1e-9 t_max and t_max */
    double t_max;                 /* > 0 */
    size_t max_samples;           /* per line, seed included; 0 = 10000 */
    double min_speed;             /* stop below; 0 = 1e-300 */
} sl_flow_options;

/* r^(1/n) for r in [1e-10, 1e10] and n in 1..8, as the step control takes
 * it: n = 1 r, n = 2 sqrt(r), else r = m 2^(n k) with m in [2^-1, 2^(n-1))
 * (frexp), Newton's iteration on y^n = m from y = 2 for 12 rounds, times
 * 2^k. Only operations IEEE 754 rounds exactly (+ - * / sqrt, exponent
 * scaling), in a fixed order, so flow_integrate.glsl's root_n gives the
 * same bits in double on the GPU. libm's pow(r, 1.0 / 3) did not: its
 * exponent is not 1/3, and a Newton root from a float pow seed differs by
 * an ulp or two, which the cancellation in the error estimate amplified
 * into different step sequences (test_flow_gpu). Within 1 ulp of the
 * true root (measured for n = 1..8 over the range; test_flow bounds it). */
double sl_flow_step_root(double r, int n);

/* Checks the options against a field (solver vs mode, positive step / tol /
 * t_max, finite values): SL_ERR_INVALID with a sentence. */
sl_status sl_flow_options_check(const sl_flow_options *o, sl_err *err);

/* One streamline: samples (t, x, v = field(x)) from the seed on. */
typedef struct sl_flow_line {
    size_t count;
    double *t;                    /* count */
    double *x;                    /* 3 * count */
    double *v;                    /* 3 * count */
    sl_flow_stop stop;
    size_t rejected;              /* adaptive: rejected trial steps */
    size_t forced;                /* adaptive: steps accepted at h_min above tol */
    size_t evaluations;           /* field samples taken */
} sl_flow_line;

typedef struct sl_flow_result {
    size_t line_count;
    sl_flow_line *lines;          /* owned */
} sl_flow_result;

/* Traces one streamline per seed on the CPU in double. SL_ERR_INVALID for
 * bad options, SL_ERR_NOMEM, SL_ERR_LIMIT when the samples of all lines
 * together would exceed SL_MAX_VERTICES. Degenerate lines (seed outside, NaN, zero
 * speed) are not errors: they carry their stop reason. On failure *out is
 * zeroed and nothing is allocated. */
sl_status sl_flow_trace(const sl_flow_field *f, const double *seeds, size_t seed_count,
                        const sl_flow_options *o, sl_flow_result *out, sl_err *err);
void sl_flow_result_free(sl_flow_result *r); /* zeroed is fine */

/* The paper's error metric E (Eq. 7) of line y against a reference x:
 * sum over y's samples i >= 1 of (t_i - t_{i-1}) |x(t_i) - y_i|_2, where
 * x(t_i) is the reference at time t_i by cubic Hermite interpolation of its
 * samples (positions and velocities; exact to O(h^4) of the reference
 * spacing), or exact(t) when `exact` is given. Samples past the reference's
 * last time use its last sample (the lines stopped at the boundary). */
typedef void (*sl_flow_exact_fn)(void *user, size_t line, double t, double x[3]);
double sl_flow_line_error(const sl_flow_line *y, const sl_flow_line *ref,
                          sl_flow_exact_fn exact, void *user, size_t line);
/* max over lines of sl_flow_line_error (lines paired by index). */
double sl_flow_error(const sl_flow_result *y, const sl_flow_result *ref,
                     sl_flow_exact_fn exact, void *user);

/* The result as a line set dataset: one line per streamline with at least
 * 2 samples, positions and tangents = velocities (world units per unit t:
 * Hermite data for renderer/tubes), a per-vertex attribute "speed" and "t";
 * finished with sl_dataset_finish_lines (so positions are float relative
 * to the bounds centre). SL_ERR_INVALID when no line has 2 samples. */
sl_status sl_flow_result_to_dataset(const sl_flow_result *r, const char *name, sl_dataset **out,
                                    sl_err *err);

/* ---- seeds ------------------------------------------------------------- */

/* Seeds as x,y,z triples (owned *seeds, free()).
 * CSV: one "x,y,z" per line (spaces allowed; blank lines and lines starting
 * with '#' skipped; a first line that does not parse as numbers is a header
 * and skipped); anything else is SL_ERR_FORMAT naming the line.
 * Box "x0,y0,z0,x1,y1,z1,count": count points of the Halton sequence in
 * bases 2, 3, 5 (indices 1..count) mapped to the box, deterministic.
 * Plane "ox,oy,oz,ux,uy,uz,vx,vy,vz,nu,nv": the nu x nv cell centres
 * o + (i + 0.5)/nu u + (j + 0.5)/nv v, i fastest.
 * At most SL_FLOW_MAX_SEEDS seeds (SL_ERR_LIMIT). */
#define SL_FLOW_MAX_SEEDS (1u << 20)
sl_status sl_flow_seeds_csv(const char *text, size_t size, double **seeds, size_t *count, sl_err *err);
sl_status sl_flow_seeds_box(const char *spec, double **seeds, size_t *count, sl_err *err);
sl_status sl_flow_seeds_plane(const char *spec, double **seeds, size_t *count, sl_err *err);

#endif
