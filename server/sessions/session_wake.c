/* session_wake.c — sl_sessions_on_wake (sl_server.h): what the render thread left for the
 * service thread: new frames and snapshots to dispatch, failed loads to revert, checkpoints
 * due, dataset descriptions to store and broadcast. Service thread. */
#include "sl_sessions.h"

#include <stdlib.h>
#include <string.h>


#include "session_internal.h"

/* Dataset loads that failed (render.c): the session goes back to the last
 * scene that rendered, unless its desired dataset changed since. The bounds
 * follow as the render thread's description of the kept dataset. */
static void apply_reverts(sl_server *srv)
{
    for (;;) {
        sl_session *s = NULL;
        pthread_mutex_lock(&srv->lock);
        for (sl_session *t = sl_sessions_first(srv); t && !s; t = sl_session_next(t))
            if (!t->slot.doomed && t->slot.revert_pending)
                s = t;
        int reverted = 0;
        if (s) {
            s->slot.revert_pending = 0;
            sl_session_state *st = &s->slot.state;
            const sl_session_state *to = &s->slot.revert_to;
            if (strcmp(st->dataset_source, s->slot.revert_failed_source) == 0) {
                memcpy(st->dataset, to->dataset, sizeof st->dataset);
                memcpy(st->dataset_source, to->dataset_source, sizeof st->dataset_source);
                st->dataset_is_file = to->dataset_is_file;
                st->dataset_kind = to->dataset_kind;
                memcpy(st->technique, to->technique, sizeof st->technique);
                st->params = to->params;
                st->phase = SL_PHASE_NONE;
                sl_session_state_changed_locked(srv, s);
                reverted = 1;
            }
        }
        pthread_mutex_unlock(&srv->lock);
        if (!s)
            return;
        if (!reverted)
            continue;
        cJSON_Delete(s->bounds);
        s->bounds = NULL;
        cJSON *full = sl_session_state_json(s);
        cJSON_DeleteItemFromObjectCaseSensitive(full, "stream");
        sl_session_broadcast_patch(s, full);
    }
}

void sl_sessions_on_wake(sl_server *srv)
{
    pthread_mutex_lock(&srv->lock);
    for (sl_session *s = sl_sessions_first(srv); s; s = sl_session_next(s)) {
        if (s->slot.doomed)
            continue;
        if (s->slot.latest && s->slot.latest->header.frame_id != s->dispatched_frame) {
            s->dispatched_frame = s->slot.latest->header.frame_id;
            for (sl_client *c = s->clients; c; c = c->next)
                sl_client_wake(c);
        }
        if (s->slot.snap_ready) {
            for (int i = 0; i < s->slot.snap_ready_count; i++) {
                sl_client *c = s->slot.snap_ready_ids[i] ? sl_session_find_client(s, s->slot.snap_ready_ids[i]) : NULL;
                if (c && !c->snapshot) {
                    sl_frame_buf_ref(s->slot.snap_ready);
                    c->snapshot = s->slot.snap_ready;
                    sl_client_wake(c);
                }
            }
            sl_frame_buf_unref(s->slot.snap_ready);
            s->slot.snap_ready = NULL;
            s->slot.snap_ready_count = 0;
        }
        /* The session's newest render error is sent by write_next (coalesced:
         * a client that is behind gets the latest error once, not a backlog). */
        for (sl_client *c = s->clients; c; c = c->next)
            if (c->error_seq != s->slot.error_seq || c->progress_seq != s->slot.progress_seq || c->record_seq != s->slot.record_seq)
                sl_client_wake(c);
    }
    pthread_mutex_unlock(&srv->lock);
    apply_reverts(srv);
    /* Checkpoints the render thread asked for (a still frame of a new state
     * version): written here, outside the lock, one session per pass. */
    for (;;) {
        sl_session *s = NULL;
        pthread_mutex_lock(&srv->lock);
        for (sl_session *t = sl_sessions_first(srv); t && !s; t = sl_session_next(t))
            if (!t->slot.doomed && t->slot.checkpoint_due)
                s = t;
        if (s)
            s->slot.checkpoint_due = 0;
        pthread_mutex_unlock(&srv->lock);
        if (!s)
            break;
        sl_checkpoint_write(srv, s);
    }
    /* Dataset descriptions from the render thread: taken under the lock, written
     * to the catalog and broadcast outside it (SQLite must not stall rendering). */
    for (;;) {
        sl_session *s = NULL;
        char *bounds = NULL, *counts = NULL, *attrs = NULL, name[SL_PROTO_NAME_MAX];
        pthread_mutex_lock(&srv->lock);
        for (sl_session *t = sl_sessions_first(srv); t && !s; t = sl_session_next(t)) {
            if (!t->slot.doomed && t->slot.info_pending) {
                s = t;
                s->slot.info_pending = 0;
                bounds = s->slot.info_bounds;
                counts = s->slot.info_counts;
                attrs = s->slot.info_attrs;
                s->slot.info_bounds = s->slot.info_counts = s->slot.info_attrs = NULL;
                memcpy(name, s->slot.info_dataset, sizeof name);
            }
        }
        pthread_mutex_unlock(&srv->lock);
        if (!s)
            break;
        sl_err err = {0};
        if (bounds && counts && attrs)
            sl_catalog_set_info(srv->db, name, bounds, counts, attrs, &err);
        cJSON *b = bounds ? cJSON_Parse(bounds) : NULL;
        if (b && strcmp(name, s->slot.state.dataset) == 0) {
            cJSON_Delete(s->bounds);
            s->bounds = b;
            cJSON *p = cJSON_CreateObject();
            cJSON_AddItemToObject(p, "bounds", cJSON_Duplicate(b, 1));
            sl_session_broadcast_patch(s, p);
        } else {
            cJSON_Delete(b);
        }
        free(bounds);
        free(counts);
        free(attrs);
    }
}
