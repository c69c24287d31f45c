/* render.c — the render thread: the only thread that touches EGL/GL.
 *
 * It owns the sl_gpu, the encoder and one sl_pipeline per session (so each
 * session keeps its prepared technique state and a camera move costs one
 * render; sessions are capped by --max-sessions, so pipelines are too).
 * Loop: under srv->lock pick the next session that needs work (a snapshot,
 * a state version not yet rendered, or a due still frame), copy its desired
 * state, unlock, render + read back + encode, lock, publish the frame as the
 * session's one latest frame (dropping the older one), unlock and wake the
 * service thread with lws_cancel_service. State that changed meanwhile is
 * simply rendered next time: the newest state wins, nothing is queued.
 * Interactive frames (camera phase start/move/end younger than
 * still_delay_ms) render at the scale interactive_scale.c picks from the
 * session's measured frame costs, at the interactive JPEG quality; once the
 * delay passes a full-size still frame follows. Sessions are picked round
 * robin so one busy session cannot starve another. Sessions on the same
 * dataset share one loaded copy (dataset_cache.c). A dataset that fails to
 * load leaves the pipeline on the last one that rendered; the session gets
 * load_failed and the service thread puts its scene back (s->good ->
 * revert_to). Never touches a socket.
 */
#include "sl_server.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <libwebsockets.h>

#include "core/sl_camera.h"
#include "core/sl_clock.h"
#include "core/sl_technique.h"
#include "gpu/sl_gpu.h"
#include "pipeline/sl_pipeline.h"

enum job_kind { JOB_NONE, JOB_FRAME, JOB_STILL, JOB_SNAPSHOT };

typedef struct render_ctx {
    sl_server *srv;
    sl_gpu *gpu;
    sl_encoder *enc;
    uint8_t *rgba;
    size_t rgba_cap;
    unsigned rr;          /* round-robin start */
    sl_dataset_cache datasets;
} render_ctx;

/* Picks work under the lock; fills *deadline_ms with the next still due time (or leaves it). */
static sl_session *pick_job(sl_server *srv, unsigned *rr, enum job_kind *kind, double now, double *deadline_ms)
{
    int n = 0;
    for (sl_session *s = srv->sessions; s; s = s->next)
        n++;
    if (n == 0)
        return NULL;
    for (int k = 0; k < n; k++) {
        int idx = (int)((*rr + (unsigned)k) % (unsigned)n);
        sl_session *s = srv->sessions;
        for (int i = 0; i < idx; i++)
            s = s->next;
        if (s->doomed)
            continue;
        double still_due = s->state.camera_ms + s->state.stream.still_delay_ms;
        if (s->snap_req_count > 0 && !s->snap_ready) {
            *kind = JOB_SNAPSHOT;
        } else if (s->state.version != s->rendered_version) {
            *kind = JOB_FRAME;
        } else if (s->rendered_interactive && now >= still_due) {
            *kind = JOB_STILL;
        } else {
            if (s->rendered_interactive && still_due < *deadline_ms)
                *deadline_ms = still_due;
            continue;
        }
        *rr = (unsigned)idx + 1;
        return s;
    }
    return NULL;
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
    h = fnv1a(h, st->params.tf, sizeof st->params.tf); /* transfer functions: unused entries are zero */
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

/* Creates the session's pipeline and gives it the dataset of st when its
 * source changed. On a load failure the pipeline keeps the dataset it had
 * and err holds the loader's reason (SL_ERR_FORMAT, SL_ERR_IO, ...). */
static sl_status ensure_dataset(render_ctx *ctx, sl_session *s, const sl_session_state *st, sl_err *err)
{
    sl_status rc;
    if (!s->pipeline && (rc = sl_pipeline_create(ctx->gpu, &s->pipeline, err)) != SL_OK)
        return rc;
    if (strcmp(s->loaded_source, st->dataset_source) == 0 && sl_pipeline_dataset(s->pipeline))
        return SL_OK;
    sl_dataset *ds = NULL;
    uint64_t loads = ctx->datasets.loads;
    if ((rc = sl_dataset_cache_get(&ctx->datasets, st->dataset_source, st->dataset_is_file, &ds, err)) != SL_OK)
        return rc;
    info_texts info;
    sl_catalog_describe(ds, &info.bounds, &info.counts, &info.attrs);
    sl_pipeline_set_dataset(s->pipeline, ds);
    snprintf(s->loaded_source, sizeof s->loaded_source, "%s", st->dataset_source);
    pthread_mutex_lock(&ctx->srv->lock);
    if (ctx->datasets.loads != loads)
        ctx->srv->metrics.dataset_loads++;
    else
        ctx->srv->metrics.dataset_cache_hits++;
    post_info_locked(s, &info, st->dataset);
    pthread_mutex_unlock(&ctx->srv->lock);
    return SL_OK;
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
 * if the desired state still names the failed source. The pipeline still
 * holds that scene's dataset, so the next frame renders it without a load. */
static void report_load_failure(render_ctx *ctx, sl_session *s, const sl_session_state *st, const sl_err *err)
{
    sl_server *srv = ctx->srv;
    char reason[400];
    strip_dir(err->message, st->dataset_source, reason, sizeof reason);
    int revert = s->has_good && strcmp(s->good.dataset_source, st->dataset_source) != 0;
    const sl_dataset *kept = revert && strcmp(s->loaded_source, s->good.dataset_source) == 0
                                 ? sl_pipeline_dataset(s->pipeline) : NULL;
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

/* Selects the technique and renders the session's dataset (ensure_dataset
 * first) at scale (1 = the session's size) with interactive or still
 * quality. *render_ms is the time of the render call, *prepare_ms the part
 * of it a technique prepare took. */
static sl_status render_state(render_ctx *ctx, sl_session *s, const sl_session_state *st, int interactive,
                              double scale, int *w_out, int *h_out, double *render_ms, double *prepare_ms,
                              sl_err *err)
{
    sl_status rc;
    const sl_dataset *ds = sl_pipeline_dataset(s->pipeline);
    const sl_technique *t = sl_technique_find(st->technique);
    if (!t)
        return sl_err_set(err, SL_ERR_INVALID, "technique \"%s\" is not in this build", st->technique);
    if ((rc = sl_pipeline_set_technique(s->pipeline, t, &st->params, err)) != SL_OK)
        return rc;
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
    if ((rc = sl_pipeline_render(s->pipeline, &view, 1, &stats, err)) != SL_OK)
        return rc;
    if ((rc = ensure_rgba(ctx, w, h, err)) != SL_OK)
        return rc;
    *w_out = w;
    *h_out = h;
    *render_ms = sl_clock_ms() - t0;
    *prepare_ms = stats.prepare_ms;
    return SL_OK;
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

/* --test-frame-delay-ms, --test-frame-fixed-ms: a render cost proportional
 * to the frame's pixels, and one that is not. */
static void test_delay(const sl_server *srv, const sl_session_state *st, int w, int h)
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
    double render_ms = 0, prepare_ms = 0, encode_ms = 0;
    double t0 = sl_clock_ms();
    sl_frame_buf *f = NULL;
    sl_iscale_sync(&s->iscale, scene_key(st), st->stream.interactive_scale);
    double scale = interactive ? sl_iscale_choose(&s->iscale, &st->stream, &step) : 1.0;
    if (ensure_dataset(ctx, s, st, &err) != SL_OK) {
        if (s->pipeline)
            report_load_failure(ctx, s, st, &err);
        else
            report_error(ctx->srv, s, st, &err);
        return;
    }
    if (render_state(ctx, s, st, interactive, scale, &w, &h, &render_ms, &prepare_ms, &err) != SL_OK) {
        report_error(ctx->srv, s, st, &err);
        return;
    }
    double t_read = sl_clock_ms();
    sl_pipeline_read_rgba(s->pipeline, ctx->rgba, 0);
    test_delay(ctx->srv, st, w, h);
    double t_done = sl_clock_ms();
    double cost_ms = render_ms - prepare_ms + (t_done - t_read);
    render_ms = t_done - t0;
    int quality = interactive ? st->stream.interactive_quality : st->stream.still_quality;
    int sub420 = interactive ? st->stream.interactive_420 : st->stream.still_420;
    if (sl_encoder_jpeg(ctx->enc, ctx->rgba, w, h, quality, sub420, &f, &encode_ms, &err) != SL_OK) {
        report_error(ctx->srv, s, st, &err);
        return;
    }
    sl_iscale_record(&s->iscale, interactive, step, cost_ms + encode_ms);
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
    sl_frame_buf_unref(s->latest);
    s->latest = f;
    s->rendered_version = st->version;
    s->rendered_interactive = interactive;
    srv->metrics.frames_rendered++;
    sl_histogram_add(&srv->metrics.render_ms, render_ms);
    sl_histogram_add(&srv->metrics.encode_ms, encode_ms);
    pthread_mutex_unlock(&srv->lock);
}

static void do_snapshot(render_ctx *ctx, sl_session *s, const sl_session_state *st, const int *ids, int n)
{
    sl_err err = {0};
    int w = 0, h = 0;
    double render_ms = 0, prepare_ms = 0, encode_ms = 0;
    sl_frame_buf *f = NULL;
    sl_server *srv = ctx->srv;
    if (ensure_dataset(ctx, s, st, &err) != SL_OK) {
        if (s->pipeline)
            report_load_failure(ctx, s, st, &err);
        else
            report_error(srv, s, st, &err);
        return;
    }
    if (render_state(ctx, s, st, 0, 1.0, &w, &h, &render_ms, &prepare_ms, &err) == SL_OK) {
        sl_pipeline_read_rgba(s->pipeline, ctx->rgba, 1);
        if (sl_encoder_png(ctx->rgba, w, h, &f, &encode_ms, &err) == SL_OK) {
            f->header.state_version = st->version;
            f->header.render_ms = (float)render_ms;
            f->header.camera_seq = st->camera_seq;
            sl_frame_header_write(&f->header, f->data);
        }
    }
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

/* Unlinks doomed sessions (lock held) and frees them with their pipelines. */
static void reap(sl_server *srv)
{
    sl_session **pp = &srv->sessions;
    while (*pp) {
        sl_session *s = *pp;
        if (s->doomed && !s->rendering) {
            *pp = s->next;
            sl_pipeline_destroy(s->pipeline);
            s->pipeline = NULL;
            sl_session_free(s);
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
    pthread_mutex_lock(&srv->lock);
    if (st != SL_OK) {
        srv->render_ready = -1;
        snprintf(srv->render_fail, sizeof srv->render_fail, "%.250s", err.message);
        pthread_cond_broadcast(&srv->wake);
        pthread_mutex_unlock(&srv->lock);
        sl_encoder_destroy(ctx.enc);
        sl_gpu_destroy(ctx.gpu);
        return NULL;
    }
    srv->render_ready = 1;
    snprintf(srv->gpu_renderer, sizeof srv->gpu_renderer, "%s", sl_gpu_renderer(ctx.gpu));
    pthread_cond_broadcast(&srv->wake);
    sl_session_state *copy = malloc(sizeof *copy);
    while (!srv->stop && copy) {
        reap(srv);
        double now = sl_clock_ms();
        double deadline = now + 1000.0;
        enum job_kind kind = JOB_NONE;
        sl_session *s = pick_job(srv, &ctx.rr, &kind, now, &deadline);
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
        int interactive = 0;
        if (kind == JOB_FRAME)
            interactive = copy->phase != SL_PHASE_NONE && now < copy->camera_ms + copy->stream.still_delay_ms;
        s->rendering = 1;
        pthread_mutex_unlock(&srv->lock);
        if (kind == JOB_SNAPSHOT)
            do_snapshot(&ctx, s, copy, ids, nids);
        else
            do_frame(&ctx, s, copy, interactive);
        lws_cancel_service(srv->lws);
        pthread_mutex_lock(&srv->lock);
        s->rendering = 0;
    }
    /* Shutdown: GL objects die on this thread; sessions are freed by the service thread. */
    for (sl_session *s = srv->sessions; s; s = s->next) {
        sl_pipeline_destroy(s->pipeline);
        s->pipeline = NULL;
    }
    reap(srv);
    pthread_mutex_unlock(&srv->lock);
    sl_dataset_cache_deinit(&ctx.datasets);
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
