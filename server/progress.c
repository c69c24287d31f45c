/* progress.c — a session's long work (load, prepare, first frame) told to its clients.
 *
 * Render thread. One round is the work between a desired state that needs
 * a dataset load or a technique prepare and the frame that shows it (or its
 * end without one: a failed load, a failed prepare, a newer state that no
 * longer needs it). Each round posts its stages in order — loading (only
 * when a load is waited for), preparing, first_frame, done — at most once
 * each, as ready-made `progress` texts kept on the session under srv->lock
 * (at most SL_PROGRESS_EVENTS per round); session.c sends every client each
 * text of the current round once, in order, and a newer round replaces the
 * older one. A post wakes the service thread at once, so the message leaves
 * before the long step it announces starts.
 */
#include "sl_server.h"

#include <stdlib.h>
#include <string.h>

#include <libwebsockets.h>

static void post(sl_server *srv, sl_session *s, sl_progress_stage stage, double render_ms, uint32_t frame, int ok)
{
    sl_progress_round *r = &s->round;
    sl_msg_progress m = {.stage = stage, .round = r->id, .version = r->version, .dataset = r->dataset,
                         .technique = r->technique, .fraction = -1, .elapsed_ms = sl_clock_ms() - r->t0_ms,
                         .load_ms = r->load_ms, .prepare_ms = r->prepare_ms, .render_ms = render_ms,
                         .frame = frame, .ok = ok};
    char *text = sl_msg_progress_text(&m);
    pthread_mutex_lock(&srv->lock);
    if (text && s->progress_count < SL_PROGRESS_EVENTS && s->progress_round == r->id) {
        s->progress_text[s->progress_count++] = text;
        s->progress_closed = stage == SL_PROGRESS_DONE;
        text = NULL;
    }
    pthread_mutex_unlock(&srv->lock);
    free(text);
    lws_cancel_service(srv->lws);
}

void sl_progress_begin(sl_server *srv, sl_session *s, const sl_session_state *st)
{
    if (s->round.active)
        sl_progress_end(srv, s, 0, 0, 0);
    sl_progress_round *r = &s->round;
    char *old[SL_PROGRESS_EVENTS];
    pthread_mutex_lock(&srv->lock);
    int n = s->progress_count;
    memcpy(old, s->progress_text, sizeof old);
    memset(s->progress_text, 0, sizeof s->progress_text);
    s->progress_count = 0;
    s->progress_closed = 0;
    r->id = ++s->progress_round;
    pthread_mutex_unlock(&srv->lock);
    for (int i = 0; i < n; i++)
        free(old[i]);
    r->active = 1;
    r->version = st->version;
    memcpy(r->dataset, st->dataset, sizeof r->dataset);
    memcpy(r->technique, st->technique, sizeof r->technique);
    r->t0_ms = sl_clock_ms();
    r->load_ms = r->prepare_ms = 0;
    r->stage = -1;
}

void sl_progress_stage_post(sl_server *srv, sl_session *s, sl_progress_stage stage)
{
    if (!s->round.active || (int)stage <= s->round.stage || stage == SL_PROGRESS_DONE)
        return;
    s->round.stage = (int)stage;
    post(srv, s, stage, 0, 0, 0);
}

void sl_progress_end(sl_server *srv, sl_session *s, int ok, double render_ms, uint32_t frame)
{
    if (!s->round.active)
        return;
    s->round.active = 0;
    s->round.stage = SL_PROGRESS_DONE;
    post(srv, s, SL_PROGRESS_DONE, render_ms, frame, ok);
}
