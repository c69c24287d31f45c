/* record.c — recording jobs: a camera path rendered into a video in the background of a session.
 *
 * A controller sends `record` {path, format, crf}; the job (one per session:
 * a second one while the first runs is `busy`) is checked here against the
 * session's technique and the limits, then the render thread renders one of
 * its frames whenever that session has nothing else due (render.c
 * do_record), so interactive frames keep flowing to every client while it
 * runs. Each step posts the session's newest `recording` text (newest wins:
 * a slow client skips intermediate frame counts, never the final state).
 * The finished file is served once over HTTP, GET /recording/KEY?token=T
 * with the session's token, and removed after; cancelled, failed and
 * undownloaded files are removed with the job (a new job, or the session's
 * end). Service thread, except sl_record_free (whoever frees the session). The
 * job's status texts are render/record_status.c's (both threads post them).
 */
#include "sl_sessions.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/sl_technique.h"
#include "image/sl_video.h"
#include "sl_scene_path.h"

sl_status sl_record_create(sl_server *srv, sl_session *s, const cJSON *path, const char *format, int crf,
                           sl_record_job **out, sl_err *err)
{
    *out = NULL;
    if (!srv->record_dir[0])
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "this server has no folder for recordings");
    const sl_technique *t = sl_technique_find(s->slot.state.technique);
    if (!t)
        return sl_err_set(err, SL_ERR_INVALID, "technique %s is not in this build", s->slot.state.technique);
    sl_scene_path *p = NULL;
    sl_status st = sl_scene_path_parse(path, t, &p, err);
    if (st != SL_OK)
        return st;
    int frames = sl_scene_path_frames(p);
    double pixels = (double)frames * s->slot.state.width * s->slot.state.height;
    if (frames > SL_RECORD_MAX_FRAMES || pixels > SL_RECORD_MAX_PIXELS) {
        sl_scene_path_destroy(p);
        return sl_err_set(err, SL_ERR_INVALID, "path: %d frames of %dx%d; a recording holds at most %d frames and "
                          "%.0f pixels in all (3600 frames of 1920x1080)", frames, s->slot.state.width, s->slot.state.height,
                          SL_RECORD_MAX_FRAMES, SL_RECORD_MAX_PIXELS);
    }
    sl_record_job *j = calloc(1, sizeof *j);
    if (!j) {
        sl_scene_path_destroy(p);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    }
    j->id = ++srv->next_record_id;
    j->path = p;
    j->base = s->slot.state;
    j->frames = frames;
    j->crf = crf;
    snprintf(j->format, sizeof j->format, "%s", format);
    sl_random_hex(j->key, 16);
    snprintf(j->file, sizeof j->file, "%s/%s-%u.%s", srv->record_dir, s->id, j->id, format);
    st = sl_video_check(&(sl_video_desc){j->file, s->slot.state.width, s->slot.state.height, p->fps, crf}, err);
    if (st != SL_OK) {
        sl_record_free(j);
        return st;
    }
    *out = j;
    return SL_OK;
}

void sl_record_free(sl_record_job *j)
{
    if (!j)
        return;
    if (j->writer)
        sl_video_abort(j->writer); /* removes its partial file */
    else if (j->file[0])
        unlink(j->file);           /* a finished file nobody fetched (ENOENT when it was) */
    sl_scene_path_destroy(j->path);
    free(j);
}

int sl_record_take_download(sl_server *srv, const char *key, const char *token, char *file, size_t size,
                            const char **mime)
{
    int status = 404;
    pthread_mutex_lock(&srv->lock);
    for (sl_session *s = sl_sessions_first(srv); s; s = sl_session_next(s)) {
        sl_record_job *j = s->slot.record;
        if (s->slot.doomed || !j || strcmp(j->key, key) != 0)
            continue;
        if (!j->finished || !j->file[0])
            status = j->finished ? 410 : 404;
        else if (strcmp(s->token, token) != 0)
            status = 403;
        else if (!j->ok)
            status = 410;
        else {
            status = 200;
            snprintf(file, size, "%s", j->file);
            *mime = strcmp(j->format, "webm") == 0 ? "video/webm" : "video/mp4";
            j->ok = 0; /* one download: the caller serves the file and removes it */
        }
        break;
    }
    pthread_mutex_unlock(&srv->lock);
    return status;
}
