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
 * scene back (s->good -> revert_to). The steps of a frame it shares with
 * render_record.c are render_scene.c's. It sees a session only as its render
 * slot (sl_render.h) and never touches a socket.
 */
#include "sl_render.h"

#include <errno.h>
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>


#include "core/sl_camera.h"
#include "core/sl_clock.h"
#include "core/sl_hash.h"
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
static int waiting_for_load(render_ctx *ctx, const sl_render_slot *s)
{
    return s->load && strcmp(sl_dataset_load_source(s->load), s->state.dataset_source) == 0 &&
           !sl_dataset_load_poll(ctx->datasets, s->load, NULL, NULL, NULL, NULL);
}

/* Picks work under the lock; fills *deadline_ms with the next still due time (or leaves it). */
static sl_render_slot *pick_job(render_ctx *ctx, enum job_kind *kind, double now, double *deadline_ms)
{
    sl_server *srv = ctx->srv;
    int n = 0;
    for (sl_render_slot *s = srv->slots; s; s = s->next)
        n++;
    if (n == 0)
        return NULL;
    for (int k = 0; k < n; k++) {
        int idx = (int)((ctx->rr + (unsigned)k) % (unsigned)n);
        sl_render_slot *s = srv->slots;
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
    for (sl_render_slot *s = srv->slots; s; s = s->next) {
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

/* What the interactive scale's estimates depend on besides the camera:
 * dataset, technique, parameter values and image size. */
static uint64_t scene_key(const sl_session_state *st)
{
    uint64_t h = SL_FNV1A_SEED;
    h = sl_fnv1a(h, st->dataset_source, strlen(st->dataset_source) + 1);
    h = sl_fnv1a(h, st->technique, strlen(st->technique) + 1);
    h = sl_fnv1a(h, st->params.value, sizeof st->params.value[0] * (size_t)st->params.count);
    h = sl_fnv1a(h, st->params.value_count, sizeof st->params.value_count[0] * (size_t)st->params.count);
    h = sl_fnv1a(h, st->params.tf, sizeof st->params.tf); /* transfer functions: unused entries are zero */
    h = sl_fnv1a(h, &st->params.tf2d.count, sizeof st->params.tf2d.count); /* field by field: no padding */
    h = sl_fnv1a(h, &st->params.tf2d.range, sizeof st->params.tf2d.range);
    h = sl_fnv1a(h, st->params.tf2d.widget, sizeof st->params.tf2d.widget); /* unused widgets are zero */
    h = sl_fnv1a(h, &st->width, sizeof st->width);
    return sl_fnv1a(h, &st->height, sizeof st->height);
}

/* A dataset's description (sl_catalog_describe: bounds, counts, attribute
 * names), made outside the lock and posted under it. */

static void do_frame(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st, int interactive)
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
        sl_render_report_error(ctx->srv, s, st, &err);
        return;
    }
    sl_pipeline_read_rgba(s->prepared->pipeline, ctx->rgba, 0);
    sl_render_test_delay(ctx->srv, st, w, h);
    render_ms = sl_clock_ms() - t0;
    int quality = interactive ? st->stream.interactive_quality : st->stream.still_quality;
    int sub420 = interactive ? st->stream.interactive_420 : st->stream.still_420;
    if (sl_encoder_jpeg(ctx->enc, ctx->rgba, w, h, quality, sub420, &f, &encode_ms, &err) != SL_OK) {
        sl_progress_end(ctx->srv, s, 0, 0, 0);
        sl_render_report_error(ctx->srv, s, st, &err);
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
static void requeue_snapshots(sl_server *srv, sl_render_slot *s, const int *ids, int n)
{
    pthread_mutex_lock(&srv->lock);
    for (int i = 0; i < n && s->snap_req_count < SL_SESSION_MAX_SNAPSHOTS; i++)
        s->snap_req[s->snap_req_count++] = ids[i];
    pthread_mutex_unlock(&srv->lock);
}

static void do_snapshot(render_ctx *ctx, sl_render_slot *s, const sl_session_state *st, const int *ids, int n)
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
static void release_slot(render_ctx *ctx, sl_render_slot *s)
{
    sl_prepared_release(&ctx->prepared, s->prepared);
    s->prepared = NULL;
    sl_dataset_load_release(ctx->datasets, s->load);
    s->load = NULL;
}

/* Unlinks doomed sessions (lock held) and frees them with their scenes. */
static void reap(render_ctx *ctx)
{
    sl_render_slot **pp = &ctx->srv->slots;
    while (*pp) {
        sl_render_slot *s = *pp;
        if (s->doomed && !s->rendering) {
            *pp = s->next;
            release_slot(ctx, s);
            s->destroy(s);
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
        sl_render_slot *s = pick_job(&ctx, &kind, now, &deadline);
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
    for (sl_render_slot *s = srv->slots; s; s = s->next)
        release_slot(&ctx, s);
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
