/* hatch_check.c — in-process checks of the hatching of `particles`
 * (renderer/particles/particles_hatch.h), through sl_pipeline and the
 * checker-only hooks of renderer/particles/particles_debug.h.
 *
 *   hatch-check rebuild --dataset JSON [--param name=value]... --step CHANGE:N ...
 *     renders once, then per step applies CHANGE (`camera`: the orbit moves
 *     40 degrees; `name=value`: a parameter) and renders again; the hatch
 *     cache must have been built exactly N times by that frame.
 *   hatch-check direction --dataset JSON --major R --minor r [--param ...]
 *                         --min-reliability RHO --max-mean-deg A --max-p90-deg B
 *     on a torus around z (gen_torus: dark inside), the main stroke of every
 *     particle whose reliability (from its own curvatures) is at least RHO
 *     must follow the analytic main principal direction: the angle between
 *     the chord of its two vertices next to the particle, in the particle's
 *     tangent plane, and pref_torus_curvature's main direction.
 *   hatch-check time --dataset JSON [--param ...] [--size WxH] [--frames N]
 *     wall ms per frame (camera moves, no rebuild) and per frame with a
 *     rebuild (hatch_length alternating), for the README; judges nothing.
 * Prints the measured values; exit 0 pass, 1 FAIL (named), 2 usage or setup.
 * Single thread (the render thread: it owns the GL context).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_camera.h"
#include "core/sl_params.h"
#include "core/sl_technique.h"
#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "particles_reference.h"
#include "pipeline/sl_pipeline.h"
#include "particles/particles_debug.h"
#include "particles/particles_system.h"

#define MAX_ARGS 32

typedef struct capture {
    int got;
    int strokes_per_particle, segments;
    uint32_t particles;
    pt_record *records;
    float *vertices;
} capture;

static void on_build(void *user, const pt_debug_hatch_build *b)
{
    capture *c = user;
    if (b->set != 0)
        return;
    free(c->records);
    free(c->vertices);
    size_t nv = (size_t)b->particles * b->strokes_per_particle * (b->segments + 1);
    c->records = malloc((size_t)b->particles * sizeof *c->records + 1);
    c->vertices = malloc(nv * 16 + 1);
    if (!c->records || !c->vertices) {
        c->got = 0;
        return;
    }
    glGetNamedBufferSubData(b->records, 0, (GLsizeiptr)((size_t)b->particles * sizeof *c->records), c->records);
    glGetNamedBufferSubData(b->strokes, 0, (GLsizeiptr)(nv * 16), c->vertices);
    c->particles = b->particles;
    c->strokes_per_particle = b->strokes_per_particle;
    c->segments = b->segments;
    c->got = 1;
}

static int set_param(sl_params *p, const char *spec, sl_err *err)
{
    char name[64];
    const char *eq = strchr(spec, '=');
    if (!eq || (size_t)(eq - spec) >= sizeof name) {
        fprintf(stderr, "hatch-check: bad parameter '%s' (name=value)\n", spec);
        return -1;
    }
    memcpy(name, spec, (size_t)(eq - spec));
    name[eq - spec] = '\0';
    const char *v = eq + 1;
    double num[4];
    int n = 0;
    const char *q = *v == '[' ? v + 1 : v;
    char *end = NULL;
    while (n < 4) {
        double x = strtod(q, &end);
        if (end == q)
            break;
        num[n++] = x;
        q = end;
        while (*q == ',' || *q == ' ')
            q++;
    }
    sl_status st = (n > 0 || *v == '[') ? sl_params_set_numbers(p, name, num, n, err)
                                        : sl_params_set_choice(p, name, v, err);
    if (st != SL_OK) {
        fprintf(stderr, "hatch-check: %s: %s\n", spec, err->message);
        return -1;
    }
    return 0;
}

static int view_width = 256, view_height = 256;

static sl_status make_view(const sl_dataset *ds, double azimuth, sl_view *view, sl_err *err)
{
    memset(view, 0, sizeof *view);
    view->width = view_width;
    view->height = view_height;
    const float bg[4] = {0.1f, 0.1f, 0.12f, 1.0f};
    memcpy(view->background, bg, sizeof bg);
    view->origin = ds->origin;
    sl_orbit orbit = {azimuth, 40.0, 2.2, 45.0};
    sl_status st = sl_camera_from_orbit(&orbit, ds->bounds_min, ds->bounds_max, &view->camera, err);
    return st == SL_OK ? sl_view_init(view, sl_dataset_radius(ds), err) : st;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Reliability as the export computes it (pref: the paper's rho). */
static int direction_check(const capture *c, const sl_dataset *ds, double eps, double major, double minor,
                           double min_rho, double max_mean, double max_p90)
{
    if (!c->got || c->segments < 2) {
        fprintf(stderr, "hatch-check: no strokes captured (or fewer than 2 segments)\n");
        return 2;
    }
    double *ang = malloc((size_t)c->particles * sizeof *ang + 1);
    if (!ang)
        return 2;
    size_t m = 0;
    int centre = c->segments / 2, stride = c->segments + 1;
    for (uint32_t i = 0; i < c->particles; i++) {
        const pt_record *r = &c->records[i];
        if (pref_reliability(r->k1, r->k2, eps) < min_rho)
            continue;
        const float *v = c->vertices + (size_t)(i * c->strokes_per_particle) * stride * 4;
        const float *a = v + (centre - 1) * 4, *b = v + (centre + 1) * 4;
        double ch[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double dn = ch[0] * r->n[0] + ch[1] * r->n[1] + ch[2] * r->n[2];
        for (int k = 0; k < 3; k++)
            ch[k] -= dn * r->n[k];
        double cl = sqrt(ch[0] * ch[0] + ch[1] * ch[1] + ch[2] * ch[2]);
        double p[3] = {ds->origin.x + r->x[0], ds->origin.y + r->x[1], ds->origin.z + r->x[2]};
        double k1, k2, e1[3], main_dir[3];
        if (!(cl > 0.0) || pref_torus_curvature(major, minor, p, &k1, &k2, e1, main_dir) != 0)
            continue;
        double dot = fabs(ch[0] * main_dir[0] + ch[1] * main_dir[1] + ch[2] * main_dir[2]) / cl;
        ang[m++] = acos(fmin(dot, 1.0)) * 180.0 / M_PI;
    }
    if (m < 100) {
        printf("FAIL: only %zu particles with reliability >= %g\n", m, min_rho);
        free(ang);
        return 1;
    }
    qsort(ang, m, sizeof *ang, cmp_double);
    double mean = 0.0;
    for (size_t k = 0; k < m; k++)
        mean += ang[k];
    mean /= (double)m;
    double p90 = ang[(size_t)(0.9 * (double)(m - 1))], mx = ang[m - 1];
    printf("direction: %zu of %u particles with reliability >= %g: angle to the main principal direction mean %.3f "
           "p90 %.3f max %.3f deg\n",
           m, c->particles, min_rho, mean, p90, mx);
    free(ang);
    int fail = 0;
    if (mean > max_mean)
        printf("FAIL: mean angle %.3f deg > %g\n", mean, max_mean), fail = 1;
    if (p90 > max_p90)
        printf("FAIL: p90 angle %.3f deg > %g\n", p90, max_p90), fail = 1;
    return fail;
}

int main(int argc, char **argv)
{
    if (argc < 2 ||
        (strcmp(argv[1], "rebuild") != 0 && strcmp(argv[1], "direction") != 0 && strcmp(argv[1], "time") != 0)) {
        fprintf(stderr, "usage: hatch-check rebuild|direction|time --dataset JSON [--param name=value]... ...\n");
        return 2;
    }
    int direction = strcmp(argv[1], "direction") == 0, timing = strcmp(argv[1], "time") == 0;
    int frames = 5;
    const char *dataset = NULL, *params_in[MAX_ARGS], *steps[MAX_ARGS];
    int np = 0, ns = 0;
    double major = 0.55, minor = 0.25, min_rho = 0.9, max_mean = 1e30, max_p90 = 1e30;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) {
            fprintf(stderr, "hatch-check: %s needs a value\n", a);
            return 2;
        }
        i++;
        if (!strcmp(a, "--dataset")) dataset = v;
        else if (!strcmp(a, "--param") && np < MAX_ARGS) params_in[np++] = v;
        else if (!strcmp(a, "--step") && ns < MAX_ARGS) steps[ns++] = v;
        else if (!strcmp(a, "--major")) major = atof(v);
        else if (!strcmp(a, "--minor")) minor = atof(v);
        else if (!strcmp(a, "--min-reliability")) min_rho = atof(v);
        else if (!strcmp(a, "--max-mean-deg")) max_mean = atof(v);
        else if (!strcmp(a, "--max-p90-deg")) max_p90 = atof(v);
        else if (!strcmp(a, "--frames")) frames = atoi(v);
        else if (!strcmp(a, "--size")) {
            if (sscanf(v, "%dx%d", &view_width, &view_height) != 2 || view_width < 1 || view_height < 1) {
                fprintf(stderr, "hatch-check: bad --size %s (WxH)\n", v);
                return 2;
            }
        }
        else {
            fprintf(stderr, "hatch-check: unknown option %s\n", a);
            return 2;
        }
    }
    if (!dataset) {
        fprintf(stderr, "hatch-check: --dataset is required\n");
        return 2;
    }
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    sl_pipeline *pipe = NULL;
    sl_dataset *ds = NULL;
    int rc = 2;
    capture cap = {0};
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK || sl_generate_json(dataset, &ds, &err) != SL_OK ||
        sl_pipeline_create(gpu, &pipe, &err) != SL_OK) {
        fprintf(stderr, "hatch-check: %s\n", err.message);
        goto done;
    }
    double min_spacing = fmin(ds->volume.spacing[0], fmin(ds->volume.spacing[1], ds->volume.spacing[2]));
    const sl_dataset *dsv = ds;
    sl_pipeline_set_dataset(pipe, ds); /* owned by the pipeline from here */
    ds = NULL;
    const sl_technique *t = sl_technique_find("particles");
    sl_params params;
    sl_params_init(&params, t->params, t->param_count);
    for (int k = 0; k < np; k++)
        if (set_param(&params, params_in[k], &err) != 0)
            goto done;
    sl_view view;
    sl_frame_stats fs;
    double azimuth = 30.0;
    pt_debug_hatch_observe(on_build, &cap);
    if (sl_pipeline_set_technique(pipe, t, &params, &err) != SL_OK || make_view(dsv, azimuth, &view, &err) != SL_OK ||
        sl_pipeline_render(pipe, &view, 1, &fs, &err) != SL_OK) {
        fprintf(stderr, "hatch-check: %s\n", err.message);
        goto done;
    }
    if (direction) {
        rc = direction_check(&cap, dsv, sl_params_float(&params, "flat_curvature") / min_spacing, major, minor,
                             min_rho, max_mean, max_p90);
        goto done;
    }
    if (timing) {
        double cam = 0.0, reb = 0.0;
        for (int k = 0; k < frames; k++) {
            azimuth += 10.0;
            if (make_view(dsv, azimuth, &view, &err) != SL_OK || sl_pipeline_render(pipe, &view, 1, &fs, &err) != SL_OK)
                break;
            cam += fs.wall_ms;
        }
        double length = sl_params_float(&params, "hatch_length");
        for (int k = 0; k < frames; k++) {
            if (sl_params_set_numbers(&params, "hatch_length", (double[]){length * (k % 2 ? 1.0 : 1.1)}, 1, &err) !=
                    SL_OK ||
                sl_pipeline_set_technique(pipe, t, &params, &err) != SL_OK ||
                sl_pipeline_render(pipe, &view, 1, &fs, &err) != SL_OK)
                break;
            reb += fs.wall_ms;
        }
        if (err.message[0]) {
            fprintf(stderr, "hatch-check: %s\n", err.message);
            goto done;
        }
        printf("%dx%d: %.1f ms per frame (camera moves), %.1f ms per frame with a rebuild (%lu builds)\n", view_width,
               view_height, cam / frames, reb / frames, pt_debug_hatch_builds());
        rc = 0;
        goto done;
    }
    rc = 0;
    printf("first frame: %lu builds\n", pt_debug_hatch_builds());
    for (int k = 0; k < ns; k++) {
        char change[128];
        snprintf(change, sizeof change, "%s", steps[k]);
        char *colon = strrchr(change, ':');
        if (!colon) {
            fprintf(stderr, "hatch-check: bad step '%s' (CHANGE:N)\n", steps[k]);
            rc = 2;
            goto done;
        }
        *colon = '\0';
        long want = atol(colon + 1);
        unsigned long before = pt_debug_hatch_builds();
        if (!strcmp(change, "camera")) {
            azimuth += 40.0;
            if (make_view(dsv, azimuth, &view, &err) != SL_OK) {
                fprintf(stderr, "hatch-check: %s\n", err.message);
                rc = 2;
                goto done;
            }
        } else if (set_param(&params, change, &err) != 0 || sl_pipeline_set_technique(pipe, t, &params, &err) != SL_OK) {
            rc = 2;
            goto done;
        }
        if (sl_pipeline_render(pipe, &view, 1, &fs, &err) != SL_OK) {
            fprintf(stderr, "hatch-check: %s\n", err.message);
            rc = 2;
            goto done;
        }
        long got = (long)(pt_debug_hatch_builds() - before);
        printf("%s: %ld builds (prepared %d)\n", change, got, fs.prepared);
        if (got != want) {
            printf("FAIL: %s rebuilt the hatch strokes %ld times, want %ld\n", change, got, want);
            rc = 1;
        }
    }
done:
    pt_debug_hatch_observe(NULL, NULL);
    free(cap.records);
    free(cap.vertices);
    sl_pipeline_destroy(pipe);
    sl_dataset_destroy(ds);
    sl_gpu_destroy(gpu);
    return rc;
}
