/* session_drain.c — the end of sessions: the grace-period sweep, draining (SIGTERM: no new
 * sessions, checkpoints handed over at the end) and the teardown at exit. Service thread. */
#include "sl_sessions.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sl_sessions_sweep(sl_server *srv)
{
    double now = sl_clock_ms();
    /* One expired session per pass under the lock; its catalog row is deleted
     * after unlocking, so a WAL commit never stalls the render thread. */
    for (;;) {
        char id[SL_SESSION_ID_SIZE] = "";
        pthread_mutex_lock(&srv->lock);
        for (sl_session *s = sl_sessions_first(srv); s && !id[0]; s = sl_session_next(s)) {
            if (s->slot.doomed || s->client_count > 0 || now - s->empty_since_ms < srv->cfg.grace_s * 1000.0)
                continue;
            memcpy(id, s->id, sizeof id);
            s->slot.doomed = 1;   /* the render thread may free it from here on */
            srv->session_count--;
            pthread_cond_signal(&srv->wake);
        }
        pthread_mutex_unlock(&srv->lock);
        if (!id[0])
            break;
        sl_err err = {0};
        if (sl_catalog_session_remove(srv->db, id, &err) != SL_OK)
            fprintf(stderr, "sightline-server: %s\n", err.message);
    }
}

void sl_sessions_destroy_all(sl_server *srv)
{
    pthread_mutex_lock(&srv->lock);
    sl_render_slot *s = srv->slots;
    srv->slots = NULL;
    pthread_mutex_unlock(&srv->lock);
    while (s) {
        sl_render_slot *next = s->next;
        s->destroy(s);
        s = next;
    }
}

void sl_sessions_drain_begin(sl_server *srv)
{
    pthread_mutex_lock(&srv->lock);
    srv->draining = 1;
    int sessions = srv->session_count, clients = srv->client_count;
    pthread_mutex_unlock(&srv->lock);
    srv->drain_start_ms = sl_clock_ms();
    fprintf(stderr, "sightline-server: draining (SIGTERM): %d session(s), %d client(s); no new sessions; "
            "a second SIGTERM stops at once\n", sessions, clients);
}

int sl_sessions_drain_done(sl_server *srv)
{
    int busy = 0;
    pthread_mutex_lock(&srv->lock);
    for (sl_session *s = sl_sessions_first(srv); s && !busy; s = sl_session_next(s))
        busy = !s->slot.doomed && s->client_count > 0;
    pthread_mutex_unlock(&srv->lock);
    if (busy && sl_clock_ms() - srv->drain_start_ms < srv->cfg.grace_s * 1000.0)
        return 0;
    /* What stays is handed over: each checkpoint is current, so the node a
     * client reaches next restores the session as it was. */
    pthread_mutex_lock(&srv->lock);
    int n = 0, cap = srv->session_count;
    sl_session **live = cap > 0 ? malloc(sizeof *live * (size_t)cap) : NULL;
    for (sl_session *s = sl_sessions_first(srv); s && live && n < cap; s = sl_session_next(s))
        if (!s->slot.doomed)
            live[n++] = s;
    pthread_mutex_unlock(&srv->lock);
    for (int i = 0; i < n; i++) /* valid outside the lock: only this thread dooms a session */
        sl_checkpoint_write(srv, live[i]);
    free(live);
    fprintf(stderr, "sightline-server: drained%s\n", busy ? " (--grace passed; clients left are closed)" : "");
    return 1;
}
