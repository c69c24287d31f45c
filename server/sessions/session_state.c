/* session_state.c — a session's state as its clients see it: the state object, patches merged
 * into every client's pending one (newest value wins), the version bump that wakes the render
 * thread, who holds control, camera and parameters set by the server itself (playback), and
 * the render queue's length for /healthz. Service thread (the queue: lock held). */
#include "sl_sessions.h"

#include <string.h>


#include "session_internal.h"
#include "sl_camera_json.h"
#include "sl_params_json.h"

cJSON *sl_session_state_json(const sl_session *s)
{
    const sl_session_state *st = &s->slot.state;
    sl_msg_state m = {.version = st->version, .dataset = st->dataset, .technique = st->technique,
                      .params = &st->params, .camera = &st->camera, .camera_seq = st->camera_seq,
                      .width = st->width, .height = st->height, .background = st->background, .stream = &st->stream,
                      .controller = s->controller, .bounds = s->bounds};
    return sl_msg_state_json(&m);
}

/* Merges patch (consumed) into every client's pending patch: newest value of each key wins. */
void sl_session_broadcast_patch(sl_session *s, cJSON *patch)
{
    for (sl_client *c = s->clients; c; c = c->next) {
        if (!c->patch)
            c->patch = cJSON_CreateObject();
        const cJSON *it;
        cJSON_ArrayForEach(it, patch) {
            cJSON *dup = cJSON_Duplicate(it, 1);
            if (!dup)
                continue;
            if (cJSON_HasObjectItem(c->patch, it->string))
                cJSON_ReplaceItemInObjectCaseSensitive(c->patch, it->string, dup);
            else
                cJSON_AddItemToObject(c->patch, it->string, dup);
        }
        c->patch_version = s->slot.state.version;
        sl_client_wake(c);
    }
    cJSON_Delete(patch);
}

/* Bumps the version, wakes the render thread; caller holds srv->lock. */
void sl_session_state_changed_locked(sl_server *srv, sl_session *s)
{
    s->slot.state.version++;
    pthread_cond_signal(&srv->wake);
}

sl_client *sl_session_find_client(sl_session *s, int id)
{
    for (sl_client *c = s->clients; c; c = c->next)
        if (c->id == id)
            return c;
    return NULL;
}

void sl_session_set_controller(sl_session *s, int id)
{
    s->controller = id;
    /* A client that holds control no longer waits for it; other pending
     * requests stay and go to the new controller (sl_session_broadcast_patch wakes it). */
    sl_client *now = sl_session_find_client(s, id);
    if (now)
        now->wants_control = 0;
    cJSON *p = cJSON_CreateObject();
    cJSON_AddNumberToObject(p, "controller", id);
    sl_session_broadcast_patch(s, p);
}

/* Control passes to the longest-connected other client (the list's tail), or nobody. */
void sl_session_pass_control(sl_session *s, int leaving)
{
    int next = 0;
    for (sl_client *c = s->clients; c; c = c->next)
        if (c->id != leaving)
            next = c->id;
    sl_session_set_controller(s, next);
}

void sl_session_set_view(sl_server *srv, sl_session *s, const sl_camera_spec *camera, const sl_params *params,
                         sl_camera_phase phase)
{
    pthread_mutex_lock(&srv->lock);
    s->slot.state.camera = *camera;
    if (params)
        s->slot.state.params = *params;
    s->slot.state.phase = phase;
    s->slot.state.camera_ms = sl_clock_ms();
    sl_session_state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *p = cJSON_CreateObject();
    cJSON_AddItemToObject(p, "camera", sl_camera_to_json(camera));
    if (params)
        cJSON_AddItemToObject(p, "params", sl_params_to_json(params));
    sl_session_broadcast_patch(s, p);
}

int sl_sessions_render_queue_locked(const sl_server *srv)
{
    int n = 0;
    for (const sl_session *s = sl_sessions_first(srv); s; s = sl_session_next(s))
        n += !s->slot.doomed && (s->slot.snap_req_count > 0 || s->slot.state.version != s->slot.rendered_version ||
                            s->slot.rendered_interactive);
    return n;
}
