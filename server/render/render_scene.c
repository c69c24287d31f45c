/* render_scene.c — the steps of a frame that render.c (frames, stills, snapshots) and
 * render_record.c (a recording job's frames) share: a slot's scene made ready (its
 * dataset from the cache, a prepared scene found or made, the technique's prepare
 * announced as `progress`), a load's failure reported so the service thread puts the
 * scene back, a view rendered at a scale into the context's readback buffer, and a
 * render failure reported. Render thread only; the lock is taken only to read or post
 * the slot's [lock] fields.
 */
#include "sl_render.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/sl_camera.h"
#include "core/sl_clock.h"
#include "core/sl_technique.h"
#include "pipeline/sl_pipeline.h"

#include "render_internal.h"

static sl_status ensure_rgba(render_ctx *ctx, int w, int h, sl_err *err)
{
    size_t need = (size_t)w * (size_t)h * 4;
    if (need <= ctx->rgba_cap)
        return SL_OK;
    uint8_t *p = realloc(ctx->rgba, need);
    if (!p)
        return sl_err_set(err, SL_ERR_NOMEM, "cannot allocate a %dx%d readback buffer", w, h);
    ctx->rgba = p;
    ctx->rgba_cap = need;
    return SL_OK;
}

typedef struct info_texts {
    char *bounds, *counts, *attrs;
} info_texts;

/* Hands the texts (consumed) to the service thread as the description of
 * dataset `name` (catalog row, the session's bounds). Lock held. */
static void post_info_locked(sl_render_slot *s, info_texts *in, const char *name)
{
    free(s->info_bounds);
    free(s->info_counts);
    free(s->info_attrs);
    s->info_bounds = in->bounds;
    s->info_counts = in->counts;
    s->info_attrs = in->attrs;
    memset(in, 0, sizeof *in);
    snprintf(s->info_dataset, sizeof s->info_dataset, "%s", name);
    s->info_pending = 1;
}

/* Moves s onto p (the reference is consumed). When the session's dataset
 * changed, the dataset is described for the service thread and counted as
 * a cache hit when `hit` (it was handed out without a load of its own). */
static void switch_prepared(render_ctx *ctx, sl_render_slot *s, sl_prepared *p, const sl_session_state *st, int hit)
{
    int new_dataset = !s->prepared || s->prepared->dataset != p->dataset;
    sl_prepared_release(&ctx->prepared, s->prepared);
    s->prepared = p;
    info_texts info = {0};
    if (new_dataset)
        sl_catalog_describe(p->dataset, &info.bounds, &info.counts, &info.attrs);
    pthread_mutex_lock(&ctx->srv->lock);
    ctx->srv->prepared_scenes = ctx->prepared.count;
    if (new_dataset) {
        if (hit)
            ctx->srv->metrics.dataset_cache_hits++;
        post_info_locked(s, &info, st->dataset);
    }
    pthread_mutex_unlock(&ctx->srv->lock);
}

enum scene_status {
    SCENE_READY,       /* s->prepared shows st's dataset with st's technique */
    SCENE_WAITING,     /* its dataset is loading (s->load); nothing to render yet */
    SCENE_LOAD_FAILED, /* the dataset did not load: err says why; s->prepared is unchanged */
    SCENE_FAILED,      /* anything else (unknown technique, out of memory): err */
};

/* Puts s on the prepared scene of st: the one it has, another session's
 * (shared), or a new one over the dataset — taken from a scene that holds
 * it, from the dataset cache, or once its load (started or joined here, on
 * a loader thread) has finished. Never waits for a load. */
static enum scene_status ensure_scene(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st, sl_err *err)
{
    const sl_technique *t = sl_technique_find(st->technique);
    if (!t) {
        sl_err_set(err, SL_ERR_INVALID, "technique \"%s\" is not in this build", st->technique);
        return SCENE_FAILED;
    }
    sl_prepared *cur = s->prepared;
    int same_source = cur && strcmp(cur->source, st->dataset_source) == 0;
    if (same_source && cur->technique == t && sl_params_compare(&cur->key, &st->params) < SL_INVALIDATE_PREPARED)
        return SCENE_READY;
    if (s->load && strcmp(sl_dataset_load_source(s->load), st->dataset_source) != 0) {
        sl_dataset_load_release(ctx->datasets, s->load); /* no longer wanted; the load may go on for others */
        s->load = NULL;
        sl_progress_end(ctx->srv, s, 0, 0, 0);
    }
    sl_dataset *ds = NULL;
    int hit = 0;
    if (s->load) {
        sl_status ls = SL_OK;
        double ms = 0;
        if (!sl_dataset_load_poll(ctx->datasets, s->load, &ds, &ms, &ls, err))
            return SCENE_WAITING;
        sl_dataset_load_release(ctx->datasets, s->load);
        s->load = NULL;
        s->round.load_ms = sl_clock_ms() - s->round.t0_ms;
        if (ls != SL_OK)
            return SCENE_LOAD_FAILED;
        hit = !s->load_is_new; /* the load itself was counted by on_load_done */
    } else if (same_source) {
        ds = sl_dataset_retain(cur->dataset); /* another technique or prepare-level parameter on the same data */
    } else {
        hit = 1;
        /* A file goes through the cache, which checks that it is unchanged on disk. */
        ds = st->dataset_is_file ? NULL : sl_prepared_dataset_of(&ctx->prepared, st->dataset_source);
        if (!ds) {
            sl_dataset_load *l = NULL;
            sl_dataset_origin origin = SL_DATASET_CACHED;
            if (sl_dataset_cache_request(ctx->datasets, st->dataset_source, st->dataset_is_file,
                                         st->dataset_checksum, &ds, &l, &origin,
                                         err) != SL_OK)
                return SCENE_LOAD_FAILED;
            if (l) {
                s->load = l;
                s->load_is_new = origin == SL_DATASET_NEW_LOAD;
                sl_progress_begin(ctx->srv, s, st);
                sl_progress_stage_post(ctx->srv, s, SL_PROGRESS_LOADING);
                return SCENE_WAITING;
            }
        }
    }
    sl_prepared *p = sl_prepared_find(&ctx->prepared, st->dataset_source, t, &st->params, ds);
    if (p)
        sl_dataset_destroy(ds);
    else if (sl_prepared_create(&ctx->prepared, st->dataset_source, ds, t, &st->params, &p, err) != SL_OK)
        return SCENE_FAILED;
    switch_prepared(ctx, s, p, st, hit);
    return SCENE_READY;
}

/* msg with every "<directory of path>/" removed, so a loader's message
 * names the file but never shows clients where the server keeps it. */
static void strip_dir(const char *msg, const char *path, char *out, size_t size)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) + 1 : 0, o = 0;
    for (const char *p = msg; *p && o + 1 < size;) {
        if (n > 1 && strncmp(p, path, n) == 0) {
            p += n;
            continue;
        }
        out[o++] = *p++;
    }
    out[o] = '\0';
}

/* A dataset load for st failed: the session's clients get `load_failed`
 * naming the dataset and the loader's reason, and the service thread is
 * asked to put the session back on the last scene that rendered (s->good)
 * if the desired state still names the failed source. s->prepared, when it
 * is still that scene, renders it next without a load. */
static void report_load_failure(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st, const sl_err *err)
{
    sl_server *srv = ctx->srv;
    char reason[400];
    strip_dir(err->message, st->dataset_source, reason, sizeof reason);
    int revert = s->has_good && strcmp(s->good.dataset_source, st->dataset_source) != 0;
    const sl_dataset *kept = revert && s->prepared && strcmp(s->prepared->source, s->good.dataset_source) == 0
                                 ? s->prepared->dataset : NULL;
    info_texts info = {0};
    if (kept)
        sl_catalog_describe(kept, &info.bounds, &info.counts, &info.attrs);
    pthread_mutex_lock(&srv->lock);
    snprintf(s->error_code, sizeof s->error_code, "load_failed");
    if (revert)
        snprintf(s->error_text, sizeof s->error_text, "dataset \"%.60s\" could not be loaded: %.320s; the session "
                 "keeps showing \"%.60s\"", st->dataset, reason, s->good.dataset);
    else
        snprintf(s->error_text, sizeof s->error_text, "dataset \"%.60s\" could not be loaded: %.400s", st->dataset,
                 reason);
    s->error_seq++;
    s->rendered_version = st->version;
    s->rendered_interactive = 0;
    srv->metrics.frames_failed++;
    srv->metrics.dataset_load_failures++;
    if (revert) {
        s->revert_to = s->good;
        snprintf(s->revert_failed_source, sizeof s->revert_failed_source, "%s", st->dataset_source);
        s->revert_pending = 1;
        if (kept)
            post_info_locked(s, &info, s->good.dataset);
    }
    pthread_mutex_unlock(&srv->lock);
}

void sl_render_report_error(sl_server *srv, sl_render_slot *s, const sl_session_state *st, const sl_err *err)
{
    pthread_mutex_lock(&srv->lock);
    snprintf(s->error_code, sizeof s->error_code, "render_failed");
    snprintf(s->error_text, sizeof s->error_text, "%.500s", err->message);
    s->error_seq++;
    s->rendered_version = st->version;
    s->rendered_interactive = 0;
    srv->metrics.frames_failed++;
    pthread_mutex_unlock(&srv->lock);
}

/* Gets s ready to render st: its prepared scene (ensure_scene) and the
 * technique's prepare when it is due, announced before it runs (`preparing`,
 * then `first_frame`). Returns 1 when ready; 0 when waiting for a load or
 * failed, with the failure reported and the round ended. */
int sl_render_ready_scene(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st)
{
    sl_err err = {0};
    enum scene_status ss = ensure_scene(ctx, s, st, &err);
    if (ss == SCENE_WAITING)
        return 0;
    if (ss != SCENE_READY) {
        sl_progress_end(ctx->srv, s, 0, 0, 0);
        if (ss == SCENE_LOAD_FAILED)
            report_load_failure(ctx, s, st, &err);
        else
            sl_render_report_error(ctx->srv, s, st, &err);
        return 0;
    }
    sl_pipeline *pl = s->prepared->pipeline;
    if (sl_pipeline_set_technique(pl, s->prepared->technique, &st->params, &err) != SL_OK) {
        sl_progress_end(ctx->srv, s, 0, 0, 0);
        sl_render_report_error(ctx->srv, s, st, &err);
        return 0;
    }
    if (sl_pipeline_needs_prepare(pl)) {
        if (!s->round.active)
            sl_progress_begin(ctx->srv, s, st);
        s->round.version = st->version;
        sl_progress_stage_post(ctx->srv, s, SL_PROGRESS_PREPARING);
        sl_frame_stats ps;
        memset(&ps, 0, sizeof ps);
        if (sl_pipeline_prepare(pl, &ps, &err) != SL_OK) {
            sl_progress_end(ctx->srv, s, 0, 0, 0);
            sl_render_report_error(ctx->srv, s, st, &err);
            return 0;
        }
        s->round.prepare_ms = ps.prepare_ms;
        pthread_mutex_lock(&ctx->srv->lock);
        sl_histogram_add(&ctx->srv->metrics.prepare_ms, ps.prepare_ms);
        pthread_mutex_unlock(&ctx->srv->lock);
    }
    s->round.version = st->version;
    sl_progress_stage_post(ctx->srv, s, SL_PROGRESS_FIRST_FRAME);
    return 1;
}

/* Renders the session's prepared scene (ready_scene first) at scale (1 =
 * the session's size) with interactive or still quality; *render_ms is the
 * render call's wall time (no prepare: ready_scene ran it). */
sl_status sl_render_view(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st, int interactive,
                             double scale, int *w_out, int *h_out, double *render_ms, const char **backend,
                             sl_err *err)
{
    sl_status rc;
    sl_pipeline *pl = s->prepared->pipeline;
    const sl_dataset *ds = s->prepared->dataset;
    sl_view view;
    memset(&view, 0, sizeof view);
    if ((rc = sl_camera_spec_resolve(&st->camera, ds->bounds_min, ds->bounds_max, &view.camera, err)) != SL_OK)
        return rc;
    int w = st->width, h = st->height;
    if (scale < 1) {
        w = (int)lround(w * scale);
        h = (int)lround(h * scale);
        w = w < 1 ? 1 : w;
        h = h < 1 ? 1 : h;
    }
    view.width = w;
    view.height = h;
    view.quality = interactive ? SL_QUALITY_INTERACTIVE : SL_QUALITY_STILL;
    memcpy(view.background, st->background, sizeof view.background);
    view.origin = ds->origin;
    if ((rc = sl_view_init(&view, sl_dataset_radius(ds), err)) != SL_OK)
        return rc;
    double t0 = sl_clock_ms();
    sl_frame_stats stats;
    if ((rc = sl_pipeline_render(pl, &view, 1, &stats, err)) != SL_OK)
        return rc;
    *backend = stats.render.backend;
    snprintf(s->round.backend, sizeof s->round.backend, "%s", stats.render.backend ? stats.render.backend : "");
    if ((rc = ensure_rgba(ctx, w, h, err)) != SL_OK)
        return rc;
    *w_out = w;
    *h_out = h;
    *render_ms = sl_clock_ms() - t0;
    return SL_OK;
}

/* --test-frame-delay-ms, --test-frame-fixed-ms: a render cost proportional
 * to the frame's pixels, and one that is not. */
void sl_render_test_delay(const sl_server *srv, const sl_session_state *st, int w, int h)
{
    double ms = srv->cfg.test_frame_delay_ms * ((double)w * h) / ((double)st->width * st->height) +
                srv->cfg.test_frame_fixed_ms;
    if (ms <= 0)
        return;
    struct timespec ts = {.tv_sec = (time_t)(ms / 1000.0), .tv_nsec = (long)(fmod(ms, 1000.0) * 1e6)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}