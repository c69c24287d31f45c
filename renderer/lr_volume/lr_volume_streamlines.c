/* lr_volume_streamlines.c — streamlines traced on the GPU and drawn as
 * tubes in lr_volume's frame (lr_volume_streamlines.h).
 *
 * Fixed-step solvers take the paper's heuristic step (h = flow_step x the
 * element's min side / 2^degree, Eq. 4), adaptive ones (he, bs, rkf45) the
 * embedded error control with flow_tol; both stop at the domain boundary,
 * t_max or max_samples (renderer/flow). The tubes get the line set in its own
 * coordinates (the flow module puts its origin at the lines' bounds centre),
 * so their view is the frame's with that origin: the same eye, near plane
 * and so the same reversed-Z depth as the volume's rays.
 */
#include "lr_volume_streamlines.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../flow/sl_flow.h"

void lrv_streamlines_init(lrv_streamlines *s, sl_gpu *gpu, const sl_dataset *dataset)
{
    memset(s, 0, sizeof *s);
    s->gpu = gpu;
    s->dataset = dataset;
}

static void drop_lines(lrv_streamlines *s)
{
    if (s->tubes && s->tubes_state)
        s->tubes->release(s->tubes_state);
    s->tubes_state = NULL;
    sl_dataset_destroy(s->lines);
    s->lines = NULL;
    s->traced = 0;
    s->line_count = s->sample_count = 0;
}

void lrv_streamlines_deinit(lrv_streamlines *s)
{
    if (!s)
        return;
    drop_lines(s);
    sl_flow_gpu_destroy(s->flow);
    sl_depth_copy_deinit(&s->depth);
    memset(s, 0, sizeof *s);
}

size_t lrv_streamlines_gpu_bytes(const lrv_streamlines *s)
{
    size_t tubes = s->tubes && s->tubes_state && s->tubes->gpu_bytes ? s->tubes->gpu_bytes(s->tubes_state) : 0;
    return tubes + sl_depth_copy_bytes(&s->depth);
}

static void key_from_params(const sl_params *p, lrv_trace_key *k)
{
    memset(k, 0, sizeof *k);
    float lo[3], hi[3];
    sl_params_vec3(p, "seed_min", lo);
    sl_params_vec3(p, "seed_max", hi);
    for (int a = 0; a < 3; a++) {
        k->seed_lo[a] = lo[a];
        k->seed_hi[a] = hi[a];
    }
    k->seed_count = sl_params_int(p, "seed_count");
    k->solver = sl_params_choice(p, "solver");
    k->precision = sl_params_choice(p, "precision");
    k->step = sl_params_float(p, "flow_step");
    k->tol = sl_params_float(p, "flow_tol");
    k->t_max = sl_params_float(p, "t_max");
    k->max_samples = sl_params_int(p, "max_samples");
}

/* The seeds of the key: Halton points (flow's box seeds) in the seed box,
 * given in fractions of the domain, the corners sorted. */
static sl_status make_seeds(const lrv_streamlines *s, const lrv_trace_key *k, double **seeds, size_t *count,
                            sl_err *err)
{
    const sl_lr_volume *lr = s->dataset->lr;
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        double ext = lr->domain_hi[a] - lr->domain_lo[a];
        lo[a] = lr->domain_lo[a] + ext * fmin(k->seed_lo[a], k->seed_hi[a]);
        hi[a] = lr->domain_lo[a] + ext * fmax(k->seed_lo[a], k->seed_hi[a]);
    }
    char spec[320];
    snprintf(spec, sizeof spec, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
             k->seed_count);
    return sl_flow_seeds_box(spec, seeds, count, err);
}

/* Traces the key's lines and prepares the tubes on them (nothing to draw
 * when no line has two samples: seeds where the field is zero). */
static sl_status trace(lrv_streamlines *s, const lrv_trace_key *k, sl_err *err)
{
    sl_flow_field field;
    sl_status st = sl_flow_field_from_dataset(&field, s->dataset, err);
    if (st != SL_OK)
        return sl_err_set(err, SL_ERR_INVALID,
                          "streamlines need a vector LR-spline volume (3 components); this one has %d",
                          s->dataset->lr->dim);
    if (!s->flow && (st = sl_flow_gpu_create(&field, &s->flow, err)) != SL_OK)
        return st;
    int adaptive = sl_flow_methods[k->solver].embedded_order > 0;
    sl_flow_options o = {.solver = (sl_flow_solver)k->solver,
                         .mode = adaptive ? SL_FLOW_STEP_ADAPTIVE : SL_FLOW_STEP_HEURISTIC,
                         .step = adaptive ? 0.0 : k->step,
                         .tol = k->tol,
                         .t_max = k->t_max,
                         .max_samples = (size_t)k->max_samples};
    double *seeds = NULL;
    size_t count = 0;
    if ((st = make_seeds(s, k, &seeds, &count, err)) != SL_OK)
        return st;
    sl_flow_result r = {0};
    double t0 = sl_clock_ms();
    st = sl_flow_gpu_trace(s->flow, seeds, count, &o, (sl_flow_precision)k->precision, &r, NULL, err);
    free(seeds);
    s->trace_ms = sl_clock_ms() - t0;
    if (st != SL_OK)
        return st;
    size_t samples = 0, lines = 0;
    for (size_t i = 0; i < r.line_count; i++) {
        samples += r.lines[i].count;
        lines += r.lines[i].count >= 2;
    }
    sl_dataset *ds = NULL;
    if (lines > 0)
        st = sl_flow_result_to_dataset(&r, "streamlines", &ds, err);
    sl_flow_result_free(&r);
    if (st != SL_OK)
        return st;
    s->lines = ds;
    s->line_count = lines;
    s->sample_count = samples;
    if (!ds)
        return SL_OK;
    if (!s->tubes && !(s->tubes = sl_technique_find("tubes")))
        return sl_err_set(err, SL_ERR_INVALID, "streamlines: the tubes technique is not in this build");
    sl_params_init(&s->tube_params, s->tubes->params, s->tubes->param_count);
    return s->tubes->prepare(s->gpu, ds, &s->tube_params, &s->tubes_state, err);
}

sl_status lrv_streamlines_update(lrv_streamlines *s, const sl_params *params, double *rebuild_ms, sl_err *err)
{
    *rebuild_ms = 0.0;
    lrv_trace_key k;
    key_from_params(params, &k);
    if (s->traced && memcmp(&k, &s->key, sizeof k) == 0)
        return SL_OK;
    double t0 = sl_clock_ms();
    drop_lines(s);
    sl_status st = trace(s, &k, err);
    if (st != SL_OK) {
        drop_lines(s);
        sl_err_prefix(err, "lr_volume: streamlines");
        return st;
    }
    s->key = k;
    s->traced = 1;
    s->traces++;
    *rebuild_ms = sl_clock_ms() - t0;
    return SL_OK;
}

/* lr_volume's tube parameters onto the tubes' own (FRAME level there): the
 * radius from a fraction of the domain's diagonal to world units. */
static sl_status set_tube_params(lrv_streamlines *s, const sl_params *params, sl_err *err)
{
    const sl_lr_volume *lr = s->dataset->lr;
    double diagonal = 0.0;
    for (int a = 0; a < 3; a++)
        diagonal += (lr->domain_hi[a] - lr->domain_lo[a]) * (lr->domain_hi[a] - lr->domain_lo[a]);
    double radius = sl_params_float(params, "tube_radius") * sqrt(diagonal);
    sl_status st = sl_params_set_numbers(&s->tube_params, "radius", &radius, 1, err);
    if (st == SL_OK)
        st = sl_params_set_choice(&s->tube_params, "colormap", sl_params_choice_name(params, "tube_colormap"), err);
    return st;
}

sl_status lrv_streamlines_draw(lrv_streamlines *s, const sl_view *view, const sl_params *params, sl_target *target,
                               sl_render_stats *stats, sl_err *err)
{
    sl_status st = SL_OK;
    if (s->tubes_state) {
        sl_view tv = *view;
        tv.origin = s->lines->origin;
        sl_render_stats ts = {0};
        if ((st = sl_view_init(&tv, sl_dataset_radius(s->lines), err)) == SL_OK &&
            (st = set_tube_params(s, params, err)) == SL_OK)
            st = s->tubes->render(s->tubes_state, &tv, &s->tube_params, target, &ts, err);
        if (st != SL_OK) {
            sl_err_prefix(err, "lr_volume: streamline tubes");
            return st;
        }
        stats->primitives += ts.primitives;
        stats->culled += ts.culled;
    }
    if ((st = sl_depth_copy_update(&s->depth, target, err)) != SL_OK)
        sl_err_prefix(err, "lr_volume: streamline depth");
    return st;
}
