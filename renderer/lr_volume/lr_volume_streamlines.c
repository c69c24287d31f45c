/* lr_volume_streamlines.c — streamlines traced on the GPU over lr_volume's
 * Bézier blocks and drawn as tubes in its frame (lr_volume_streamlines.h).
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
#include "../flow/flow_gpu.h"
#include "../flow/sl_flow.h"

void lrv_streamlines_init(lrv_streamlines *s, sl_gpu *gpu, const sl_dataset *dataset, const sl_lr_bezier *bz,
                          sl_lr_bezier_gpu *blocks)
{
    memset(s, 0, sizeof *s);
    s->gpu = gpu;
    s->dataset = dataset;
    s->bz = bz;
    s->blocks = blocks;
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
    sl_depth_copy_deinit(&s->depth);
    memset(s, 0, sizeof *s);
}

size_t lrv_streamlines_gpu_bytes(const lrv_streamlines *s)
{
    size_t tubes = s->tubes && s->tubes_state && s->tubes->gpu_bytes ? s->tubes->gpu_bytes(s->tubes_state) : 0;
    return tubes + sl_depth_copy_bytes(&s->depth);
}

/* The seeds of params: Halton points (flow's box seeds) in the seed box,
 * given in fractions of the domain, the corners sorted. */
static sl_status make_seeds(const lrv_streamlines *s, const sl_params *p, double **seeds, size_t *count,
                            sl_err *err)
{
    const sl_lr_volume *lr = s->dataset->lr;
    float a_frac[3], b_frac[3];
    sl_params_vec3(p, "seed_min", a_frac);
    sl_params_vec3(p, "seed_max", b_frac);
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        double ext = lr->domain_hi[a] - lr->domain_lo[a];
        lo[a] = lr->domain_lo[a] + ext * fmin(a_frac[a], b_frac[a]);
        hi[a] = lr->domain_lo[a] + ext * fmax(a_frac[a], b_frac[a]);
    }
    char spec[320];
    snprintf(spec, sizeof spec, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
             sl_params_int(p, "seed_count"));
    return sl_flow_seeds_box(spec, seeds, count, err);
}

/* The trace on the GPU over lr_volume's blocks: the flow state lives for
 * this one call (a state traces once), the blocks gain their double copies
 * for mixed and double precision. */
static sl_status trace_lines(lrv_streamlines *s, const sl_params *p, sl_flow_result *r, sl_err *err)
{
    sl_flow_field field;
    sl_status st = sl_flow_field_from_dataset(&field, s->dataset, err);
    if (st != SL_OK || s->dataset->lr->dim != 3)
        return sl_err_set(err, SL_ERR_INVALID,
                          "the volume has %d component(s); streamlines need a vector LR-spline volume (3)",
                          s->dataset->lr->dim);
    int solver = sl_params_choice(p, "solver");
    sl_flow_precision precision = (sl_flow_precision)sl_params_choice(p, "precision");
    int adaptive = sl_flow_methods[solver].embedded_order > 0;
    sl_flow_options o = {.solver = (sl_flow_solver)solver,
                         .mode = adaptive ? SL_FLOW_STEP_ADAPTIVE : SL_FLOW_STEP_HEURISTIC,
                         .step = adaptive ? 0.0 : sl_params_float(p, "flow_step"),
                         .tol = sl_params_float(p, "flow_tol"),
                         .t_max = sl_params_float(p, "t_max"),
                         .max_samples = (size_t)sl_params_int(p, "max_samples")};
    if (precision != SL_FLOW_SINGLE && (st = sl_lr_bezier_upload_double(s->bz, s->blocks, err)) != SL_OK)
        return st;
    sl_flow_gpu *flow = NULL;
    if ((st = sl_flow_gpu_create_lr(&field, s->bz, s->blocks, &flow, err)) != SL_OK)
        return st;
    double *seeds = NULL;
    size_t count = 0;
    if ((st = make_seeds(s, p, &seeds, &count, err)) == SL_OK) {
        double t0 = sl_clock_ms();
        st = sl_flow_gpu_trace(flow, seeds, count, &o, precision, r, &s->compute_ms, err);
        s->trace_ms = sl_clock_ms() - t0;
    }
    free(seeds);
    sl_flow_gpu_destroy(flow);
    return st;
}

/* The lines of r as a line set and the tubes prepared on it (nothing to
 * draw when no line has two samples: seeds where the field is zero). */
static sl_status make_tubes(lrv_streamlines *s, const sl_flow_result *r, const sl_params *params, sl_err *err)
{
    size_t samples = 0, lines = 0;
    for (size_t i = 0; i < r->line_count; i++) {
        samples += r->lines[i].count;
        lines += r->lines[i].count >= 2;
    }
    s->line_count = lines;
    s->sample_count = samples;
    if (lines == 0)
        return SL_OK;
    sl_status st = sl_flow_result_to_dataset(r, "streamlines", &s->lines, err);
    if (st != SL_OK)
        return st;
    if (!s->tubes && !(s->tubes = sl_technique_find("tubes")))
        return sl_err_set(err, SL_ERR_INVALID, "streamlines: the tubes technique is not in this build");
    sl_params_init(&s->tube_params, s->tubes->params, s->tubes->param_count);
    double speed = -1.0; /* the colour: the line set's "speed" attribute */
    for (int a = 0; a < s->lines->lines.attribute_count; a++)
        if (strcmp(s->lines->lines.attributes[a].name, "speed") == 0)
            speed = a;
    if (speed < 0)
        return sl_err_set(err, SL_ERR_INVALID, "streamlines: the line set has no speed attribute");
    if ((st = sl_params_set_numbers(&s->tube_params, "attribute", &speed, 1, err)) != SL_OK)
        return st;
    if ((st = sl_params_set_choice(&s->tube_params, "backend", sl_params_choice_name(params, "tube_backend"), err)) !=
        SL_OK)
        return st;
    double t0 = sl_clock_ms();
    st = s->tubes->prepare(s->gpu, s->lines, &s->tube_params, &s->tubes_state, err);
    s->tubes_ms = sl_clock_ms() - t0;
    return st;
}

sl_status lrv_streamlines_trace(lrv_streamlines *s, const sl_params *params, sl_err *err)
{
    if (s->traced)
        return SL_OK;
    sl_flow_result r = {0};
    sl_status st = trace_lines(s, params, &r, err);
    if (st == SL_OK)
        st = make_tubes(s, &r, params, err);
    sl_flow_result_free(&r);
    if (st != SL_OK) {
        drop_lines(s);
        sl_err_prefix(err, "lr_volume: streamlines");
        return st;
    }
    s->traced = 1;
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
