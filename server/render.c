/* render.c — the render thread: the only thread that touches EGL/GL.
 *
 * It owns the sl_gpu, the encoder and the prepared scenes (prepared_cache.c:
 * one sl_pipeline per dataset + technique + prepare-level parameters, shared
 * by the sessions that show it, so a camera move costs one render and N
 * sessions on one scene cost one prepare). Datasets are loaded on the
 * dataset cache's loader threads (dataset_cache.c), never here: a session
 * whose dataset is loading is skipped (its clients get `progress`), every
 * other session keeps rendering, and the finished load wakes this thread.
 * Loop: under srv->lock let go of the prepared state of sessions idle past
 * --idle-release, pick the next session that needs work (a snapshot, a state
 * version not yet rendered, or a due still frame) and is not waiting for a
 * load, copy its desired state, unlock, prepare if needed (announced as
 * `progress`) + render + read back + encode, lock, publish the frame as the
 * session's one latest frame (dropping the older one), unlock and wake the
 * service thread through srv->transport.wake_service. State that changed meanwhile is
 * simply rendered next time: the newest state wins, nothing is queued.
 * Interactive frames (camera phase start/move/end younger than
 * still_delay_ms) render at the scale interactive_scale.c picks from the
 * session's measured frame costs, at the interactive JPEG quality; once the
 * delay passes a full-size still frame follows. Sessions are picked round
 * robin so one busy session cannot starve another. A technique prepare runs
 * here (it needs the context) and still stalls every session while it runs.
 * A dataset that fails to load leaves the session on the last scene that
 * rendered; the session gets load_failed and the service thread puts its
 * scene back (s->good -> revert_to). Never touches a socket.
 */
#include "sl_server.h"

#include <errno.h>
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>


#include "core/sl_camera.h"
#include "core/sl_clock.h"
#include "core/sl_technique.h"
#include "gpu/sl_gpu.h"
#include "image/sl_video.h"
#include "pipeline/sl_pipeline.h"
#include "sl_params_json.h"
#include "sl_scene_path.h"

#include "render_internal.h"

/* A finished load (loader thread): counted, and the render thread picks its sessions up. */
static void on_load_done(void *arg, sl_status status, double load_ms)
{
    sl_server *srv = arg;
    pthread_mutex_lock(&srv->lock);
    if (status == SL_OK) {
        srv->metrics.dataset_loads++;
        sl_histogram_add(&srv->metrics.load_ms, load_ms);
    }
    pthread_cond_broadcast(&srv->wake);
    pthread_mutex_unlock(&srv->lock);
}

/* The session waits for the load of the dataset it wants (lock held). */
static int waiting_for_load(render_ctx *ctx, const sl_session *s)
{
    return s->load && strcmp(sl_dataset_load_source(s->load), s->state.dataset_source) == 0 &&
           !sl_dataset_load_poll(ctx->datasets, s->load, NULL, NULL, NULL, NULL);
}

/* Picks work under the lock; fills *deadline_ms with the next still due time (or leaves it). */
static sl_session *pick_job(render_ctx *ctx, enum job_kind *kind, double now, double *deadline_ms)
{
    sl_server *srv = ctx->srv;
    int n = 0;
    for (sl_session *s = srv->sessions; s; s = s->next)
        n++;
    if (n == 0)
        return NULL;
    for (int k = 0; k < n; k++) {
        int idx = (int)((ctx->rr + (unsigned)k) % (unsigned)n);
        sl_session *s = srv->sessions;
        for (int i = 0; i < idx; i++)
            s = s->next;
        if (s->doomed || waiting_for_load(ctx, s))
            continue;
        double still_due = s->state.camera_ms + s->state.stream.still_delay_ms;
        if (s->snap_req_count > 0 && !s->snap_ready) {
            *kind = JOB_SNAPSHOT;
        } else if (s->state.version != s->rendered_version) {
            *kind = JOB_FRAME;
        } else if (s->rendered_interactive && now >= still_due) {
            *kind = JOB_STILL;
        } else if (s->record && !s->record->finished) {
            *kind = JOB_RECORD; /* the session's own frames first: a recording only fills its idle time */
        } else {
            if (s->rendered_interactive && still_due < *deadline_ms)
                *deadline_ms = still_due;
            continue;
        }
        ctx->rr = (unsigned)idx + 1;
        return s;
    }
    return NULL;
}

/* Lets go of the prepared scenes of sessions without clients for
 * --idle-release seconds (lock held); a scene another session still shows
 * stays. The next render of such a session prepares again (its latest frame
 * stays, so a client that comes back sees it at once). A session busy with
 * a load or a progress round keeps its state until that ends. When
 * something was freed, the lock is let go while the driver's references
 * are dropped and memory goes back to the system (milliseconds, and no
 * session pointer is kept across it). *deadline_ms gets the next release. */
static void release_idle(render_ctx *ctx, double now, double *deadline_ms)
{
    sl_server *srv = ctx->srv;
    double idle_ms = srv->cfg.idle_release_s * 1000.0;
    int released = 0;
    for (sl_session *s = srv->sessions; s; s = s->next) {
        if (s->doomed || !s->prepared || s->idle_since_ms <= 0 || s->load || s->round.active)
            continue;
        double due = s->idle_since_ms + idle_ms;
        if (now < due) {
            if (due < *deadline_ms)
                *deadline_ms = due;
            continue;
        }
        sl_prepared_release(&ctx->prepared, s->prepared);
        s->prepared = NULL;
        released++;
    }
    if (released) {
        pthread_mutex_unlock(&srv->lock);
        sl_gpu_drop_references(); /* else the driver keeps the last-drawn buffers */
        malloc_trim(0);           /* llvmpipe's buffers were malloc'd: give the pages back */
        pthread_mutex_lock(&srv->lock);
    }
    srv->prepared_scenes = ctx->prepared.count; /* after the memory went back, for /metrics readers */
}

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

static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

/* What the interactive scale's estimates depend on besides the camera:
 * dataset, technique, parameter values and image size. */
static uint64_t scene_key(const sl_session_state *st)
{
    uint64_t h = 0xcbf29ce484222325ull;
    h = fnv1a(h, st->dataset_source, strlen(st->dataset_source) + 1);
    h = fnv1a(h, st->technique, strlen(st->technique) + 1);
    h = fnv1a(h, st->params.value, sizeof st->params.value[0] * (size_t)st->params.count);
    h = fnv1a(h, st->params.value_count, sizeof st->params.value_count[0] * (size_t)st->params.count);
    h = fnv1a(h, st->params.tf, sizeof st->params.tf); /* transfer functions: unused entries are zero */
    h = fnv1a(h, &st->params.tf2d.count, sizeof st->params.tf2d.count); /* field by field: no padding */
    h = fnv1a(h, &st->params.tf2d.range, sizeof st->params.tf2d.range);
    h = fnv1a(h, st->params.tf2d.widget, sizeof st->params.tf2d.widget); /* unused widgets are zero */
    h = fnv1a(h, &st->width, sizeof st->width);
    return fnv1a(h, &st->height, sizeof st->height);
}

/* A dataset's description (sl_catalog_describe: bounds, counts, attribute
 * names), made outside the lock and posted under it. */
typedef struct info_texts {
    char *bounds, *counts, *attrs;
} info_texts;

/* Hands the texts (consumed) to the service thread as the description of
 * dataset `name` (catalog row, the session's bounds). Lock held. */
static void post_info_locked(sl_session *s, info_texts *in, const char *name)
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
static void switch_prepared(render_ctx *ctx, sl_session *s, sl_prepared *p, const sl_session_state *st, int hit)
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
static enum scene_status ensure_scene(render_ctx *ctx, sl_session *s, const sl_session_state *st, sl_err *err)
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
static void report_load_failure(render_ctx *ctx, sl_session *s, const sl_session_state *st, const sl_err *err)
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

static void report_error(sl_server *srv, sl_session *s, const sl_session_state *st, const sl_err *err)
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
int sl_render_ready_scene(render_ctx *ctx, sl_session *s, const sl_session_state *st)
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
            report_error(ctx->srv, s, st, &err);
        return 0;
    }
    sl_pipeline *pl = s->prepared->pipeline;
    if (sl_pipeline_set_technique(pl, s->prepared->technique, &st->params, &err) != SL_OK) {
        sl_progress_end(ctx->srv, s, 0, 0, 0);
        report_error(ctx->srv, s, st, &err);
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
            report_error(ctx->srv, s, st, &err);
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
sl_status sl_render_view(render_ctx *ctx, sl_session *s, const sl_session_state *st, int interactive,
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

static void do_frame(render_ctx *ctx, sl_session *s, const sl_session_state *st, int interactive)
{
    sl_err err = {0};
    int w = 0, h = 0, step = 0;
    double render_ms = 0, encode_ms = 0;
    sl_frame_buf *f = NULL;
    sl_iscale_sync(&s->iscale, scene_key(st), st->stream.interactive_scale);
    double scale = interactive ? sl_iscale_choose(&s->iscale, &st->stream, &step) : 1.0;
    if (!sl_render_ready_scene(ctx, s, st))
        return;
    double t0 = sl_clock_ms();
    const char *backend = NULL;
    if (sl_render_view(ctx, s, st, interactive, scale, &w, &h, &render_ms, &backend, &err) != SL_OK) {
        sl_progress_end(ctx->srv, s, 0, 0, 0);
        report_error(ctx->srv, s, st, &err);
        return;
    }
    sl_pipeline_read_rgba(s->prepared->pipeline, ctx->rgba, 0);
    sl_render_test_delay(ctx->srv, st, w, h);
    render_ms = sl_clock_ms() - t0;
    int quality = interactive ? st->stream.interactive_quality : st->stream.still_quality;
    int sub420 = interactive ? st->stream.interactive_420 : st->stream.still_420;
    if (sl_encoder_jpeg(ctx->enc, ctx->rgba, w, h, quality, sub420, &f, &encode_ms, &err) != SL_OK) {
        sl_progress_end(ctx->srv, s, 0, 0, 0);
        report_error(ctx->srv, s, st, &err);
        return;
    }
    double seen_ms = render_ms + encode_ms;
    if (ctx->srv->cfg.test_frame_time_ms > 0 || ctx->srv->cfg.test_frame_time_fixed_ms > 0)
        /* tests: an injected cost, whatever this machine's speed */
        seen_ms = ctx->srv->cfg.test_frame_time_ms * ((double)w * h) / ((double)st->width * st->height) +
                  ctx->srv->cfg.test_frame_time_fixed_ms;
    sl_iscale_record(&s->iscale, interactive, step, seen_ms);
    s->good = *st;
    s->has_good = 1;
    sl_server *srv = ctx->srv;
    pthread_mutex_lock(&srv->lock);
    f->header.frame_id = ++s->next_frame_id;
    f->header.state_version = st->version;
    f->header.flags = interactive ? SL_FRAME_FLAG_INTERACTIVE : 0;
    f->header.render_ms = (float)render_ms;
    f->header.camera_seq = st->camera_seq;
    sl_frame_header_write(&f->header, f->data);
    uint32_t frame_id = f->header.frame_id;
    sl_frame_buf_unref(s->latest);
    s->latest = f;
    s->rendered_version = st->version;
    s->rendered_interactive = interactive;
    if (!interactive && st->version > s->checkpoint_version) {
        /* A still of a state not checkpointed yet: the service thread writes the checkpoint (it owns the DB). */
        s->checkpoint_version = st->version;
        s->checkpoint_due = 1;
    }
    srv->last_frame_ms = render_ms + encode_ms;
    srv->metrics.frames_rendered++;
    srv->metrics.frames_by_backend[sl_metric_backend_index(backend)]++;
    sl_histogram_add(&srv->metrics.render_ms, render_ms);
    sl_histogram_add(&srv->metrics.encode_ms, encode_ms);
    pthread_mutex_unlock(&srv->lock);
    sl_progress_end(srv, s, 1, render_ms, frame_id);
}

/* Puts snapshot requests back (their scene is still loading). */
static void requeue_snapshots(sl_server *srv, sl_session *s, const int *ids, int n)
{
    pthread_mutex_lock(&srv->lock);
    for (int i = 0; i < n && s->snap_req_count < SL_SESSION_MAX_SNAPSHOTS; i++)
        s->snap_req[s->snap_req_count++] = ids[i];
    pthread_mutex_unlock(&srv->lock);
}

static void do_snapshot(render_ctx *ctx, sl_session *s, const sl_session_state *st, const int *ids, int n)
{
    sl_err err = {0};
    int w = 0, h = 0;
    double render_ms = 0, encode_ms = 0;
    sl_frame_buf *f = NULL;
    sl_server *srv = ctx->srv;
    if (!sl_render_ready_scene(ctx, s, st)) {
        if (s->load)
            requeue_snapshots(srv, s, ids, n);
        return;
    }
    const char *backend = NULL;
    if (sl_render_view(ctx, s, st, 0, 1.0, &w, &h, &render_ms, &backend, &err) == SL_OK) {
        sl_pipeline_read_rgba(s->prepared->pipeline, ctx->rgba, 1);
        if (sl_encoder_png(ctx->rgba, w, h, &f, &encode_ms, &err) == SL_OK) {
            f->header.state_version = st->version;
            f->header.render_ms = (float)render_ms;
            f->header.camera_seq = st->camera_seq;
            sl_frame_header_write(&f->header, f->data);
        }
    }
    sl_progress_end(srv, s, f != NULL, render_ms, 0); /* a round it began ends with the snapshot */
    pthread_mutex_lock(&srv->lock);
    if (f) {
        s->snap_ready = f;
        memcpy(s->snap_ready_ids, ids, sizeof(int) * (size_t)n);
        s->snap_ready_count = n;
        srv->metrics.snapshots++;
    } else {
        snprintf(s->error_code, sizeof s->error_code, "render_failed");
        snprintf(s->error_text, sizeof s->error_text, "snapshot failed: %.480s", err.message);
        s->error_seq++;
    }
    pthread_mutex_unlock(&srv->lock);
}

/* Lets go of what the session holds on this thread. */
void sl_render_session_release(render_ctx *ctx, sl_session *s)
{
    sl_prepared_release(&ctx->prepared, s->prepared);
    s->prepared = NULL;
    sl_dataset_load_release(ctx->datasets, s->load);
    s->load = NULL;
}

/* Unlinks doomed sessions (lock held) and frees them with their scenes. */
static void reap(render_ctx *ctx)
{
    sl_session **pp = &ctx->srv->sessions;
    while (*pp) {
        sl_session *s = *pp;
        if (s->doomed && !s->rendering) {
            *pp = s->next;
            sl_render_session_release(ctx, s);
            sl_session_free(s);
            ctx->srv->prepared_scenes = ctx->prepared.count;
        } else {
            pp = &s->next;
        }
    }
}

static void *render_main(void *arg)
{
    render_ctx ctx = {.srv = arg};
    sl_server *srv = ctx.srv;
    sl_err err = {0};
    sl_gpu_desc desc = {.device = srv->cfg.egl_device, .quiet = 1};
    sl_status st = sl_gpu_create(&desc, &ctx.gpu, &err);
    if (st == SL_OK)
        st = sl_encoder_create(&ctx.enc, &err);
    sl_dataset_cache_desc dc = {.on_done = on_load_done, .arg = srv, .test_delay_ms = srv->cfg.test_load_delay_ms,
                                .data_dirs = srv->cfg.data_dirs, .data_dir_count = srv->cfg.data_dir_count};
    if (st == SL_OK)
        st = sl_dataset_cache_create(&dc, &ctx.datasets, &err);
    ctx.prepared.gpu = ctx.gpu;
    pthread_mutex_lock(&srv->lock);
    if (st != SL_OK) {
        srv->render_ready = -1;
        snprintf(srv->render_fail, sizeof srv->render_fail, "%.250s", err.message);
        pthread_cond_broadcast(&srv->wake);
        pthread_mutex_unlock(&srv->lock);
        sl_dataset_cache_destroy(ctx.datasets);
        sl_encoder_destroy(ctx.enc);
        sl_gpu_destroy(ctx.gpu);
        return NULL;
    }
    srv->render_ready = 1;
    snprintf(srv->gpu_renderer, sizeof srv->gpu_renderer, "%s", sl_gpu_renderer(ctx.gpu));
    pthread_cond_broadcast(&srv->wake);
    sl_session_state *copy = malloc(sizeof *copy);
    while (!srv->stop && copy) {
        reap(&ctx);
        double now = sl_clock_ms();
        double deadline = now + 1000.0;
        release_idle(&ctx, now, &deadline);
        enum job_kind kind = JOB_NONE;
        sl_session *s = pick_job(&ctx, &kind, now, &deadline);
        if (!s) {
            double wait = deadline - now;
            if (wait < 1)
                wait = 1;
            struct timespec ts = sl_clock_deadline(wait);
            pthread_cond_timedwait(&srv->wake, &srv->lock, &ts);
            continue;
        }
        *copy = s->state;
        int ids[SL_SESSION_MAX_SNAPSHOTS], nids = 0;
        if (kind == JOB_SNAPSHOT) {
            nids = s->snap_req_count;
            memcpy(ids, s->snap_req, sizeof(int) * (size_t)nids);
            s->snap_req_count = 0;
        }
        sl_record_job *record = kind == JOB_RECORD ? s->record : NULL; /* replaced only once finished */
        int record_cancel = record && record->cancel;
        int interactive = 0;
        if (kind == JOB_FRAME)
            interactive = copy->phase != SL_PHASE_NONE && now < copy->camera_ms + copy->stream.still_delay_ms;
        s->rendering = 1;
        pthread_mutex_unlock(&srv->lock);
        if (kind == JOB_SNAPSHOT)
            do_snapshot(&ctx, s, copy, ids, nids);
        else if (kind == JOB_RECORD)
            sl_render_record(&ctx, s, record, record_cancel);
        else
            do_frame(&ctx, s, copy, interactive);
        if (srv->transport.wake_service)
            srv->transport.wake_service(srv);
        pthread_mutex_lock(&srv->lock);
        s->rendering = 0;
    }
    /* Shutdown: GL objects die on this thread; sessions are freed by the service thread. */
    for (sl_session *s = srv->sessions; s; s = s->next)
        sl_render_session_release(&ctx, s);
    reap(&ctx);
    pthread_mutex_unlock(&srv->lock);
    sl_dataset_cache_destroy(ctx.datasets);
    free(copy);
    free(ctx.rgba);
    sl_encoder_destroy(ctx.enc);
    sl_gpu_destroy(ctx.gpu);
    return NULL;
}

sl_status sl_render_start(sl_server *srv, sl_err *err)
{
    if (pthread_create(&srv->render_thread, NULL, render_main, srv) != 0)
        return sl_err_set(err, SL_ERR_NOMEM, "cannot start the render thread: %s", strerror(errno));
    srv->render_started = 1;
    pthread_mutex_lock(&srv->lock);
    while (srv->render_ready == 0)
        pthread_cond_wait(&srv->wake, &srv->lock);
    int ok = srv->render_ready > 0;
    pthread_mutex_unlock(&srv->lock);
    if (!ok) {
        pthread_join(srv->render_thread, NULL);
        srv->render_started = 0;
        return sl_err_set(err, SL_ERR_GPU, "render thread: %s", srv->render_fail);
    }
    return SL_OK;
}

void sl_render_stop(sl_server *srv)
{
    if (!srv->render_started)
        return;
    pthread_mutex_lock(&srv->lock);
    srv->stop = 1;
    pthread_cond_broadcast(&srv->wake);
    pthread_mutex_unlock(&srv->lock);
    pthread_join(srv->render_thread, NULL);
    srv->render_started = 0;
}
