/* test_flow_gpu_lr.c — the compute-shader integrator on LR-spline vector
 * volumes (flow_field_lr.glsl, flow_gpu.c) against the CPU double reference
 * (flow_trace.c on the same sl_lr_volume, sl_lr_eval from the LR basis).
 * Field: the rotation v = (-y, x, 0.2) on [-1.1, 0.9] x [-1, 1] x [0, 1]
 * (x bounds not floats: lines leaving through x = 0.9 or -1.1 end on the
 * double face while the look-up's float box lies inside it), reproduced
 * exactly by a degree-1 tensor product (coefficients = v at the Greville
 * points = the knots) on uneven, non-dyadic knots (so float boxes are
 * rounded), and the same model locally refined by sl_lr_refine (three mesh
 * rectangles, so lines cross elements of different sizes and the look-up
 * works on a refined mesh), and the refined model with its coefficients
 * perturbed (0.05 sin(...)), a field that differs from element to element,
 * so the GPU must evaluate the element the CPU does. 16 Halton seeds and
 * 2 that leave through the x faces, t_max 2 (several lines leave the box:
 * the boundary clip runs). RK4 with a fixed step h = 0.05 and the
 * heuristic step (H = 0.5 times the element's min side / 2); sample by
 * sample, max |x_gpu - x_cpu| / (box side 2): double <= 1e-12, mixed <=
 * 1e-7, single <= 1e-5, the last samples too; the same stop reasons; sample
 * counts within +-1: the boundary bisection can end an ulp inside the face
 * (then one Euler step onto it) or exactly on it (no step), measured on the
 * CPU at x = 0.89999999999999969 and on the GPU at 0.9 in double, both then
 * ending on x = 0.9. The CPU line is also checked against
 * the exact rotation (rk4 at h = 0.05: <= 1e-6), so the reference is right.
 * The seed box avoids knots: a seed on a knot, -0.7 in double, is -0.699999988
 * in float, in the next element, so the single heuristic step differs there
 * (measured 1e-2 relative): an inherent limit of single precision.
 * Adaptive he (tol 1e-5), bs (1e-7), rkf45 (1e-9) on the same 18 seeds,
 * judged by Eq. 7 (sl_flow_error) against a fine CPU reference (RKF5, h =
 * 1e-3, double): every GPU precision within 2 x the CPU run's E plus 1e-12
 * (double), 2e-7 (mixed; measured up to 4.6e-8 above, rkf45 at 1e-9, where
 * the float evaluation is the floor) or 2e-6 (single; measured up to
 * 2.8e-7); same stop reasons. GPU double against the CPU run itself: E <=
 * 1e-12 on the tensor and refined models (measured <= 3.1e-15), <= 1e-12 +
 * E_cpu / 2 on the perturbed one (measured up to 7.2e-8, rkf45): its
 * coefficients are not exact, so the CPU's LR-basis and the GPU's Bézier
 * values differ by ~1e-14, the error estimate's cancellation (err ~ tol =
 * 1e-9 from O(1) stage values) turns that into ~1e-8 relative in the next
 * step, and accept/reject decisions then part (counts differ by a few
 * samples on 7 of 18 lines). Fixed steps and the step control itself are
 * the CPU's (test_flow_gpu: double adaptive bit for bit on one field).
 * Borrowed blocks (sl_flow_gpu_create_lr: a k-d tree look-up, uploaded in
 * float, the double copies added later) trace the same lines bit for bit in
 * every precision; mixed before the double copies is refused.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "flow/flow_gpu.h"
#include "gpu/sl_gpu.h"
#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_refine.h"
#include "sl_test.h"

static void rotation(void *user, const int ijk[3], const double g[3], double *coef)
{
    (void)user;
    (void)ijk;
    coef[0] = -g[1];
    coef[1] = g[0];
    coef[2] = 0.2;
}

static int rotation_model(sl_lr_volume *lr, int refine)
{
    static const double kx[] = {-1.1, -1.1, -0.7, -0.1, 0.35, 0.8, 0.9, 0.9};
    static const double ky[] = {-1, -1, -0.55, 0.15, 0.6, 1, 1};
    static const double kz[] = {0, 0, 0.45, 1, 1};
    const double *k[3] = {kx, ky, kz};
    const int count[3] = {8, 7, 5}, order[3] = {2, 2, 2};
    sl_err err = {0};
    if (sl_lr_tensor_product(lr, order, 3, k, count, rotation, NULL, &err) != SL_OK) {
        fprintf(stderr, "tensor product: %s\n", err.message);
        return 0;
    }
    if (!refine)
        return 1;
    const sl_lr_meshrect r[3] = {
        {{0.1, -1, 0}, {0.1, 0.15, 1}, 1},     /* x = 0.1 in the lower half */
        {{-0.7, 0.3, 0}, {0.35, 0.3, 0.45}, 1}, /* y = 0.3, lower z */
        {{-0.1, -0.55, 0.2}, {0.35, 0.6, 0.2}, 1}, /* z = 0.2 */
    };
    if (sl_lr_refine(lr, r, 3, &err) != SL_OK) {
        fprintf(stderr, "refine: %s\n", err.message);
        sl_lr_free(lr);
        return 0;
    }
    if (refine == 2) /* a field that differs per element: the right element matters */
        for (size_t b = 0; b < lr->basis_count; b++)
            for (int c = 0; c < 3; c++)
                lr->basis[b].coef[c] += 0.05 * sin(1.7 * (double)b + (double)c);
    return 1;
}

static void compare(const sl_flow_result *g, const sl_flow_result *c, double bound, int slack,
                    const char *what)
{
    double worst = 0;
    int count_ok = 1, stop_ok = 1;
    for (size_t j = 0; j < c->line_count; j++) {
        const sl_flow_line *a = &g->lines[j], *b = &c->lines[j];
        long dc = (long)a->count - (long)b->count;
        if (dc < -slack || dc > slack)
            count_ok = 0;
        if (a->stop != b->stop)
            stop_ok = 0;
        size_t n = a->count < b->count ? a->count : b->count;
        if (dc != 0 && n > 0)
            n--;                                  /* the last samples differ in time */
        for (size_t i = 0; i < 3 * n; i++) {
            double e = fabs(a->x[i] - b->x[i]) / 2.0;
            if (!(e <= worst))
                worst = e;
        }
        for (int k = 0; dc != 0 && a->count > 0 && b->count > 0 && k < 3; k++) { /* the last samples */
            double e = fabs(a->x[3 * (a->count - 1) + k] - b->x[3 * (b->count - 1) + k]) / 2.0;
            if (!(e <= worst))
                worst = e;
        }
    }
    SL_CHECK_MSG(worst <= bound, "%s: max relative difference %.3g > %.3g", what, worst, bound);
    SL_CHECK_MSG(count_ok, "%s: sample counts differ", what);
    SL_CHECK_MSG(stop_ok, "%s: stop reasons differ", what);
    printf("%s: max relative difference %.3g\n", what, worst);
}

/* The CPU samples against the exact rotation about z at speed 0.2 in z. */
static double exact_error(const sl_flow_result *c)
{
    double worst = 0;
    for (size_t j = 0; j < c->line_count; j++) {
        const sl_flow_line *l = &c->lines[j];
        for (size_t i = 0; i < l->count; i++) {
            double t = l->t[i], x0 = l->x[0], y0 = l->x[1], z0 = l->x[2];
            double ex[3] = {x0 * cos(t) - y0 * sin(t), x0 * sin(t) + y0 * cos(t), z0 + 0.2 * t};
            for (int k = 0; k < 3; k++) {
                double e = fabs(l->x[3 * i + k] - ex[k]);
                if (!(e <= worst))
                    worst = e;
            }
        }
    }
    return worst;
}

/* Adaptive he, bs, rkf45 on one model: Eq. 7 (sl_flow_error) of the CPU
 * run and of each GPU precision against a fine CPU reference (RKF5, h =
 * 1e-3, double, on the same model), and of the GPU double run against the
 * CPU run itself; the same stop reasons. Bounds in the header. */
static void check_adaptive(const sl_flow_field *f, sl_flow_gpu *g, const double *seeds, size_t n, const char *model,
                           int kinks)
{
    static const struct { sl_flow_solver solver; double tol; } runs[3] = {
        {SL_FLOW_HE, 1e-5}, {SL_FLOW_BS, 1e-7}, {SL_FLOW_RKF45, 1e-9}};
    sl_err err = {0};
    sl_flow_options ro = {.solver = SL_FLOW_RKF5, .mode = SL_FLOW_STEP_FIXED, .step = 1e-3, .t_max = 2.0,
                          .max_samples = 4000};
    sl_flow_result ref;
    SL_CHECK(sl_flow_trace(f, seeds, n, &ro, &ref, &err) == SL_OK);
    for (int r = 0; r < 3; r++) {
        sl_flow_options o = {.solver = runs[r].solver, .mode = SL_FLOW_STEP_ADAPTIVE, .tol = runs[r].tol,
                             .t_max = 2.0, .max_samples = 4000};
        sl_flow_result cpu;
        SL_CHECK(sl_flow_trace(f, seeds, n, &o, &cpu, &err) == SL_OK);
        double e_cpu = sl_flow_error(&cpu, &ref, NULL, NULL);
        printf("%s %s tol %g cpu: E %.3g\n", model, sl_flow_methods[o.solver].name, o.tol, e_cpu);
        for (int p = SL_FLOW_SINGLE; p <= SL_FLOW_DOUBLE; p++) {
            sl_flow_result gr;
            sl_status st = sl_flow_gpu_trace(g, seeds, n, &o, (sl_flow_precision)p, &gr, NULL, &err);
            SL_CHECK_MSG(st == SL_OK, "%s", err.message);
            if (st != SL_OK)
                continue;
            const char *pn = sl_flow_precision_name((sl_flow_precision)p);
            int stops = 1;
            size_t same_count = 0;
            for (size_t j = 0; j < n; j++) {
                stops &= gr.lines[j].stop == cpu.lines[j].stop;
                same_count += gr.lines[j].count == cpu.lines[j].count;
            }
            double e = sl_flow_error(&gr, &ref, NULL, NULL), e_vs_cpu = sl_flow_error(&gr, &cpu, NULL, NULL);
            double slack = p == SL_FLOW_DOUBLE ? 1e-12 : p == SL_FLOW_MIXED ? 2e-7 : 2e-6;
            printf("%s %s %s: E %.3g, against the CPU run %.3g, %zu of %zu lines with the CPU's sample count\n",
                   model, sl_flow_methods[o.solver].name, pn, e, e_vs_cpu, same_count, n);
            SL_CHECK_MSG(stops, "%s %s %s: stop reasons differ", model, sl_flow_methods[o.solver].name, pn);
            SL_CHECK_MSG(e <= 2.0 * e_cpu + slack, "%s %s %s: E %.3g > 2 x the CPU's %.3g + %.0e", model,
                         sl_flow_methods[o.solver].name, pn, e, e_cpu, slack);
            double vs_bound = 1e-12 + (kinks ? 0.5 * e_cpu : 0.0);
            if (p == SL_FLOW_DOUBLE)
                SL_CHECK_MSG(e_vs_cpu <= vs_bound, "%s %s double: E against the CPU run %.3g > %.3g", model,
                             sl_flow_methods[o.solver].name, e_vs_cpu, vs_bound);
            sl_flow_result_free(&gr);
        }
        sl_flow_result_free(&cpu);
    }
    sl_flow_result_free(&ref);
}

/* The lines of two traces are the same bit for bit. */
static int same_lines(const sl_flow_result *a, const sl_flow_result *b)
{
    if (a->line_count != b->line_count)
        return 0;
    for (size_t j = 0; j < a->line_count; j++) {
        const sl_flow_line *p = &a->lines[j], *q = &b->lines[j];
        if (p->count != q->count || p->stop != q->stop ||
            (p->count && (memcmp(p->t, q->t, p->count * sizeof *p->t) != 0 ||
                          memcmp(p->x, q->x, 3 * p->count * sizeof *p->x) != 0 ||
                          memcmp(p->v, q->v, 3 * p->count * sizeof *p->v) != 0)))
            return 0;
    }
    return 1;
}

/* Borrowed blocks (sl_flow_gpu_create_lr, as lr_volume shares its own):
 * blocks with another look-up (one k-d tree) uploaded in float only trace
 * single precision exactly as the flow's own blocks; mixed is refused until
 * sl_lr_bezier_upload_double adds the double copies, then mixed and double
 * equal the own blocks' traces bit for bit too. */
static void check_borrowed(const sl_lr_volume *lr, const sl_flow_field *f, sl_flow_gpu *own, const double *seeds,
                           size_t n, const char *model)
{
    sl_err err = {0};
    sl_lr_bezier bz;
    sl_lr_bezier_gpu blocks;
    if (sl_lr_bezier_build(lr, SL_LR_LOOKUP_KDTREE, 0, &bz, &err) != SL_OK) {
        SL_CHECK_MSG(0, "%s: blocks: %s", model, err.message);
        return;
    }
    sl_flow_gpu *g = NULL;
    sl_status st = sl_lr_bezier_upload(&bz, 0, &blocks, &err);
    if (st == SL_OK)
        st = sl_flow_gpu_create_lr(f, &bz, &blocks, &g, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: borrowed blocks: %s", model, err.message);
    const sl_flow_options o = {.solver = SL_FLOW_RK4, .t_max = 2.0, .max_samples = 400,
                               .mode = SL_FLOW_STEP_HEURISTIC, .step = 0.5};
    for (int p = SL_FLOW_SINGLE; g && p <= SL_FLOW_DOUBLE; p++) {
        sl_flow_result a = {0}, b = {0};
        if (p == SL_FLOW_MIXED) {
            st = sl_flow_gpu_trace(g, seeds, n, &o, SL_FLOW_MIXED, &b, NULL, &err);
            SL_CHECK_MSG(st == SL_ERR_INVALID && strstr(err.message, "double"),
                         "%s: mixed on float-only borrowed blocks: %d %s", model, st, err.message);
            sl_flow_result_free(&b);
            SL_CHECK_MSG(sl_lr_bezier_upload_double(&bz, &blocks, &err) == SL_OK, "%s", err.message);
        }
        SL_CHECK(sl_flow_gpu_trace(own, seeds, n, &o, (sl_flow_precision)p, &a, NULL, &err) == SL_OK);
        st = sl_flow_gpu_trace(g, seeds, n, &o, (sl_flow_precision)p, &b, NULL, &err);
        SL_CHECK_MSG(st == SL_OK, "%s: borrowed %s: %s", model, sl_flow_precision_name((sl_flow_precision)p),
                     err.message);
        SL_CHECK_MSG(st != SL_OK || same_lines(&a, &b), "%s: borrowed k-d tree blocks trace other %s lines", model,
                     sl_flow_precision_name((sl_flow_precision)p));
        sl_flow_result_free(&a);
        sl_flow_result_free(&b);
    }
    printf("%s: borrowed blocks (k-d tree) trace the own blocks' lines bit for bit\n", model);
    sl_flow_gpu_destroy(g);
    sl_lr_bezier_release(&blocks);
    sl_lr_bezier_free(&bz);
}

int main(void)
{
    sl_gpu *gpu = NULL;
    sl_err err = {0};
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err);
    SL_CHECK_MSG(st == SL_OK, "no GL 4.5 context: %s", err.message);
    if (st != SL_OK)
        SL_TEST_END();
    static const char *names[3] = {"tensor", "refined", "refined perturbed"};
    double *seeds;
    size_t n;
    SL_CHECK(sl_flow_seeds_box("-0.79,-0.77,0.05,0.81,0.79,0.6,16", &seeds, &n, &err) == SL_OK);
    /* Two more seeds whose lines leave through the faces x = 0.9 and x = -1.1
     * (not floats: the look-up's float box lies inside the double domain). */
    static const double face_seeds[6] = {0.5, -0.8, 0.3, -0.8, 0.85, 0.3};
    double *more = seeds ? realloc(seeds, (3 * n + 6) * sizeof *seeds) : NULL;
    SL_CHECK(more != NULL);
    if (!more)
        SL_TEST_END();
    seeds = more;
    memcpy(seeds + 3 * n, face_seeds, sizeof face_seeds);
    n += 2;
    for (int refine = 0; refine < 3; refine++) {
        sl_lr_volume lr;
        SL_CHECK(rotation_model(&lr, refine));
        printf("%s model: %zu elements, %zu basis functions\n", names[refine],
               lr.element_count, lr.basis_count);
        sl_dataset ds = {.kind = SL_DATASET_LR, .lr = &lr};
        snprintf(ds.name, sizeof ds.name, "rotation");
        sl_flow_field f;
        SL_CHECK(sl_flow_field_from_dataset(&f, &ds, &err) == SL_OK);
        sl_flow_gpu *g = NULL;
        st = sl_flow_gpu_create(&f, &g, &err);
        SL_CHECK_MSG(st == SL_OK, "%s", err.message);
        for (int mode = 0; g && mode < 2; mode++) {
            sl_flow_options o = {.solver = SL_FLOW_RK4, .t_max = 2.0, .max_samples = 400,
                                 .mode = mode ? SL_FLOW_STEP_HEURISTIC : SL_FLOW_STEP_FIXED,
                                 .step = mode ? 0.5 : 0.05};
            sl_flow_result cpu;
            SL_CHECK(sl_flow_trace(&f, seeds, n, &o, &cpu, &err) == SL_OK);
            for (size_t j = n - 2; j < n; j++) { /* the face seeds end on their x face */
                const sl_flow_line *l = &cpu.lines[j];
                double face = j == n - 2 ? 0.9 : -1.1;
                SL_CHECK_MSG(l->stop == SL_FLOW_STOP_BOUNDARY && l->count > 0 && l->x[3 * (l->count - 1)] == face,
                             "line %zu: stop %d, does not end on x = %g", j, (int)l->stop, face);
            }
            if (!mode && refine < 2) {
                double e = exact_error(&cpu);
                SL_CHECK_MSG(e <= 1e-6, "cpu rk4 vs the exact rotation: %.3g", e);
                printf("cpu vs exact: %.3g\n", e);
            }
            for (int p = SL_FLOW_SINGLE; p <= SL_FLOW_DOUBLE; p++) {
                sl_flow_result gr;
                st = sl_flow_gpu_trace(g, seeds, n, &o, (sl_flow_precision)p, &gr, NULL, &err);
                SL_CHECK_MSG(st == SL_OK, "%s", err.message);
                if (st != SL_OK)
                    continue;
                char what[96];
                snprintf(what, sizeof what, "%s rk4 %s %s", names[refine],
                         mode ? "heuristic" : "fixed", sl_flow_precision_name((sl_flow_precision)p));
                double bound = p == SL_FLOW_DOUBLE ? 1e-12 : p == SL_FLOW_MIXED ? 1e-7 : 1e-5;
                compare(&gr, &cpu, bound, 1, what);
                sl_flow_result_free(&gr);
            }
            sl_flow_result_free(&cpu);
        }
        if (g)
            check_adaptive(&f, g, seeds, n, names[refine], refine == 2);
        if (g)
            check_borrowed(&lr, &f, g, seeds, n, names[refine]);
        sl_flow_gpu_destroy(g);
        sl_lr_free(&lr);
    }
    free(seeds);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
