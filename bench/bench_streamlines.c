/* bench-streamlines — run time against error for the streamline solvers
 * (issue 15 "Run time against error"; paper 003 sec. 5.6-5.7, Eq. 7,
 * Fig. 9 and 10).
 *
 * Fields (regular vector volumes, so the GPU can trace them): `helix`, the
 * rotation v = (-y, x, 0.5) at 33x33x17 voxel centres on [-2,2]^2 x [-1,1]
 * (lines leave through z = 1 before t_max, so the boundary clip is timed too)
 * (trilinear reproduces it exactly, so the true error is known: x(t) in
 * closed form), and `abc`, the ABC flow (A = sqrt 3, B = sqrt 2, C = 1)
 * sampled at 33^3 centres on [0, 2 pi]^3 (no generator makes vector volumes,
 * so it is sampled here). 64 Halton seeds (sl_flow_seeds_box), t_max 3
 * (helix) and 2 (abc). Reference: the CPU RKF5 with fixed h = 1e-4 in
 * double; E = Eq. 7 (sl_flow_error: max over lines of sum dt |x - y|, the
 * reference interpolated by cubic Hermite at the run's times); on the helix
 * also E against the exact solution.
 * Fig. 9: fixed-step rk2, rk4, rkf5 at base steps 0.2 / 2^k, k = 0..7, in
 * single, mixed and double on the GPU. Fig. 10: adaptive he, bs, rkf45 at
 * tol 1e-2 .. 1e-10 and the heuristic rk4 / rkf5 (h = H * voxel/2, H = 2^-k
 * ... as base steps) in mixed precision on the GPU. Every row also has the
 * CPU double run's ms. GPU ms: the wall time of the whole trace call, seed
 * upload, dispatch, glFinish and the read-back of the samples ("to
 * read-back"), and of the dispatch to glFinish alone (each variant run once
 * before, so shader compilation is not timed), medians of 3. `cut`: lines
 * stopped by max_samples (4096) before t_max or the
 * boundary — their E covers only the part traced, so such rows are not
 * comparable (the SVG leaves them out).
 * `lr`: an LR-spline vector field, tests/data/lr/refined_quadratic.lr.gz (a
 * file of the reference library: the identity map v(x) = x on [0, 1]^3 as a
 * locally refined quadratic, 1240 elements), whose streamlines x0 e^t are
 * exact; 64 Halton seeds in [0.1, 0.5]^3, t_max 3 (every line leaves through
 * a face first); Fig. 9 rows at h = 0.1 / 2^k, and Fig. 10 rows (adaptive
 * he, bs, rkf45; heuristic rk4 and rkf5 with h = H x the element's min side
 * / 4) in single, mixed and double, each with E against the exact solution.
 * Writes the Markdown tables to stdout and one SVG plot (log E against
 * log ms to read-back) per figure and field into --out DIR (default bench-out).
 * Usage: bench-streamlines [--out DIR] [--only helix|abc|lr] [--quick]
 * Main thread owns the GL context.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/sl_clock.h"
#include "data/sl_dataset_open.h"
#include "flow/flow_gpu.h"
#include "flow/sl_flow.h"
#include "gpu/sl_gpu.h"

typedef struct bench_field {
    const char *name;
    sl_dataset *ds;
    sl_flow_field f;
    double t_max;
    double *seeds;
    size_t seed_count;
    sl_flow_exact_fn exact;      /* the closed form (helix, lr), else NULL */
    double base_step;            /* Fig. 9: h = base_step / 2^k */
    int fig10_precisions;        /* Fig. 10 rows in all precisions (1) or mixed only (0) */
} bench_field;

static sl_dataset *sample_volume(const char *name, const int dims[3], const double org[3], double sp,
                                 int abc)
{
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VECTORS, name);
    sl_err err = {0};
    if (!ds || sl_volume_alloc(&ds->volume, dims, 3, SL_VOXEL_F32, &err) != SL_OK)
        return NULL;
    ds->origin = sl_v3(org[0], org[1], org[2]);
    for (int a = 0; a < 3; a++)
        ds->volume.spacing[a] = sp;
    float *d = ds->volume.data;
    const double A = sqrt(3.0), B = sqrt(2.0), C = 1.0;
    for (int k = 0; k < dims[2]; k++)
        for (int j = 0; j < dims[1]; j++)
            for (int i = 0; i < dims[0]; i++) {
                size_t v = ((size_t)k * dims[1] + j) * dims[0] + i;
                double x = org[0] + i * sp, y = org[1] + j * sp, z = org[2] + k * sp;
                if (abc) {
                    d[3 * v] = (float)(A * sin(z) + C * cos(y));
                    d[3 * v + 1] = (float)(B * sin(x) + A * cos(z));
                    d[3 * v + 2] = (float)(C * sin(y) + B * cos(x));
                } else {
                    d[3 * v] = (float)-y;
                    d[3 * v + 1] = (float)x;
                    d[3 * v + 2] = 0.5f;
                }
            }
    if (sl_dataset_finish_volume(ds, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

static void helix_exact(void *user, size_t line, double t, double x[3])
{
    const bench_field *bf = user;
    sl_flow_field h;
    sl_flow_field_helix(&h, 1.0, 0.5, bf->f.lo, bf->f.hi);
    sl_flow_helix_exact(&h, bf->seeds + 3 * line, t, x);
}

/* v(x) = x: x(t) = x0 e^t. */
static void identity_exact(void *user, size_t line, double t, double x[3])
{
    const bench_field *bf = user;
    for (int c = 0; c < 3; c++)
        x[c] = bf->seeds[3 * line + (size_t)c] * exp(t);
}

static const char *source_dir(void)
{
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    return src ? src : SIGHTLINE_SOURCE_DIR;
}

typedef struct row {
    char label[48];
    int fig;
    const char *precision;
    double param;                /* step, H or tol */
    const char *param_name;
    double E, E_true, gpu_ms, wall_ms, cpu_ms;   /* gpu_ms: dispatch to glFinish; wall_ms: the trace call */
    size_t samples;
    size_t truncated;            /* lines stopped by max_samples before t_max / the boundary */
} row;

#define MAX_ROWS 256

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static int run_one(sl_flow_gpu *g, bench_field *bf, const sl_flow_result *ref, const sl_flow_options *o,
                   sl_flow_precision p, row *r)
{
    sl_err err = {0};
    sl_flow_result res;
    double ms[3];
    if (sl_flow_gpu_trace(g, bf->seeds, bf->seed_count, o, p, &res, NULL, &err) != SL_OK) {
        fprintf(stderr, "bench-streamlines: %s\n", err.message);
        return -1;
    }
    sl_flow_result_free(&res);
    double wall[3];
    for (int k = 0; k < 3; k++) {
        double t0 = sl_clock_ms();
        if (sl_flow_gpu_trace(g, bf->seeds, bf->seed_count, o, p, &res, &ms[k], &err) != SL_OK) {
            fprintf(stderr, "bench-streamlines: %s\n", err.message);
            return -1;
        }
        wall[k] = sl_clock_ms() - t0;
        if (k < 2)
            sl_flow_result_free(&res);
    }
    qsort(ms, 3, sizeof ms[0], cmp_double);
    qsort(wall, 3, sizeof wall[0], cmp_double);
    r->gpu_ms = ms[1];
    r->wall_ms = wall[1];
    r->E = sl_flow_error(&res, ref, NULL, NULL);
    r->E_true = bf->exact ? sl_flow_error(&res, NULL, bf->exact, bf) : NAN;
    r->samples = 0;
    r->truncated = 0;
    for (size_t j = 0; j < res.line_count; j++) {
        r->samples += res.lines[j].count;
        r->truncated += res.lines[j].stop == SL_FLOW_STOP_SAMPLES;
    }
    sl_flow_result_free(&res);
    sl_flow_result cpu;
    double t0 = sl_clock_ms();
    if (sl_flow_trace(&bf->f, bf->seeds, bf->seed_count, o, &cpu, &err) != SL_OK) {
        fprintf(stderr, "bench-streamlines: %s\n", err.message);
        return -1;
    }
    r->cpu_ms = sl_clock_ms() - t0;
    sl_flow_result_free(&cpu);
    return 0;
}

/* A tiny SVG writer: log10 E against log10 ms, one polyline per series. */
static void write_svg(const char *path, const char *title, const row *rows, int n, int fig)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bench-streamlines: cannot write %s\n", path);
        return;
    }
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int i = 0; i < n; i++) {
        if (rows[i].fig != fig || !(rows[i].E > 0) || !(rows[i].wall_ms > 0) || rows[i].truncated)
            continue;
        double x = log10(rows[i].wall_ms), y = log10(rows[i].E);
        x0 = fmin(x0, x), x1 = fmax(x1, x), y0 = fmin(y0, y), y1 = fmax(y1, y);
    }
    if (!(x1 > x0)) x1 = x0 + 1;
    if (!(y1 > y0)) y1 = y0 + 1;
    x0 = floor(x0), x1 = ceil(x1), y0 = floor(y0), y1 = ceil(y1);
    const double W = 640, H = 440, L = 70, R = 170, T = 40, B = 50;
    fprintf(f, "<svg xmlns='http://www.w3.org/2000/svg' width='%g' height='%g' font-family='sans-serif' font-size='12'>\n", W, H);
    fprintf(f, "<rect width='100%%' height='100%%' fill='white'/>\n<text x='%g' y='22' font-size='14'>%s</text>\n", L, title);
#define PX(v) (L + ((v) - x0) / (x1 - x0) * (W - L - R))
#define PY(v) (H - B - ((v) - y0) / (y1 - y0) * (H - T - B))
    fprintf(f, "<rect x='%g' y='%g' width='%g' height='%g' fill='none' stroke='black'/>\n", L, T, W - L - R, H - T - B);
    for (double v = x0; v <= x1 + 1e-9; v += 1)
        fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='#ddd'/><text x='%g' y='%g' text-anchor='middle'>1e%g</text>\n",
                PX(v), T, PX(v), H - B, PX(v), H - B + 16, v);
    for (double v = y0; v <= y1 + 1e-9; v += 1)
        fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='#ddd'/><text x='%g' y='%g' text-anchor='end'>1e%g</text>\n",
                L, PY(v), W - R, PY(v), L - 4, PY(v) + 4, v);
    fprintf(f, "<text x='%g' y='%g' text-anchor='middle'>GPU ms (trace to read-back)</text>\n", (L + W - R) / 2, H - 12);
    fprintf(f, "<text x='16' y='%g' transform='rotate(-90 16 %g)' text-anchor='middle'>E (Eq. 7)</text>\n", (T + H - B) / 2, (T + H - B) / 2);
    static const char *colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#7f7f7f"};
    int series = 0;
    for (int i = 0; i < n; i++) {
        if (rows[i].fig != fig)
            continue;
        int first = 1;
        for (int k = 0; k < i; k++)
            if (rows[k].fig == fig && strcmp(rows[k].label, rows[i].label) == 0 &&
                strcmp(rows[k].precision, rows[i].precision) == 0)
                first = 0;
        if (!first)
            continue;
        const char *c = colors[series % 9];
        int dashed = strcmp(rows[i].precision, "single") == 0;
        fprintf(f, "<polyline fill='none' stroke='%s' stroke-width='1.5'%s points='", c,
                dashed ? " stroke-dasharray='5,3'" : "");
        for (int k = i; k < n; k++)
            if (rows[k].fig == fig && strcmp(rows[k].label, rows[i].label) == 0 &&
                strcmp(rows[k].precision, rows[i].precision) == 0 && rows[k].E > 0 && rows[k].wall_ms > 0 &&
                !rows[k].truncated)
                fprintf(f, "%.1f,%.1f ", PX(log10(rows[k].wall_ms)), PY(log10(rows[k].E)));
        fprintf(f, "'/>\n");
        fprintf(f, "<line x1='%g' y1='%g' x2='%g' y2='%g' stroke='%s' stroke-width='2'%s/><text x='%g' y='%g'>%s %s</text>\n",
                W - R + 10, T + 10 + 16 * series, W - R + 34, T + 10 + 16 * series, c,
                dashed ? " stroke-dasharray='5,3'" : "", W - R + 38, T + 14 + 16 * series, rows[i].label,
                rows[i].precision);
        series++;
    }
#undef PX
#undef PY
    fprintf(f, "</svg>\n");
    fclose(f);
}

static void print_table(const bench_field *bf, const row *rows, int n, int fig)
{
    printf("\n### %s — Fig. %d analogue (%zu lines, t_max %g)\n\n", bf->name, fig, bf->seed_count, bf->t_max);
    printf("| solver | precision | %s | samples | cut | E (Eq. 7, vs RKF5 h=1e-4) |%s GPU ms to read-back | "
           "GPU ms dispatch | CPU ms (double) |\n", fig == 9 ? "step h" : "tol / H", bf->exact ? " E vs exact |" : "");
    printf("|---|---|---|---|---|---|%s---|---|---|\n", bf->exact ? "---|" : "");
    for (int i = 0; i < n; i++) {
        if (rows[i].fig != fig)
            continue;
        printf("| %s | %s | %s %.3g | %zu | %zu | %.3g |", rows[i].label, rows[i].precision, rows[i].param_name,
               rows[i].param, rows[i].samples, rows[i].truncated, rows[i].E);
        if (bf->exact)
            printf(" %.3g |", rows[i].E_true);
        printf(" %.2f | %.2f | %.2f |\n", rows[i].wall_ms, rows[i].gpu_ms, rows[i].cpu_ms);
    }
}

int main(int argc, char **argv)
{
    const char *out_dir = "bench-out", *only = NULL;
    int quick = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            out_dir = argv[++i];
        else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else {
            fprintf(stderr, "usage: bench-streamlines [--out DIR] [--only helix|abc|lr] [--quick]\n");
            return 2;
        }
    }
    mkdir(out_dir, 0777);
    sl_gpu *gpu = NULL;
    sl_err err = {0};
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "bench-streamlines: %s\n", err.message);
        return 1;
    }
    printf("## Streamlines: run time against error (issue 15, Fig. 9 and 10)\n\nGPU: %s.\n",
           sl_gpu_renderer(gpu));
    enum { FIELDS = 3 };
    bench_field fields[FIELDS] = {{.name = "helix", .t_max = 3.0, .exact = helix_exact, .base_step = 0.2},
                                  {.name = "abc", .t_max = 2.0, .base_step = 0.2},
                                  {.name = "lr", .t_max = 3.0, .exact = identity_exact, .base_step = 0.1,
                                   .fig10_precisions = 1}};
    const int hd[3] = {33, 33, 17}, ad[3] = {33, 33, 33};
    const double ho[3] = {-2, -2, -1}, ao[3] = {0, 0, 0};
    fields[0].ds = sample_volume("helix", hd, ho, 0.125, 0);
    fields[1].ds = sample_volume("abc", ad, ao, 2 * M_PI / 32, 1);
    sl_flow_seeds_box("-1,-1,-0.5,1,1,0.5,64", &fields[0].seeds, &fields[0].seed_count, &err);
    sl_flow_seeds_box("0.5,0.5,0.5,5.8,5.8,5.8,64", &fields[1].seeds, &fields[1].seed_count, &err);
    sl_flow_seeds_box("0.1,0.1,0.1,0.5,0.5,0.5,64", &fields[2].seeds, &fields[2].seed_count, &err);
    int steps = quick ? 4 : 8, tols = quick ? 4 : 9;
    for (int fi = 0; fi < FIELDS; fi++) {
        bench_field *bf = &fields[fi];
        if (only && strcmp(only, bf->name) != 0)
            continue;
        if (fi == 2) { /* the LR file, loaded only when its table runs */
            char path[1024];
            snprintf(path, sizeof path, "%s/tests/data/lr/refined_quadratic.lr.gz", source_dir());
            if (sl_dataset_open(path, NULL, &bf->ds, &err) != SL_OK) {
                fprintf(stderr, "bench-streamlines: %s\n", err.message);
                return 1;
            }
            printf("\nlr: %s, %zu elements, domain [%g, %g]^3\n", path, bf->ds->lr->element_count,
                   bf->ds->lr->domain_lo[0], bf->ds->lr->domain_hi[0]);
        }
        if (!bf->ds || !bf->seeds || sl_flow_field_from_dataset(&bf->f, bf->ds, &err) != SL_OK) {
            fprintf(stderr, "bench-streamlines: field %s could not be made\n", bf->name);
            return 1;
        }
        sl_flow_gpu *g = NULL;
        if (sl_flow_gpu_create(&bf->f, &g, &err) != SL_OK) {
            fprintf(stderr, "bench-streamlines: %s\n", err.message);
            return 1;
        }
        sl_flow_options ro = {.solver = SL_FLOW_RKF5, .mode = SL_FLOW_STEP_FIXED, .step = 1e-4,
                              .t_max = bf->t_max, .max_samples = 100000};
        sl_flow_result ref;
        if (sl_flow_trace(&bf->f, bf->seeds, bf->seed_count, &ro, &ref, &err) != SL_OK) {
            fprintf(stderr, "bench-streamlines: reference: %s\n", err.message);
            return 1;
        }
        if (bf->exact)
            printf("\n%s reference (RKF5 h = 1e-4, CPU double) against the exact solution: E = %.3g\n", bf->name,
                   sl_flow_error(&ref, NULL, bf->exact, bf));
        static row rows[MAX_ROWS];
        int n = 0;
        static const sl_flow_solver fig9[3] = {SL_FLOW_RK2, SL_FLOW_RK4, SL_FLOW_RKF5};
        for (int s = 0; s < 3; s++)
            for (int p = SL_FLOW_SINGLE; p <= SL_FLOW_DOUBLE; p++)
                for (int k = 0; k < steps && n < MAX_ROWS; k++) {
                    double h = bf->base_step / (double)(1 << k);
                    sl_flow_options o = {.solver = fig9[s], .mode = SL_FLOW_STEP_FIXED, .step = h,
                                         .t_max = bf->t_max, .max_samples = 4096};
                    row *r = &rows[n];
                    snprintf(r->label, sizeof r->label, "%s", sl_flow_methods[fig9[s]].name);
                    r->fig = 9;
                    r->precision = sl_flow_precision_name((sl_flow_precision)p);
                    r->param = h;
                    r->param_name = "h";
                    if (run_one(g, bf, &ref, &o, (sl_flow_precision)p, r) == 0)
                        n++;
                }
        /* Fig. 10: mixed only, or every precision (lr). */
        int p_lo = bf->fig10_precisions ? SL_FLOW_SINGLE : SL_FLOW_MIXED;
        int p_hi = bf->fig10_precisions ? SL_FLOW_DOUBLE : SL_FLOW_MIXED;
        static const sl_flow_solver adaptive[3] = {SL_FLOW_HE, SL_FLOW_BS, SL_FLOW_RKF45};
        for (int s = 0; s < 3; s++)
            for (int p = p_lo; p <= p_hi; p++)
                for (int k = 0; k < tols && n < MAX_ROWS; k++) {
                    double tol = pow(10.0, -2 - k);
                    sl_flow_options o = {.solver = adaptive[s], .mode = SL_FLOW_STEP_ADAPTIVE, .tol = tol,
                                         .t_max = bf->t_max, .max_samples = 4096};
                    row *r = &rows[n];
                    snprintf(r->label, sizeof r->label, "%s", sl_flow_methods[adaptive[s]].name);
                    r->fig = 10;
                    r->precision = sl_flow_precision_name((sl_flow_precision)p);
                    r->param = tol;
                    r->param_name = "tol";
                    if (run_one(g, bf, &ref, &o, (sl_flow_precision)p, r) == 0)
                        n++;
                }
        static const sl_flow_solver heur[2] = {SL_FLOW_RK4, SL_FLOW_RKF5};
        for (int s = 0; s < 2; s++)
            for (int p = p_lo; p <= p_hi; p++)
                for (int k = 0; k < steps && n < MAX_ROWS; k++) {
                    double H = 2.0 / (double)(1 << k);
                    sl_flow_options o = {.solver = heur[s], .mode = SL_FLOW_STEP_HEURISTIC, .step = H,
                                         .t_max = bf->t_max, .max_samples = 4096};
                    row *r = &rows[n];
                    snprintf(r->label, sizeof r->label, "%s heuristic", sl_flow_methods[heur[s]].name);
                    r->fig = 10;
                    r->precision = sl_flow_precision_name((sl_flow_precision)p);
                    r->param = H;
                    r->param_name = "H";
                    if (run_one(g, bf, &ref, &o, (sl_flow_precision)p, r) == 0)
                        n++;
                }
        print_table(bf, rows, n, 9);
        print_table(bf, rows, n, 10);
        char path[512], title[128];
        for (int fig = 9; fig <= 10; fig++) {
            snprintf(path, sizeof path, "%s/streamlines_fig%d_%s.svg", out_dir, fig, bf->name);
            snprintf(title, sizeof title, "%s: E (Eq. 7) against GPU ms, Fig. %d analogue", bf->name, fig);
            write_svg(path, title, rows, n, fig);
            printf("\nplot: %s\n", path);
        }
        sl_flow_result_free(&ref);
        sl_flow_gpu_destroy(g);
    }
    for (int fi = 0; fi < FIELDS; fi++) {
        free(fields[fi].seeds);
        sl_dataset_destroy(fields[fi].ds);
    }
    sl_gpu_destroy(gpu);
    return 0;
}
