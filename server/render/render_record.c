/* render_record.c — a recording job's frames on the render thread: each call renders the next
 * frame of the job's path into its video writer (the session's interactive frames keep going
 * between calls), finishes the file after the last, or removes it when cancelled or failed;
 * the job's `recording` texts say which. Render thread. */
#include "sl_render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libwebsockets.h>

#include "core/sl_technique.h"
#include "image/sl_video.h"
#include "pipeline/sl_pipeline.h"
#include "render_internal.h"
#include "sl_params_json.h"
#include "sl_scene_path.h"

/* Ends the session's recording job with `state` (and extra fields, consumed). */
static void record_finish(sl_server *srv, sl_render_slot *s, sl_record_job *j, const char *state, int ok, cJSON *extra)
{
    pthread_mutex_lock(&srv->lock);
    j->finished = 1;
    j->ok = ok;
    sl_record_status_locked(s, j, state, extra);
    pthread_mutex_unlock(&srv->lock);
}

static void record_fail(sl_server *srv, sl_render_slot *s, sl_record_job *j, int frame, const sl_err *err)
{
    sl_video_abort(j->writer);
    j->writer = NULL;
    cJSON *x = cJSON_CreateObject();
    char msg[600];
    snprintf(msg, sizeof msg, "frame %d: %.560s", frame, err->message);
    cJSON_AddStringToObject(x, "message", msg);
    record_finish(srv, s, j, "failed", 0, x);
}

/* One frame of the session's recording job at full still quality (or its
 * cancel): the job's base state with the path's camera and parameters at
 * t = frame / fps, through the session's prepared scene (ready_scene
 * switches scenes when a keyed parameter needs another prepare: costly,
 * as scene.md says). The session's latest frame and state are untouched. */
void sl_render_record(render_ctx *ctx, sl_render_slot *s, sl_record_job *j, int cancel)
{
    sl_server *srv = ctx->srv;
    if (cancel) {
        sl_video_abort(j->writer);
        j->writer = NULL;
        record_finish(srv, s, j, "cancelled", 0, NULL);
        return;
    }
    sl_err err = {0};
    int f = j->next_frame;
    double t = f / j->path->fps;
    sl_session_state *st = malloc(sizeof *st);
    if (!st) {
        sl_err_set(&err, SL_ERR_NOMEM, "out of memory");
        record_fail(srv, s, j, f, &err);
        return;
    }
    *st = j->base;
    const sl_technique *tech = sl_technique_find(st->technique);
    cJSON *keyed = tech ? sl_scene_path_params(j->path, t, NULL, tech) : NULL;
    sl_status rc = keyed ? sl_params_apply_json(&st->params, keyed, &err)
                         : sl_err_set(&err, SL_ERR_NOMEM, "no parameters at t = %g", t);
    cJSON_Delete(keyed);
    if (rc == SL_OK && !sl_render_ready_scene(ctx, s, st)) {
        free(st); /* waiting for a load (tried again later) or failed (reported to the session) */
        if (!s->load) {
            cJSON *x = cJSON_CreateObject();
            cJSON_AddStringToObject(x, "message", "the recording's scene could not be prepared (the session's "
                                                  "render_failed error says why)");
            record_finish(srv, s, j, "failed", 0, x);
        }
        return;
    }
    const sl_dataset *ds = rc == SL_OK ? s->prepared->dataset : NULL;
    if (rc == SL_OK)
        rc = sl_camera_path_at(j->path->keys, j->path->key_count, j->path->interpolation, t, ds->bounds_min,
                               ds->bounds_max, &st->camera, &err);
    if (rc == SL_OK && !j->writer) {
        rc = sl_video_open(&(sl_video_desc){j->file, st->width, st->height, j->path->fps, j->crf}, &j->writer, &err);
        j->t0_ms = sl_clock_ms();
    }
    int w = 0, h = 0;
    double render_ms = 0;
    const char *backend = NULL;
    if (rc == SL_OK)
        rc = sl_render_view(ctx, s, st, 0, 1.0, &w, &h, &render_ms, &backend, &err);
    if (rc == SL_OK) {
        sl_pipeline_read_rgba(s->prepared->pipeline, ctx->rgba, 1);
        sl_render_test_delay(srv, st, w, h);
        rc = sl_video_write_rgba(j->writer, ctx->rgba, &err);
    }
    free(st);
    if (rc != SL_OK) {
        record_fail(srv, s, j, f, &err);
        return;
    }
    j->next_frame++;
    double spent = (sl_clock_ms() - j->t0_ms) / 1000.0;
    if (j->next_frame < j->frames) {
        cJSON *x = cJSON_CreateObject();
        cJSON_AddNumberToObject(x, "frame", j->next_frame);
        cJSON_AddNumberToObject(x, "elapsed_s", spent);
        cJSON_AddNumberToObject(x, "eta_s", spent / j->next_frame * (j->frames - j->next_frame));
        pthread_mutex_lock(&srv->lock);
        sl_record_status_locked(s, j, "running", x);
        pthread_mutex_unlock(&srv->lock);
        return;
    }
    sl_video_summary sum;
    rc = sl_video_close(j->writer, &sum, &err);
    j->writer = NULL;
    if (rc != SL_OK) {
        record_fail(srv, s, j, f, &err);
        return;
    }
    cJSON *x = cJSON_CreateObject();
    char url[64];
    snprintf(url, sizeof url, "/recording/%s", j->key);
    cJSON_AddNumberToObject(x, "frame", j->frames);
    cJSON_AddNumberToObject(x, "elapsed_s", spent);
    cJSON_AddStringToObject(x, "url", url);
    cJSON_AddNumberToObject(x, "bytes", (double)sum.bytes);
    cJSON_AddNumberToObject(x, "seconds", sum.seconds);
    cJSON_AddStringToObject(x, "codec", sum.codec);
    cJSON_AddNumberToObject(x, "crf", sum.crf);
    record_finish(srv, s, j, "done", 1, x);
}
