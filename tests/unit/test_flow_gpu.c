/* test_flow_gpu.c — the compute-shader integrators (renderer/flow/flow_gpu.c)
 * against the CPU double reference (flow_trace.c) on a regular vector field:
 * the ABC flow (A = sqrt 3, B = sqrt 2, C = 1) sampled at 33^3 voxel centres
 * on [0, 2 pi]^3, 64 Halton seeds, t_max 1.5 (the flow separates nearby
 * lines, so longer runs amplify float rounding; some lines leave the box,
 * so the boundary clip runs too). Fixed-step solvers, sample by sample,
 * max |x_gpu - x_cpu| / (box side 2 pi): double <= 1e-12, mixed and single
 * <= 1e-5, the same stop reasons and sample counts (single/mixed: +-1
 * sample, a float time can land a hair short of t_max). Adaptive solvers
 * in double: the CPU's steps, sample by sample <= 1e-12 with the same
 * counts (measured 0: bit for bit on llvmpipe). They used to part (1e-13
 * relative in h at the 7th step, then other accept/reject decisions): the
 * CPU took libm pow(r, 1.0 / 3), the GPU a Newton root from a float pow,
 * an ulp apart, amplified by the cancellation in the error estimate; both
 * now run sl_flow_step_root's operations. Single and mixed adaptive
 * runs take other steps (float field values), so they are checked against a
 * fine reference (RKF5, h = 1e-3, double) interpolated by cubic Hermite at
 * their own times: GPU error <= 2 x the CPU adaptive run's error + 1e-5,
 * and the same stop reasons. Also: an LR field without a model of dim 3 is
 * refused, mixed/double programs compile, the GPU never hangs on a seed
 * outside or NaN.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "flow/flow_gpu.h"
#include "gpu/sl_gpu.h"
#include "sl_test.h"

static sl_dataset *abc_volume(int n)
{
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VECTORS, "abc");
    sl_err err = {0};
    const int dims[3] = {n, n, n};
    if (!ds || sl_volume_alloc(&ds->volume, dims, 3, SL_VOXEL_F32, &err) != SL_OK)
        return NULL;
    double h = 2 * M_PI / (n - 1);
    for (int a = 0; a < 3; a++)
        ds->volume.spacing[a] = h;
    float *d = ds->volume.data;
    const double A = sqrt(3.0), B = sqrt(2.0), C = 1.0;
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                size_t v = ((size_t)k * n + j) * n + i;
                double x = i * h, y = j * h, z = k * h;
                d[3 * v] = (float)(A * sin(z) + C * cos(y));
                d[3 * v + 1] = (float)(B * sin(x) + A * cos(z));
                d[3 * v + 2] = (float)(C * sin(y) + B * cos(x));
            }
    if (sl_dataset_finish_volume(ds, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

/* The CPU line at time t by cubic Hermite on its samples (the test's own). */
static void cpu_at(const sl_flow_line *b, double t, double x[3])
{
    size_t i = 0;
    while (i + 2 < b->count && b->t[i + 1] < t)
        i++;
    if (b->count < 2 || t >= b->t[b->count - 1]) {
        memcpy(x, b->x + 3 * (b->count - 1), 3 * sizeof *x);
        return;
    }
    double dt = b->t[i + 1] - b->t[i], u = (t - b->t[i]) / dt;
    double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u);
    double h01 = u * u * (3 - 2 * u), h11 = u * u * (u - 1);
    for (int c = 0; c < 3; c++)
        x[c] = h00 * b->x[3 * i + c] + h10 * dt * b->v[3 * i + c] + h01 * b->x[3 * i + 3 + c] +
               h11 * dt * b->v[3 * i + 3 + c];
}

static double max_interpolated(const sl_flow_result *g, const sl_flow_result *c)
{
    double worst = 0;
    for (size_t j = 0; j < c->line_count; j++) {
        const sl_flow_line *a = &g->lines[j], *b = &c->lines[j];
        for (size_t i = 0; i < a->count && b->count > 0; i++) {
            double x[3];
            cpu_at(b, a->t[i], x);
            for (int k = 0; k < 3; k++) {
                double e = fabs(a->x[3 * i + k] - x[k]);
                if (!(e <= worst))
                    worst = e;
            }
        }
    }
    return worst;
}

/* Adaptive: the samples against the fine reference interpolated at their
 * times (absolute). */
static void compare_interpolated(const sl_flow_result *g, const sl_flow_result *c, double bound,
                                 const char *what)
{
    double worst = 0;
    int stop_ok = 1;
    for (size_t j = 0; j < c->line_count; j++) {
        const sl_flow_line *a = &g->lines[j], *b = &c->lines[j];
        if (a->stop != b->stop)
            stop_ok = 0;
        for (size_t i = 0; i < a->count && b->count > 0; i++) {
            double x[3];
            cpu_at(b, a->t[i], x);
            for (int k = 0; k < 3; k++) {
                double e = fabs(a->x[3 * i + k] - x[k]);
                if (!(e <= worst))
                    worst = e;
            }
        }
    }
    SL_CHECK_MSG(worst <= bound, "%s: max difference %.3g > %.3g", what, worst, bound);
    SL_CHECK_MSG(stop_ok, "%s: stop reasons differ", what);
    printf("%s: max difference (interpolated) %.3g\n", what, worst);
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
            double e = fabs(a->x[i] - b->x[i]) / (2 * M_PI);
            if (!(e <= worst))
                worst = e;
        }
    }
    SL_CHECK_MSG(worst <= bound, "%s: max relative difference %.3g > %.3g", what, worst, bound);
    SL_CHECK_MSG(count_ok, "%s: sample counts differ", what);
    SL_CHECK_MSG(stop_ok, "%s: stop reasons differ", what);
    printf("%s: max relative difference %.3g\n", what, worst);
}

int main(void)
{
    sl_gpu *gpu = NULL;
    sl_err err = {0};
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err);
    SL_CHECK_MSG(st == SL_OK, "no GL 4.5 context: %s", err.message);
    if (st != SL_OK)
        SL_TEST_END();
    sl_dataset *ds = abc_volume(33);
    SL_CHECK(ds != NULL);
    sl_flow_field f;
    SL_CHECK(sl_flow_field_from_dataset(&f, ds, &err) == SL_OK);
    sl_flow_gpu *g = NULL;
    SL_CHECK_MSG(sl_flow_gpu_create(&f, &g, &err) == SL_OK, "%s", err.message);
    double *seeds;
    size_t n;
    SL_CHECK(sl_flow_seeds_box("0.3,0.3,0.3,5.9,5.9,5.9,64", &seeds, &n, &err) == SL_OK);
    /* A fine reference for the adaptive single / mixed runs. */
    sl_flow_options ro = {.solver = SL_FLOW_RKF5, .mode = SL_FLOW_STEP_FIXED, .step = 1e-3, .t_max = 1.5,
                          .max_samples = 4000};
    sl_flow_result ref;
    SL_CHECK(sl_flow_trace(&f, seeds, n, &ro, &ref, &err) == SL_OK);
    for (int s = 0; g && s < SL_FLOW_SOLVER_COUNT; s++) {
        sl_flow_options o = {.solver = s, .t_max = 1.5, .max_samples = 4000};
        int adaptive = sl_flow_methods[s].embedded_order != 0;
        if (adaptive) {
            o.mode = SL_FLOW_STEP_ADAPTIVE;
            o.tol = s == SL_FLOW_HE ? 1e-4 : 1e-6;
        } else {
            o.mode = SL_FLOW_STEP_FIXED;
            o.step = 0.02;
        }
        sl_flow_result cpu;
        SL_CHECK(sl_flow_trace(&f, seeds, n, &o, &cpu, &err) == SL_OK);
        double cpu_error = adaptive ? max_interpolated(&cpu, &ref) : 0;
        if (adaptive)
            printf("%s cpu: max difference (interpolated) %.3g\n", sl_flow_methods[s].name, cpu_error);
        for (int p = SL_FLOW_SINGLE; p <= SL_FLOW_DOUBLE; p++) {
            sl_flow_result gr;
            st = sl_flow_gpu_trace(g, seeds, n, &o, (sl_flow_precision)p, &gr, NULL, &err);
            SL_CHECK_MSG(st == SL_OK, "%s", err.message);
            if (st != SL_OK)
                continue;
            char what[64];
            snprintf(what, sizeof what, "%s %s", sl_flow_methods[s].name,
                     sl_flow_precision_name((sl_flow_precision)p));
            if (adaptive && p != SL_FLOW_DOUBLE)
                compare_interpolated(&gr, &ref, 2 * cpu_error + 1e-5, what);
            else if (adaptive)
                compare(&gr, &cpu, 1e-12, 0, what);
            else
                compare(&gr, &cpu, p == SL_FLOW_DOUBLE ? 1e-12 : 1e-5, p == SL_FLOW_DOUBLE ? 0 : 1, what);
            sl_flow_result_free(&gr);
        }
        sl_flow_result_free(&cpu);
    }
    sl_flow_result_free(&ref);
    /* Degenerate seeds stop cleanly on the GPU too. */
    const double bad[6] = {-1.0, 1.0, 1.0, NAN, 1.0, 1.0};
    sl_flow_options o = {.solver = SL_FLOW_RKF45, .mode = SL_FLOW_STEP_ADAPTIVE, .tol = 1e-6, .t_max = 4};
    sl_flow_result gr;
    if (g && sl_flow_gpu_trace(g, bad, 2, &o, SL_FLOW_DOUBLE, &gr, NULL, &err) == SL_OK) {
        SL_CHECK(gr.lines[0].stop == SL_FLOW_STOP_SEED_OUTSIDE && gr.lines[0].count == 0);
        SL_CHECK(gr.lines[1].stop == SL_FLOW_STOP_SEED_OUTSIDE && gr.lines[1].count == 0);
        sl_flow_result_free(&gr);
    } else {
        SL_CHECK_MSG(0, "degenerate seeds: %s", err.message);
    }
    /* An LR field without a model of dim 3 is refused with a sentence (LR
     * fields themselves: test_flow_gpu_lr.c). */
    sl_flow_field lr = {.kind = SL_FLOW_FIELD_LR};
    sl_flow_gpu *none = NULL;
    SL_CHECK(sl_flow_gpu_create(&lr, &none, &err) == SL_ERR_UNSUPPORTED && strstr(err.message, "dim 3"));
    free(seeds);
    sl_flow_gpu_destroy(g);
    sl_dataset_destroy(ds);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
