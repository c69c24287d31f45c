/* sightline-trace — streamlines of a vector field as CSV (issue 15).
 *
 *   sightline-trace DATASET (--seeds S.csv | --seed-box x0,y0,z0,x1,y1,z1,N |
 *       --seed-plane ox,oy,oz,ux,uy,uz,vx,vy,vz,NU,NV) --solver NAME
 *       (--step H [--heuristic] | --tol E) --t-max T [--max-samples N]
 *       [--precision single|mixed|double] [--gpu] --out L.csv
 *
 * DATASET is any source sl_dataset_open takes (a vector volume file, an
 * LR-spline volume of dim 3). Writes a header and one row per sample,
 * `line,t,x,y,z,vx,vy,vz` with %.17g; a summary (lines, samples, stop
 * reasons) goes to stdout. The CPU path is double precision (the reference;
 * --precision other than double needs --gpu). --heuristic: h = H times the
 * local size of Eq. 4 (renderer/flow/sl_flow.h). Exit 0 ok, 1 failure,
 * 2 bad usage. Seeds: renderer/flow/sl_flow.h (sl_flow_seeds_*).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset_open.h"
#include "data/sl_load.h"
#include "flow/flow_gpu.h"
#include "flow/sl_flow.h"
#include "gpu/sl_gpu.h"

static void usage(void)
{
    fprintf(stderr,
            "usage: sightline-trace DATASET (--seeds S.csv | --seed-box x0,y0,z0,x1,y1,z1,N |\n"
            "         --seed-plane ox,oy,oz,ux,uy,uz,vx,vy,vz,NU,NV) --solver NAME\n"
            "         (--step H [--heuristic] | --tol E) --t-max T [--max-samples N]\n"
            "         [--precision single|mixed|double] [--gpu] --out L.csv\n"
            "solvers:");
    for (int i = 0; i < SL_FLOW_SOLVER_COUNT; i++)
        fprintf(stderr, " %s", sl_flow_methods[i].name);
    fprintf(stderr, "\n");
}

static int number(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    return s[0] && !*end && errno == 0;
}

int main(int argc, char **argv)
{
    const char *source = NULL, *seeds_path = NULL, *box = NULL, *plane = NULL, *solver = NULL;
    const char *out_path = NULL, *precision_name = "double";
    double step = 0, tol = 0, t_max = 0, max_samples = 0;
    int heuristic = 0, gpu = 0, have_step = 0, have_tol = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        int takes = 1;
        if (strcmp(a, "--heuristic") == 0) {
            heuristic = 1;
            takes = 0;
        } else if (strcmp(a, "--gpu") == 0) {
            gpu = 1;
            takes = 0;
        } else if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage();
            return 0;
        } else if (a[0] == '-' && a[1] == '-') {
            if (!v) {
                fprintf(stderr, "sightline-trace: %s needs a value\n", a);
                return 2;
            }
            int ok = 1;
            if (strcmp(a, "--seeds") == 0) seeds_path = v;
            else if (strcmp(a, "--seed-box") == 0) box = v;
            else if (strcmp(a, "--seed-plane") == 0) plane = v;
            else if (strcmp(a, "--solver") == 0) solver = v;
            else if (strcmp(a, "--out") == 0) out_path = v;
            else if (strcmp(a, "--precision") == 0) precision_name = v;
            else if (strcmp(a, "--step") == 0) ok = number(v, &step), have_step = 1;
            else if (strcmp(a, "--tol") == 0) ok = number(v, &tol), have_tol = 1;
            else if (strcmp(a, "--t-max") == 0) ok = number(v, &t_max);
            else if (strcmp(a, "--max-samples") == 0)
                ok = number(v, &max_samples) && max_samples >= 1 && max_samples <= SL_MAX_VERTICES &&
                     max_samples == (double)(size_t)max_samples;
            else {
                fprintf(stderr, "sightline-trace: unknown option %s\n", a);
                usage();
                return 2;
            }
            if (!ok) {
                fprintf(stderr, "sightline-trace: bad value for %s: %s\n", a, v);
                return 2;
            }
        } else if (!source) {
            source = a;
            takes = 0;
        } else {
            fprintf(stderr, "sightline-trace: unexpected argument %s\n", a);
            return 2;
        }
        i += takes;
    }
    if (!source || !solver || !out_path || t_max == 0 || (!!seeds_path + !!box + !!plane) != 1 ||
        have_step == have_tol) {
        fprintf(stderr, "sightline-trace: need DATASET, one seed source, --solver, --step or --tol "
                        "(one of them), --t-max and --out\n");
        usage();
        return 2;
    }
    int s = sl_flow_solver_find(solver);
    if (s < 0) {
        fprintf(stderr, "sightline-trace: unknown solver '%s'\n", solver);
        usage();
        return 2;
    }
    int prec = sl_flow_precision_find(precision_name);
    if (prec < 0) {
        fprintf(stderr, "sightline-trace: --precision is single, mixed or double (got '%s')\n", precision_name);
        return 2;
    }
    if (!gpu && prec != SL_FLOW_DOUBLE) {
        fprintf(stderr, "sightline-trace: the CPU path is double precision; --precision %s needs --gpu\n",
                precision_name);
        return 2;
    }
    sl_flow_options o = {.solver = (sl_flow_solver)s, .step = step, .tol = tol, .t_max = t_max,
                         .max_samples = (size_t)max_samples};
    o.mode = have_tol ? SL_FLOW_STEP_ADAPTIVE : heuristic ? SL_FLOW_STEP_HEURISTIC : SL_FLOW_STEP_FIXED;
    if (heuristic && have_tol) {
        fprintf(stderr, "sightline-trace: --heuristic takes --step (the factor), not --tol\n");
        return 2;
    }

    sl_err err = {0};
    sl_dataset *ds = NULL;
    double *seeds = NULL;
    size_t seed_count = 0;
    sl_flow_result r = {0};
    sl_gpu *ctx = NULL;
    sl_flow_gpu *fg = NULL;
    FILE *out = NULL;
    int rc = 1;
    sl_status st = sl_flow_options_check(&o, &err);
    if (st == SL_OK)
        st = sl_dataset_open(source, NULL, &ds, &err);
    sl_flow_field f;
    if (st == SL_OK)
        st = sl_flow_field_from_dataset(&f, ds, &err);
    if (st == SL_OK) {
        if (seeds_path) {
            uint8_t *text = NULL;
            size_t size = 0;
            st = sl_read_file(seeds_path, 256u << 20, &text, &size, &err);
            if (st == SL_OK)
                st = sl_flow_seeds_csv((const char *)text, size, &seeds, &seed_count, &err);
            free(text);
        } else if (box) {
            st = sl_flow_seeds_box(box, &seeds, &seed_count, &err);
        } else {
            st = sl_flow_seeds_plane(plane, &seeds, &seed_count, &err);
        }
    }
    double ms = 0;
    if (st == SL_OK && gpu) {
        st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &ctx, &err);
        if (st == SL_OK)
            st = sl_flow_gpu_create(&f, &fg, &err);
        if (st == SL_OK)
            st = sl_flow_gpu_trace(fg, seeds, seed_count, &o, (sl_flow_precision)prec, &r, &ms, &err);
    } else if (st == SL_OK) {
        st = sl_flow_trace(&f, seeds, seed_count, &o, &r, &err);
    }
    if (st == SL_OK) {
        out = fopen(out_path, "w");
        if (!out)
            st = sl_err_set(&err, SL_ERR_IO, "cannot write %s: %s", out_path, strerror(errno));
    }
    if (st == SL_OK) {
        size_t samples = 0, stops[7] = {0};
        fprintf(out, "line,t,x,y,z,vx,vy,vz\n");
        for (size_t j = 0; j < r.line_count; j++) {
            const sl_flow_line *l = &r.lines[j];
            samples += l->count;
            if ((unsigned)l->stop < 7)
                stops[l->stop]++;
            for (size_t i = 0; i < l->count; i++) {
                const double *x = l->x + 3 * i, *v = l->v + 3 * i;
                fprintf(out, "%zu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", j, l->t[i], x[0], x[1], x[2],
                        v[0], v[1], v[2]);
            }
        }
        if (fclose(out) != 0)
            st = sl_err_set(&err, SL_ERR_IO, "writing %s failed", out_path);
        out = NULL;
        if (st == SL_OK) {
            printf("traced %zu lines, %zu samples (%s, %s, %s)", r.line_count, samples,
                   sl_flow_methods[s].name, gpu ? "gpu" : "cpu", sl_flow_precision_name((sl_flow_precision)prec));
            if (gpu)
                printf(", compute %.3f ms", ms);
            printf("; stops:");
            for (int k = 1; k < 7; k++)
                if (stops[k])
                    printf(" %s %zu", sl_flow_stop_name((sl_flow_stop)k), stops[k]);
            printf("\n");
            rc = 0;
        }
    }
    if (st != SL_OK)
        fprintf(stderr, "sightline-trace: %s\n", err.message);
    sl_flow_result_free(&r);
    sl_flow_gpu_destroy(fg);
    sl_gpu_destroy(ctx);
    free(seeds);
    sl_dataset_destroy(ds);
    return rc;
}
