/* test_flow.c — renderer/flow: the CPU streamline integrators against the
 * exact helix x(t) = (r cos(wt + phi), r sin(wt + phi), z0 + c t) of the
 * rotation field v = (-w y, w x, c) (closed form, no shared code).
 *
 * Orders: for every solver the error at t_max, measured at h and h/2, gives
 * log2(e(h)/e(h/2)) within [order - 0.25, order + 0.35]. Adaptive solvers:
 * the true error of every sample stays <= C tol with C = 50 (the local
 * control bounds each step by tol; about 20..200 steps a line over t = 4,
 * and with local extrapolation the propagated solution is better than
 * the controlled one), and the error shrinks with tol. Boundary stop
 * exactly on the face at the exact exit time (1e-9); degenerate cases
 * (zero field, NaN voxels, seeds outside or NaN, max_samples) stop with
 * their reason. The same helix as a regular vector volume (trilinear
 * reproduces linear fields) and as degree-1 and degree-2 LR-splines
 * (sl_lr_tensor_product; Greville coefficients reproduce linear fields)
 * gives the analytic field's streamlines to 1e-9 (adaptive: step choices may differ by rounding). Seeds, Eq. 7, and the
 * line set conversion. The step control's root (sl_flow_step_root) within 1
 * ulp of r^(1/n).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "flow/sl_flow.h"
#include "sl_test.h"

static const double box_lo[3] = {-2, -2, -1}, box_hi[3] = {2, 2, 10};

static double end_error(const sl_flow_field *f, sl_flow_solver s, double h, double t_max,
                        const double seed[3])
{
    sl_flow_options o = {.solver = s, .mode = SL_FLOW_STEP_FIXED, .step = h, .t_max = t_max,
                         .max_samples = 1000000};
    sl_flow_result r;
    sl_err err = {0};
    if (sl_flow_trace(f, seed, 1, &o, &r, &err) != SL_OK) {
        fprintf(stderr, "%s\n", err.message);
        return NAN;
    }
    const sl_flow_line *l = &r.lines[0];
    double x[3], e = NAN;
    if (l->stop == SL_FLOW_STOP_TIME && l->t[l->count - 1] == t_max) {
        sl_flow_helix_exact(f, seed, t_max, x);
        double d[3] = {x[0] - l->x[3 * (l->count - 1)], x[1] - l->x[3 * (l->count - 1) + 1],
                       x[2] - l->x[3 * (l->count - 1) + 2]};
        e = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    sl_flow_result_free(&r);
    return e;
}

static void test_orders(void)
{
    sl_flow_field f;
    sl_flow_field_helix(&f, 1.0, 0.5, box_lo, box_hi);
    const double seed[3] = {1.0, 0.3, 0.0};
    const double base[6] = {2e-3, 2e-2, 4e-2, 0.1, 0.1, 0.2};
    for (int s = SL_FLOW_RK1; s <= SL_FLOW_RKF5; s++) {
        double e1 = end_error(&f, s, base[s], 4.0, seed);
        double e2 = end_error(&f, s, base[s] / 2, 4.0, seed);
        double order = log2(e1 / e2);
        int p = sl_flow_methods[s].order;
        SL_CHECK_MSG(order >= p - 0.25 && order <= p + 0.35, "%s: e(h) %.3g e(h/2) %.3g order %.3f, expected %d",
                     sl_flow_methods[s].name, e1, e2, order, p);
    }
}

static double worst_sample_error(const sl_flow_field *f, const sl_flow_result *r, const double *seeds)
{
    double worst = 0;
    for (size_t j = 0; j < r->line_count; j++)
        for (size_t i = 0; i < r->lines[j].count; i++) {
            double x[3];
            sl_flow_helix_exact(f, seeds + 3 * j, r->lines[j].t[i], x);
            const double *y = r->lines[j].x + 3 * i;
            double e = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                            (x[2] - y[2]) * (x[2] - y[2]));
            if (!(e <= worst))
                worst = e;
        }
    return worst;
}

static void test_adaptive(void)
{
    sl_flow_field f;
    sl_flow_field_helix(&f, 1.0, 0.5, box_lo, box_hi);
    const double seeds[6] = {1.0, 0.3, 0.0, -0.5, 1.2, 1.0};
    for (int s = SL_FLOW_HE; s <= SL_FLOW_RKF45; s++) {
        double prev = INFINITY;
        for (double tol = 1e-4; tol >= 1e-10; tol *= 1e-2) {
            sl_flow_options o = {.solver = s, .mode = SL_FLOW_STEP_ADAPTIVE, .tol = tol, .t_max = 4.0,
                                 .max_samples = 1000000};
            sl_flow_result r;
            sl_err err = {0};
            SL_CHECK_MSG(sl_flow_trace(&f, seeds, 2, &o, &r, &err) == SL_OK, "%s", err.message);
            double e = worst_sample_error(&f, &r, seeds);
            SL_CHECK_MSG(e <= 50 * tol, "%s tol %g: true error %.3g (samples %zu)", sl_flow_methods[s].name,
                         tol, e, r.lines[0].count);
            SL_CHECK_MSG(e < prev, "%s tol %g: error %.3g did not shrink from %.3g", sl_flow_methods[s].name,
                         tol, e, prev);
            SL_CHECK(r.lines[0].stop == SL_FLOW_STOP_TIME && r.lines[0].t[r.lines[0].count - 1] == 4.0);
            SL_CHECK(r.lines[0].forced == 0);
            prev = e;
            sl_flow_result_free(&r);
        }
    }
}

static void test_boundary_and_degenerate(void)
{
    sl_flow_field f;
    const double lo[3] = {-2, -2, 0}, hi[3] = {2, 2, 1};
    sl_flow_field_helix(&f, 1.0, 0.5, lo, hi);
    const double seed[3] = {1.0, 0.0, 0.0};
    /* Exits through z = 1 at t = 2 exactly. */
    for (int s = 0; s < SL_FLOW_SOLVER_COUNT; s++) {
        sl_flow_options o = {.solver = s, .t_max = 10.0};
        if (sl_flow_methods[s].embedded_order) {
            o.mode = SL_FLOW_STEP_ADAPTIVE;
            o.tol = s == SL_FLOW_HE ? 1e-6 : 1e-9;
        } else {
            o.mode = SL_FLOW_STEP_FIXED;
            o.step = 0.07;
        }
        sl_flow_result r;
        sl_err err = {0};
        SL_CHECK(sl_flow_trace(&f, seed, 1, &o, &r, &err) == SL_OK);
        const sl_flow_line *l = &r.lines[0];
        SL_CHECK(l->stop == SL_FLOW_STOP_BOUNDARY);
        SL_CHECK(l->x[3 * (l->count - 1) + 2] == 1.0);
        SL_CHECK_NEAR(l->t[l->count - 1], 2.0, 1e-9);
        for (size_t i = 0; i < l->count; i++)
            SL_CHECK(sl_flow_inside(&f, l->x + 3 * i));
        sl_flow_result_free(&r);
    }
    /* Zero field: stagnant after the seed. */
    sl_flow_field z;
    sl_flow_field_helix(&z, 0.0, 0.0, lo, hi);
    sl_flow_options o = {.solver = SL_FLOW_RKF45, .mode = SL_FLOW_STEP_ADAPTIVE, .tol = 1e-6, .t_max = 1e6};
    sl_flow_result r;
    sl_err err = {0};
    const double seeds[9] = {0.5, 0.5, 0.5, 3.0, 0.0, 0.0, NAN, 0.0, 0.0};
    SL_CHECK(sl_flow_trace(&z, seeds, 3, &o, &r, &err) == SL_OK);
    SL_CHECK(r.lines[0].stop == SL_FLOW_STOP_STAGNANT && r.lines[0].count == 1);
    SL_CHECK(r.lines[1].stop == SL_FLOW_STOP_SEED_OUTSIDE && r.lines[1].count == 0);
    SL_CHECK(r.lines[2].stop == SL_FLOW_STOP_SEED_OUTSIDE && r.lines[2].count == 0);
    sl_flow_result_free(&r);
    /* max_samples */
    o = (sl_flow_options){.solver = SL_FLOW_RK4, .mode = SL_FLOW_STEP_FIXED, .step = 1e-3, .t_max = 100,
                          .max_samples = 5};
    SL_CHECK(sl_flow_trace(&f, seed, 1, &o, &r, &err) == SL_OK);
    SL_CHECK(r.lines[0].stop == SL_FLOW_STOP_SAMPLES && r.lines[0].count == 5);
    sl_flow_result_free(&r);
    /* Bad options are errors, not hangs. */
    o = (sl_flow_options){.solver = SL_FLOW_RK4, .mode = SL_FLOW_STEP_ADAPTIVE, .tol = 1e-6, .t_max = 1};
    SL_CHECK(sl_flow_trace(&f, seed, 1, &o, &r, &err) == SL_ERR_INVALID);
    o = (sl_flow_options){.solver = SL_FLOW_RK4, .mode = SL_FLOW_STEP_FIXED, .step = 0, .t_max = 1};
    SL_CHECK(sl_flow_trace(&f, seed, 1, &o, &r, &err) == SL_ERR_INVALID);
    o = (sl_flow_options){.solver = SL_FLOW_BS, .mode = SL_FLOW_STEP_ADAPTIVE, .tol = 1e-6, .t_max = INFINITY};
    SL_CHECK(sl_flow_trace(&f, seed, 1, &o, &r, &err) == SL_ERR_INVALID);
}

/* The helix sampled at voxel centres of a regular vector volume. */
static sl_dataset *helix_volume(const int dims[3], const double org[3], const double sp[3], int nan_voxel)
{
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VECTORS, "helix");
    sl_err err = {0};
    if (!ds || sl_volume_alloc(&ds->volume, dims, 3, SL_VOXEL_F32, &err) != SL_OK)
        return NULL;
    ds->origin = sl_v3(org[0], org[1], org[2]);
    for (int a = 0; a < 3; a++)
        ds->volume.spacing[a] = sp[a];
    float *d = ds->volume.data;
    for (int k = 0; k < dims[2]; k++)
        for (int j = 0; j < dims[1]; j++)
            for (int i = 0; i < dims[0]; i++) {
                size_t v = ((size_t)k * dims[1] + j) * dims[0] + i;
                double x = org[0] + i * sp[0], y = org[1] + j * sp[1];
                d[3 * v] = (float)(-y);
                d[3 * v + 1] = (float)x;
                d[3 * v + 2] = 0.5f;
            }
    if (nan_voxel)
        d[3 * ((size_t)dims[0] * dims[1] * (dims[2] / 2) + dims[0] * (dims[1] / 2) + dims[0] / 2)] = NAN;
    if (sl_dataset_finish_volume(ds, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

static double max_diff(const sl_flow_result *a, const sl_flow_result *b)
{
    double worst = 0;
    for (size_t j = 0; j < a->line_count; j++) {
        if (a->lines[j].count != b->lines[j].count)
            return INFINITY;
        for (size_t i = 0; i < 3 * a->lines[j].count; i++) {
            double e = fabs(a->lines[j].x[i] - b->lines[j].x[i]);
            if (!(e <= worst))
                worst = e;
        }
    }
    return worst;
}

static void test_regular(void)
{
    /* Spacing and origin exactly representable in float, so voxel values
     * are exact and the trilinear field equals the analytic one. */
    const int dims[3] = {17, 17, 9};
    const double org[3] = {-2, -2, -1}, sp[3] = {0.25, 0.25, 0.5};
    sl_dataset *ds = helix_volume(dims, org, sp, 0);
    SL_CHECK(ds != NULL);
    if (!ds)
        return;
    sl_flow_field f, h;
    sl_err err = {0};
    SL_CHECK(sl_flow_field_from_dataset(&f, ds, &err) == SL_OK);
    SL_CHECK(f.lo[2] == -1 && f.hi[2] == 3 && f.hi[0] == 2);
    sl_flow_field_helix(&h, 1.0, 0.5, f.lo, f.hi);
    uint64_t rng = 7;
    double worst = 0;
    for (int s = 0; s < 1000; s++) {
        double p[3];
        for (int a = 0; a < 3; a++) {
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            p[a] = f.lo[a] + (f.hi[a] - f.lo[a]) * (double)(rng >> 11) / 9007199254740992.0;
        }
        if (s < 8)
            for (int a = 0; a < 3; a++)
                p[a] = (s >> a) & 1 ? f.hi[a] : f.lo[a];
        double v[3], w[3];
        SL_CHECK(sl_flow_sample(&f, p, NULL, v) == 0);
        sl_flow_sample(&h, p, NULL, w);
        for (int c = 0; c < 3; c++)
            if (fabs(v[c] - w[c]) > worst)
                worst = fabs(v[c] - w[c]);
    }
    SL_CHECK_NEAR(worst, 0, 1e-14);
    double out[3] = {2.0001, 0, 0}, v[3];
    SL_CHECK(sl_flow_sample(&f, out, NULL, v) == -1);
    SL_CHECK_NEAR(sl_flow_local_size(&f, org, NULL), 0.125, 0);
    const double seeds[6] = {1.0, 0.3, 0.0, -0.5, 1.2, 1.0};
    sl_flow_options o = {.solver = SL_FLOW_RK4, .mode = SL_FLOW_STEP_FIXED, .step = 0.05, .t_max = 3.0};
    sl_flow_result a, b;
    SL_CHECK(sl_flow_trace(&f, seeds, 2, &o, &a, &err) == SL_OK);
    SL_CHECK(sl_flow_trace(&h, seeds, 2, &o, &b, &err) == SL_OK);
    SL_CHECK_NEAR(max_diff(&a, &b), 0, 1e-12);
    /* Tangents of the line set are the velocities. */
    sl_dataset *lines = NULL;
    SL_CHECK(sl_flow_result_to_dataset(&a, "t", &lines, &err) == SL_OK);
    if (lines) {
        SL_CHECK(lines->lines.line_count == 2 && lines->lines.vertex_count == a.lines[0].count + a.lines[1].count);
        SL_CHECK_NEAR(lines->lines.tangents[3], (float)a.lines[0].v[3], 0);
        SL_CHECK_NEAR(lines->origin.x + lines->lines.positions[3], a.lines[0].x[3], 1e-6);
        sl_dataset_destroy(lines);
    }
    sl_flow_result_free(&a);
    sl_flow_result_free(&b);
    sl_dataset_destroy(ds);

    /* NaN voxel in the middle: a line through it stops with NAN. */
    ds = helix_volume(dims, org, sp, 1);
    SL_CHECK(ds && sl_flow_field_from_dataset(&f, ds, &err) == SL_OK);
    const double centre[3] = {0.0, 0.0, 1.0};
    SL_CHECK(sl_flow_trace(&f, centre, 1, &o, &a, &err) == SL_OK);
    SL_CHECK(a.lines[0].stop == SL_FLOW_STOP_NAN);
    sl_flow_result_free(&a);
    sl_dataset_destroy(ds);
}

static void helix_coef(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)user;
    (void)ijk;
    coef[0] = -g[1];
    coef[1] = g[0];
    coef[2] = 0.5;
}

static void test_lr(void)
{
    const double k1[] = {-2, -2, -1, 0, 0.5, 2, 2};
    const double kz1[] = {-1, -1, 1, 3, 3};
    const double k2[] = {-2, -2, -2, -1, 0, 0.5, 2, 2, 2};
    const double kz2[] = {-1, -1, -1, 0.25, 3, 3, 3};
    for (int deg = 1; deg <= 2; deg++) {
        const int order[3] = {deg + 1, deg + 1, deg + 1};
        const double *kn[3] = {deg == 1 ? k1 : k2, deg == 1 ? k1 : k2, deg == 1 ? kz1 : kz2};
        const int count[3] = {deg == 1 ? 7 : 9, deg == 1 ? 7 : 9, deg == 1 ? 5 : 7};
        sl_lr_volume *lr = calloc(1, sizeof *lr);
        sl_err err = {0};
        SL_CHECK_MSG(sl_lr_tensor_product(lr, order, 3, kn, count, helix_coef, NULL, &err) == SL_OK, "%s",
                     err.message);
        sl_dataset *ds = sl_dataset_create(SL_DATASET_LR, "lr");
        ds->lr = lr;
        sl_flow_field f, h;
        SL_CHECK(sl_flow_field_from_dataset(&f, ds, &err) == SL_OK);
        sl_flow_field_helix(&h, 1.0, 0.5, f.lo, f.hi);
        /* Heuristic size: the element [0, 0.5] x [0, 0.5] x [..] holds (0.1, 0.1, z). */
        const double p[3] = {0.1, 0.1, 2.0};
        double zside = deg == 1 ? 2.0 : 2.75;
        double expect = (0.5 < zside ? 0.5 : zside) / (deg == 1 ? 2.0 : 4.0);
        SL_CHECK_NEAR(sl_flow_local_size(&f, p, NULL), expect, 1e-15);
        const double seeds[6] = {1.0, 0.3, -0.5, -0.5, 1.2, 1.0};
        for (int s = 0; s < SL_FLOW_SOLVER_COUNT; s++) {
            sl_flow_options o = {.solver = s, .t_max = 6.0};
            if (sl_flow_methods[s].embedded_order) {
                o.mode = SL_FLOW_STEP_ADAPTIVE;
                o.tol = s == SL_FLOW_HE ? 1e-5 : 1e-7;
            } else {
                o.mode = SL_FLOW_STEP_HEURISTIC;
                o.step = 0.2;
            }
            sl_flow_result a, b;
            SL_CHECK(sl_flow_trace(&f, seeds, 2, &o, &a, &err) == SL_OK);
            SL_CHECK(sl_flow_trace(&h, seeds, 2, &o, &b, &err) == SL_OK);
            if (o.mode == SL_FLOW_STEP_HEURISTIC) {
                /* The helix field's stand-in size differs: compare against the exact helix instead. */
                double e = worst_sample_error(&h, &a, seeds);
                double bound = s == SL_FLOW_RK1 ? 0.5 : s == SL_FLOW_RK2 ? 1e-2 : 1e-3;
                SL_CHECK_MSG(e <= bound, "LR deg %d %s heuristic: error %.3g", deg, sl_flow_methods[s].name, e);
            } else {
                SL_CHECK_MSG(max_diff(&a, &b) <= 1e-9, "LR deg %d %s: %.3g", deg, sl_flow_methods[s].name,
                             max_diff(&a, &b));
            }
            SL_CHECK_MSG(a.lines[0].stop == SL_FLOW_STOP_BOUNDARY || a.lines[0].stop == SL_FLOW_STOP_TIME,
                         "LR deg %d %s: stop %s", deg, sl_flow_methods[s].name, sl_flow_stop_name(a.lines[0].stop));
            sl_flow_result_free(&a);
            sl_flow_result_free(&b);
        }
        sl_dataset_destroy(ds);
    }
    /* A scalar LR volume is refused. */
    sl_dataset *lines = sl_dataset_create(SL_DATASET_LINES, "l");
    sl_flow_field f;
    sl_err err = {0};
    SL_CHECK(sl_flow_field_from_dataset(&f, lines, &err) == SL_ERR_INVALID);
    sl_dataset_destroy(lines);
}

static void test_seeds_and_metric(void)
{
    const char csv[] = "x,y,z\n# comment\n1, 2, 3\n\n4,5,6\r\n";
    double *s;
    size_t n;
    sl_err err = {0};
    SL_CHECK(sl_flow_seeds_csv(csv, strlen(csv), &s, &n, &err) == SL_OK);
    SL_CHECK(n == 2 && s[0] == 1 && s[5] == 6);
    free(s);
    const char bad[] = "1,2,3\n1,2\n";
    SL_CHECK(sl_flow_seeds_csv(bad, strlen(bad), &s, &n, &err) == SL_ERR_FORMAT);
    SL_CHECK(strstr(err.message, "line 2") != NULL);
    SL_CHECK(sl_flow_seeds_box("0,0,0,1,2,4,5", &s, &n, &err) == SL_OK);
    SL_CHECK(n == 5 && s[0] == 0.5 && s[1] == 2.0 / 3.0 && s[2] == 0.8 && s[3] == 0.25);
    free(s);
    SL_CHECK(sl_flow_seeds_box("0,0,0,1,2,4,0", &s, &n, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_flow_seeds_plane("0,0,1,2,0,0,0,4,0,2,2", &s, &n, &err) == SL_OK);
    SL_CHECK(n == 4 && s[0] == 0.5 && s[1] == 1.0 && s[2] == 1 && s[3] == 1.5 && s[10] == 3.0);
    free(s);
    /* Eq. 7 against the exact helix: a line y = exact + (d, 0, 0) over t in
     * [0, 1] sampled at 0, 0.5, 1 gives E = 0.5 d + 0.5 d = d. */
    sl_flow_field f;
    sl_flow_field_helix(&f, 1.0, 0.5, box_lo, box_hi);
    double t[3] = {0, 0.5, 1}, x[9], v[9] = {0};
    const double seed[3] = {1, 0, 0};
    for (int i = 0; i < 3; i++) {
        sl_flow_helix_exact(&f, seed, t[i], x + 3 * i);
        x[3 * i] += 1e-3;
    }
    sl_flow_line y = {.count = 3, .t = t, .x = x, .v = v};
    /* Reference: the exact samples with exact velocities, interpolated. */
    double rt[201], rx[603], rv[603];
    for (int i = 0; i <= 200; i++) {
        rt[i] = i / 200.0;
        sl_flow_helix_exact(&f, seed, rt[i], rx + 3 * i);
        sl_flow_sample(&f, rx + 3 * i, NULL, rv + 3 * i);
    }
    sl_flow_line ref = {.count = 201, .t = rt, .x = rx, .v = rv};
    SL_CHECK_NEAR(sl_flow_line_error(&y, &ref, NULL, NULL, 0), 1e-3, 1e-12);
}

/* The step control's root against pow in long double: within 1 ulp (plus
 * the long double's own rounding) for n = 1..8 over [1e-10, 1e10]. */
static void test_step_root(void)
{
    for (int n = 1; n <= 8; n++) {
        double worst = 0;
        for (int i = 0; i <= 20000; i++) {
            double r = pow(10.0, -10.0 + 20.0 * i / 20000.0);
            long double t = powl((long double)r, 1.0L / n);
            double y = sl_flow_step_root(r, n), ulp = nextafter((double)t, INFINITY) - (double)t;
            double e = (double)(fabsl((long double)y - t) / ulp);
            worst = e > worst ? e : worst;
        }
        SL_CHECK_MSG(worst <= 1.0, "sl_flow_step_root n = %d: %.3g ulp from the root", n, worst);
    }
    SL_CHECK(sl_flow_step_root(1e-10, 5) > 0 && sl_flow_step_root(32.0, 5) == 2.0 && sl_flow_step_root(0.25, 2) == 0.5);
}

/* The schema names are the table's, in order, and find takes each back. */
static void test_names(void)
{
    for (int i = 0; i < SL_FLOW_SOLVER_COUNT; i++)
        SL_CHECK(sl_flow_solver_names[i] && strcmp(sl_flow_solver_names[i], sl_flow_methods[i].name) == 0 &&
                 sl_flow_solver_find(sl_flow_solver_names[i]) == i);
    SL_CHECK(sl_flow_solver_names[SL_FLOW_SOLVER_COUNT] == NULL);
}

int main(void)
{
    test_step_root();
    test_names();
    test_orders();
    test_adaptive();
    test_boundary_and_degenerate();
    test_regular();
    test_lr();
    test_seeds_and_metric();
    SL_TEST_END();
}
