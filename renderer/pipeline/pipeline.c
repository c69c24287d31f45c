/* pipeline.c — dataset + technique + cached prepared state -> frames (see sl_pipeline.h).
 *
 * Invariant: `state` was prepared from exactly (dataset, technique,
 * prepared_params); `stale` is set whenever one of those may no longer hold
 * and forces a prepare at the next render. A camera move touches none of
 * them. Render thread only.
 */
#include "sl_pipeline.h"

#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"

struct sl_pipeline {
    sl_gpu *gpu;                  /* borrowed */
    sl_dataset *dataset;          /* owned */
    const sl_technique *technique;
    sl_params params;             /* requested */
    sl_params prepared_params;    /* what state was prepared with */
    void *state;                  /* technique state, owned through technique->release */
    int stale;
    sl_target target;
    sl_gpu_timer timer;
};

sl_status sl_pipeline_create(sl_gpu *gpu, sl_pipeline **out, sl_err *err)
{
    sl_pipeline *p = calloc(1, sizeof *p);
    if (!p)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    p->gpu = gpu;
    p->stale = 1;
    sl_gpu_timer_init(&p->timer);
    *out = p;
    return SL_OK;
}

static void release_state(sl_pipeline *p)
{
    if (p->state && p->technique)
        p->technique->release(p->state);
    p->state = NULL;
    p->stale = 1;
}

void sl_pipeline_destroy(sl_pipeline *p)
{
    if (!p)
        return;
    release_state(p);
    sl_target_deinit(&p->target);
    sl_gpu_timer_deinit(&p->timer);
    sl_dataset_destroy(p->dataset);
    free(p);
}

void sl_pipeline_set_dataset(sl_pipeline *p, sl_dataset *ds)
{
    release_state(p);
    sl_dataset_destroy(p->dataset);
    p->dataset = ds;
}

const sl_dataset *sl_pipeline_dataset(const sl_pipeline *p) { return p->dataset; }

sl_status sl_pipeline_set_technique(sl_pipeline *p, const sl_technique *t, const sl_params *params, sl_err *err)
{
    if (params->schema != t->params)
        return sl_err_set(err, SL_ERR_INVALID, "parameters do not belong to technique '%s'", t->name);
    if (p->dataset && !(t->dataset_kinds & (unsigned)p->dataset->kind))
        return sl_err_set(err, SL_ERR_INVALID, "technique '%s' cannot render a %s dataset",
                          t->name, sl_dataset_kind_name(p->dataset->kind));
    if (t != p->technique) {
        release_state(p);
        p->technique = t;
    }
    p->params = *params;
    return SL_OK;
}

int sl_pipeline_needs_prepare(const sl_pipeline *p)
{
    return p->stale || !p->state || sl_params_compare(&p->params, &p->prepared_params) >= SL_INVALIDATE_PREPARED;
}

static sl_status check_selection(const sl_pipeline *p, sl_err *err)
{
    if (!p->dataset || !p->technique)
        return sl_err_set(err, SL_ERR_INVALID, "no dataset or technique selected");
    if (!(p->technique->dataset_kinds & (unsigned)p->dataset->kind))
        return sl_err_set(err, SL_ERR_INVALID, "technique '%s' cannot render a %s dataset",
                          p->technique->name, sl_dataset_kind_name(p->dataset->kind));
    return SL_OK;
}

sl_status sl_pipeline_prepare(sl_pipeline *p, sl_frame_stats *stats, sl_err *err)
{
    sl_status st = check_selection(p, err);
    if (st != SL_OK || !sl_pipeline_needs_prepare(p))
        return st;
    release_state(p);
    double t0 = sl_clock_ms();
    st = p->technique->prepare(p->gpu, p->dataset, &p->params, &p->state, err);
    if (st != SL_OK) {
        p->state = NULL;
        return st;
    }
    glFinish();
    stats->prepare_ms = sl_clock_ms() - t0;
    stats->prepared = 1;
    if (p->technique->prepare_stats) {
        p->technique->prepare_stats(p->state, &stats->prepare);
        stats->prepare_reported = 1;
    }
    p->prepared_params = p->params;
    p->stale = 0;
    return SL_OK;
}

sl_status sl_pipeline_render(sl_pipeline *p, const sl_view *view, int samples,
                             sl_frame_stats *stats, sl_err *err)
{
    memset(stats, 0, sizeof *stats);
    sl_status prep = sl_pipeline_prepare(p, stats, err);
    if (prep != SL_OK)
        return prep;
    int want_samples = samples > 1 ? samples : 1;
    if (p->target.width != view->width || p->target.height != view->height || p->target.samples != want_samples) {
        sl_target_deinit(&p->target);
        sl_status st = sl_target_init(&p->target, view->width, view->height, want_samples, err);
        if (st != SL_OK)
            return st;
    }
    double t0 = sl_clock_ms();
    sl_target_begin(&p->target, view->background);
    sl_gpu_timer_begin(&p->timer);
    sl_status st = p->technique->render(p->state, view, &p->params, &p->target, &stats->render, err);
    stats->gpu_ms = sl_gpu_timer_end_ms(&p->timer);
    sl_target_resolve(&p->target);
    glFinish();
    stats->wall_ms = sl_clock_ms() - t0;
    stats->gpu_bytes = p->technique->gpu_bytes ? p->technique->gpu_bytes(p->state) : 0;
    return st;
}

sl_status sl_pipeline_export(sl_pipeline *p, const char *path, sl_err *err)
{
    if (!p->technique)
        return sl_err_set(err, SL_ERR_INVALID, "export %s: no technique selected", path);
    if (!sl_technique_exports(p->technique)) {
        char list[256];
        sl_technique_exporters(list, sizeof list);
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "technique '%s' exports nothing (export is offered by: %s)",
                          p->technique->name, list);
    }
    if (sl_pipeline_needs_prepare(p))
        return sl_err_set(err, SL_ERR_INVALID, "export %s: technique '%s' has nothing prepared (render a frame first)",
                          path, p->technique->name);
    return p->technique->export_geometry(p->state, &p->params, path, err);
}

sl_target *sl_pipeline_target(sl_pipeline *p) { return &p->target; }

void sl_pipeline_read_rgba(sl_pipeline *p, uint8_t *rgba, int top_down)
{
    sl_target_read_rgba(&p->target, rgba, top_down);
}

void sl_pipeline_read_distance(sl_pipeline *p, const sl_view *view, float *distance)
{
    sl_target_read_depth(&p->target, distance);
    for (int j = 0; j < p->target.height; j++)
        for (int i = 0; i < p->target.width; i++) {
            float *d = &distance[(size_t)j * (size_t)p->target.width + (size_t)i];
            *d = (float)sl_view_depth_to_distance(view, i, j, *d);
        }
}
