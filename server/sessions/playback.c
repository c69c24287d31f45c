/* playback.c — a camera path played live in a session, seen by every client (PROTOCOL.md "Playback").
 *
 * play_path makes the session's own camera (and its keyed parameters)
 * follow a path in real time: sl_play_tick, run by a service-thread timer
 * (ws.c), sets the state to the path at frame k = floor(elapsed · fps),
 * t = k / fps (the times a recording of the path renders), once per frame
 * that came due, with the camera phase `move` (interactive frames). The
 * render thread renders the newest state as always, so when it is slower
 * than the path's fps it skips frames and playback keeps time. The last key
 * ends playback with a still at t_last (or, with loop, starts again).
 * path_seek sets the state to the path at one t. Cameras and parameters
 * come from core/sl_camera_path.h and proto/sl_scene_path.h only: the page
 * holds no copy of the interpolation. Every change reaches the clients as
 * the state patch; `playback` texts (newest wins, s->play_text) say
 * "playing t / T" and "stopped". Does not record: record.c does.
 * Service thread only (the state's one writer); the render thread never
 * reads these fields.
 */
#include "sl_sessions.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


#include "core/sl_camera_path.h"
#include "core/sl_technique.h"
#include "sl_params_json.h"
#include "sl_scene_path.h"

static double path_duration(const sl_scene_path *p)
{
    return p->keys[p->key_count - 1].t;
}

/* Replaces the session's playback text (consumed) and wakes its clients to send it. */
static void post_text(sl_session *s, char *text)
{
    if (!text)
        return;
    free(s->play_text);
    s->play_text = text;
    s->play_seq++;
    for (sl_client *c = s->clients; c; c = c->next)
        sl_client_wake(c);
}

/* The dataset bounds the session knows ([service] s->bounds); 0 when not loaded yet. */
static int session_bounds(const sl_session *s, sl_vec3 *lo, sl_vec3 *hi)
{
    double b[2][3];
    if (cJSON_GetArraySize(s->bounds) != 2)
        return 0;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 3; k++) {
            const cJSON *v = cJSON_GetArrayItem(cJSON_GetArrayItem(s->bounds, i), k);
            if (!cJSON_IsNumber(v))
                return 0;
            b[i][k] = v->valuedouble;
        }
    *lo = (sl_vec3){b[0][0], b[0][1], b[0][2]};
    *hi = (sl_vec3){b[1][0], b[1][1], b[1][2]};
    return 1;
}

static int has_keyed_params(const sl_scene_path *p)
{
    for (int i = 0; i < p->key_count; i++)
        if (p->key_params[i])
            return 1;
    return 0;
}

/* Parses path for the session's technique; a path with eye/target keys
 * needs the dataset's bounds, known once it has loaded. */
static sl_status parse_path(const sl_session *s, const cJSON *obj, sl_scene_path **out, sl_err *err)
{
    const sl_technique *t = sl_technique_find(s->slot.state.technique);
    if (!t)
        return sl_err_set(err, SL_ERR_INVALID, "technique %s is not in this build", s->slot.state.technique);
    sl_status st = sl_scene_path_parse(obj, t, out, err);
    if (st != SL_OK)
        return st;
    sl_vec3 lo, hi;
    if (!sl_camera_path_is_orbit((*out)->keys, (*out)->key_count) && !session_bounds(s, &lo, &hi)) {
        sl_scene_path_destroy(*out);
        *out = NULL;
        return sl_err_set(err, SL_ERR_INVALID, "path: a path with eye/target keys needs the dataset's bounds, "
                          "which are known once \"%s\" has loaded; retry after its first frame", s->slot.state.dataset);
    }
    return SL_OK;
}

/* Sets the session to path p at time t over the parameters base. */
static sl_status apply_at(sl_server *srv, sl_session *s, const sl_scene_path *p, const sl_params *base, double t,
                          sl_camera_phase phase, sl_err *err)
{
    sl_vec3 lo = {0, 0, 0}, hi = {0, 0, 0};
    session_bounds(s, &lo, &hi); /* unused for orbit-only paths; parse_path required them otherwise */
    sl_camera_spec cam;
    sl_status st = sl_camera_path_at(p->keys, p->key_count, p->interpolation, t, lo, hi, &cam, err);
    if (st != SL_OK)
        return st;
    if (!has_keyed_params(p)) {
        sl_session_set_view(srv, s, &cam, NULL, phase);
        return SL_OK;
    }
    const sl_technique *tech = sl_technique_find(s->slot.state.technique);
    cJSON *keyed = tech ? sl_scene_path_params(p, t, NULL, tech) : NULL;
    if (!keyed)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the path's parameters at t = %g", t);
    sl_params params = *base;
    st = sl_params_apply_json(&params, keyed, err);
    cJSON_Delete(keyed);
    if (st == SL_OK)
        sl_session_set_view(srv, s, &cam, &params, phase);
    return st;
}

static void post_playing(sl_session *s, double t)
{
    const sl_scene_path *p = s->play;
    post_text(s, sl_msg_playback_text("playing", t, path_duration(p), s->play_frame, sl_scene_path_frames(p),
                                      s->play_loop, NULL));
}

sl_status sl_play_start(sl_server *srv, sl_session *s, const cJSON *path, int loop, sl_err *err)
{
    sl_scene_path *p = NULL;
    sl_status st = parse_path(s, path, &p, err);
    if (st != SL_OK)
        return st;
    sl_scene_path_destroy(s->play);
    s->play = p;
    s->play_loop = loop;
    s->play_base = s->slot.state.params;
    s->play_frame = -1;
    s->play_t0_ms = sl_clock_ms();
    if (srv->transport.schedule_play)
        srv->transport.schedule_play(srv, 0);
    return SL_OK;
}

void sl_play_stop(sl_server *srv, sl_session *s, const char *reason)
{
    (void)srv;
    if (!s->play)
        return;
    double t = s->play_frame < 0 ? 0 : s->play_frame / s->play->fps;
    post_text(s, sl_msg_playback_text("stopped", t, path_duration(s->play), s->play_frame < 0 ? 0 : s->play_frame,
                                      sl_scene_path_frames(s->play), s->play_loop, reason));
    sl_scene_path_destroy(s->play);
    s->play = NULL;
}

sl_status sl_play_seek(sl_server *srv, sl_session *s, const cJSON *path, double t, sl_err *err)
{
    sl_scene_path *p = NULL;
    sl_status st = parse_path(s, path, &p, err);
    if (st != SL_OK)
        return st;
    sl_play_stop(srv, s, "seek");
    st = apply_at(srv, s, p, &s->slot.state.params, t, SL_PHASE_NONE, err);
    sl_scene_path_destroy(p);
    return st;
}

/* One session's step at now; returns when its next step is due (ms, absolute) or -1 when it stopped. */
static double step_session(sl_server *srv, sl_session *s, double now)
{
    sl_scene_path *p = s->play;
    double duration = path_duration(p);
    double t = (now - s->play_t0_ms) / 1000.0;
    if (t >= duration && s->play_loop && duration > 0) {
        double laps = floor(t / duration);
        s->play_t0_ms += laps * duration * 1000.0;
        t -= laps * duration;
        s->play_frame = -1;
    }
    sl_err err = {0};
    if (t >= duration) {
        /* The end: a still at the last key, then stopped. */
        s->play_frame = sl_scene_path_frames(p) - 1;
        sl_status st = apply_at(srv, s, p, &s->play_base, duration, SL_PHASE_NONE, &err);
        sl_play_stop(srv, s, st == SL_OK ? "end" : "failed");
        return -1;
    }
    int k = (int)floor(t * p->fps + 1e-9);
    if (k != s->play_frame) {
        s->play_frame = k;
        if (apply_at(srv, s, p, &s->play_base, k / p->fps, SL_PHASE_MOVE, &err) != SL_OK) {
            sl_play_stop(srv, s, "failed");
            return -1;
        }
        post_playing(s, k / p->fps);
    }
    double next = s->play_t0_ms + (k + 1) / p->fps * 1000.0;
    double end = s->play_t0_ms + duration * 1000.0;
    return next < end ? next : end;
}

double sl_play_tick(sl_server *srv)
{
    double now = sl_clock_ms(), due = -1;
    /* The list is walked under the lock (the render thread unlinks doomed
     * sessions), each step outside it: set_view takes the lock itself. */
    for (int i = 0;; i++) {
        sl_session *s = NULL;
        pthread_mutex_lock(&srv->lock);
        int n = 0;
        for (sl_session *t = sl_sessions_first(srv); t && !s; t = sl_session_next(t))
            if (!t->slot.doomed && t->play && n++ == i)
                s = t;
        pthread_mutex_unlock(&srv->lock);
        if (!s)
            break;
        double next = step_session(srv, s, now);
        if (!s->play)
            i--; /* it left the playing sessions: the next one now has index i */
        else if (next >= 0 && (due < 0 || next < due))
            due = next;
    }
    return due < 0 ? -1 : fmax(0.0, due - sl_clock_ms());
}
