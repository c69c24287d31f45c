/* session_paths.c — the handlers of the messages about camera paths and recordings: record,
 * record_cancel, play_path / play_stop / path_seek (playback.c does the work), save_path,
 * load_path. Control is checked by the dispatch (session.c). Service thread. */
#include "sl_sessions.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#include "session_internal.h"
#include "core/sl_technique.h"
#include "sl_scene_path.h"

/* record: a new recording job of the session (one at a time). */
void sl_on_record(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    pthread_mutex_lock(&srv->lock);
    int busy = s->slot.record && !s->slot.record->finished;
    pthread_mutex_unlock(&srv->lock);
    if (busy) {
        sl_client_send_error(srv, c, "busy", "a recording is already running in this session (record_cancel stops it)", "type");
        return;
    }
    sl_record_job *j = NULL;
    sl_err err = {0};
    if (sl_record_create(srv, s, m->path, m->format, m->crf, &j, &err) != SL_OK) {
        sl_client_send_error(srv, c, "bad_field", err.message, "path");
        return;
    }
    pthread_mutex_lock(&srv->lock);
    sl_record_job *old = s->slot.record; /* finished: no thread works on it */
    s->slot.record = j;
    sl_record_status_locked(&s->slot, j, "queued", NULL);
    pthread_cond_signal(&srv->wake);
    pthread_mutex_unlock(&srv->lock);
    sl_record_free(old);
    for (sl_client *o = s->clients; o; o = o->next)
        sl_client_wake(o);
}

/* record_cancel: stops the running job (its partial file is removed). */
void sl_on_record_cancel(sl_server *srv, sl_client *c, const sl_msg *m)
{
    (void)m;
    sl_session *s = c->session;
    pthread_mutex_lock(&srv->lock);
    int running = s->slot.record && !s->slot.record->finished;
    if (running) {
        s->slot.record->cancel = 1;
        pthread_cond_signal(&srv->wake);
    }
    pthread_mutex_unlock(&srv->lock);
    if (!running)
        sl_client_send_error(srv, c, "bad_field", "no recording is running in this session", "type");
}

/* play_path, play_stop, path_seek (controller): playback.c does the work. */
void sl_on_play(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_err err = {0};
    sl_status st = SL_OK;
    if (m->type == SL_MSG_PLAY_STOP) {
        if (!s->play)
            sl_client_send_error(srv, c, "bad_field", "no path is playing in this session", "type");
        sl_play_stop(srv, s, "play_stop");
        return;
    }
    if (m->type == SL_MSG_PLAY_PATH)
        st = sl_play_start(srv, s, m->path, m->loop, &err);
    else
        st = sl_play_seek(srv, s, m->path, m->t, &err);
    if (st != SL_OK)
        sl_client_send_error(srv, c, st == SL_ERR_NOMEM ? "internal" : "bad_field", err.message, "path");
}

/* save_path (controller): the path checked against the session's technique, stored by name. */
void sl_on_save_path(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_err err = {0};
    const sl_technique *t = sl_technique_find(s->slot.state.technique);
    sl_scene_path *p = NULL;
    if (!t || sl_scene_path_parse(m->path, t, &p, &err) != SL_OK) {
        sl_client_send_error(srv, c, "bad_field", t ? err.message : "the session's technique is not in this build", "path");
        return;
    }
    char *text = cJSON_PrintUnformatted(m->path);
    if (text && strlen(text) > SL_CATALOG_MAX_PATH_BYTES) {
        char msg[160];
        snprintf(msg, sizeof msg, "path: %zu bytes of JSON; a saved path holds at most %d", strlen(text),
                 SL_CATALOG_MAX_PATH_BYTES);
        sl_client_send_error(srv, c, "limit", msg, "path");
        free(text);
        sl_scene_path_destroy(p);
        return;
    }
    sl_status st = text ? sl_catalog_save_path(srv->db, m->name, t->name, text, p->key_count,
                                               p->keys[p->key_count - 1].t, &err)
                        : sl_err_set(&err, SL_ERR_NOMEM, "out of memory writing the path");
    free(text);
    sl_scene_path_destroy(p);
    if (st != SL_OK)
        sl_client_send_error(srv, c, st == SL_ERR_LIMIT ? "limit" : "internal", err.message, "name");
    else
        sl_client_queue_text(c, sl_msg_named_text("path_saved", m->name, NULL));
}

/* load_path (any client): the stored path, to the requester only. */
void sl_on_load_path(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_err err = {0};
    cJSON *p = NULL;
    if (sl_catalog_load_path(srv->db, m->name, &p, &err) != SL_OK || !p) {
        sl_client_send_error(srv, c, p ? "internal" : "not_found", p ? err.message : "no saved path with that name", "name");
        cJSON_Delete(p);
        return;
    }
    sl_client_queue_text(c, sl_msg_named_text("path", m->name, p));
}
