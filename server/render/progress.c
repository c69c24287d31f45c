/* progress.c — a session's long work (load, prepare, first frame) told to its clients.
 *
 * Render thread. One round is the work between a desired state that needs
 * a dataset load or a technique prepare and the frame that shows it (or its
 * end without one: a failed load, a failed prepare, a newer state that no
 * longer needs it). Each round posts its stages in order — loading (only
 * when a load is waited for), preparing, first_frame, done — at most once
 * each, as ready-made `progress` texts numbered per session and kept under
 * srv->lock in a ring of the newest SL_PROGRESS_RING (two rounds); session.c
 * sends every client each text once, in order (a client more than a ring
 * behind skips the oldest). A post wakes the service thread at once, so the
 * message leaves before the long step it announces starts.
 */
#include "sl_render.h"

#include <stdlib.h>
#include <string.h>


static void post(sl_server *srv, sl_render_slot *s, sl_progress_stage stage, double render_ms, uint32_t frame, int ok)
{
    sl_progress_round *r = &s->round;
    sl_msg_progress m = {.stage = stage, .round = r->id, .version = r->version, .dataset = r->dataset,
                         .technique = r->technique, .fraction = -1, .elapsed_ms = sl_clock_ms() - r->t0_ms,
                         .load_ms = r->load_ms, .prepare_ms = r->prepare_ms, .render_ms = render_ms,
                         .frame = frame, .ok = ok, .backend = r->backend};
    char *text = sl_msg_progress_text(&m), *old = NULL;
    if (!text)
        return;
    pthread_mutex_lock(&srv->lock);
    uint32_t seq = ++s->progress_seq;
    old = s->progress_text[seq % SL_PROGRESS_RING];
    s->progress_text[seq % SL_PROGRESS_RING] = text;
    s->progress_closed = stage == SL_PROGRESS_DONE;
    pthread_mutex_unlock(&srv->lock);
    free(old);
    if (srv->transport.wake_service)
        srv->transport.wake_service(srv);
}

void sl_progress_begin(sl_server *srv, sl_render_slot *s, const sl_session_state *st)
{
    if (s->round.active)
        sl_progress_end(srv, s, 0, 0, 0);
    sl_progress_round *r = &s->round;
    pthread_mutex_lock(&srv->lock);
    s->progress_round_start = s->progress_seq;
    s->progress_closed = 0;
    r->id = ++s->progress_round;
    pthread_mutex_unlock(&srv->lock);
    r->active = 1;
    r->version = st->version;
    memcpy(r->dataset, st->dataset, sizeof r->dataset);
    memcpy(r->technique, st->technique, sizeof r->technique);
    r->t0_ms = sl_clock_ms();
    r->load_ms = r->prepare_ms = 0;
    r->stage = -1;
}

void sl_progress_stage_post(sl_server *srv, sl_render_slot *s, sl_progress_stage stage)
{
    if (!s->round.active || (int)stage <= s->round.stage || stage == SL_PROGRESS_DONE)
        return;
    s->round.stage = (int)stage;
    post(srv, s, stage, 0, 0, 0);
}

void sl_progress_end(sl_server *srv, sl_render_slot *s, int ok, double render_ms, uint32_t frame)
{
    if (!s->round.active)
        return;
    s->round.active = 0;
    s->round.stage = SL_PROGRESS_DONE;
    post(srv, s, SL_PROGRESS_DONE, render_ms, frame, ok);
}
