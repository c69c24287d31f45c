/* session.c — sessions, clients, control and the handling of every client message.
 *
 * A session is what a group of clients looks at: desired state (dataset,
 * technique, params, camera, size, stream settings), a version bumped on
 * every change, and the newest frame. The creator holds control; viewers
 * who joined with the token see every change but their camera/set/scene/
 * resize/load_view/save_view are refused until control moves to them (grant,
 * release or the controller leaving). A control request is a flag on the
 * requester (wants_control), told to the controller once by write_next, so
 * repeats merge and only a client's own replies fill its reply ring. A
 * session with no clients lives on for the grace period, then is doomed;
 * the render thread frees it with its GL state (and, --idle-release seconds
 * after its last client left, already lets go of its prepared scene:
 * idle_since_ms). Progress texts (render thread) reach each client once, in
 * order, from the session's ring; a client joining mid-round gets the
 * round from its start.
 * Flow control: state changes reach each client as one coalesced `state`
 * patch (newest wins), frames as the session's latest frame, and only while
 * the client has fewer than SL_PROTO_ACK_WINDOW unacknowledged frames.
 * Runs on the lws service thread only; it writes shared session fields under
 * srv->lock and reads them without it (it is their only writer).
 */
#include "sl_sessions.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>


#include "core/sl_technique.h"
#include "session_internal.h"
#include "sl_params_json.h"
#include "sl_camera_json.h"
#include "sl_scene.h"
#include "sl_scene_path.h"

/* ---------- sessions ---------- */

/* The list is walked under the lock because the render thread unlinks doomed
 * sessions; the pointer stays valid after unlock because only this thread dooms. */
static sl_session *find_session(sl_server *srv, const char *id)
{
    sl_session *found = NULL;
    pthread_mutex_lock(&srv->lock);
    for (sl_session *s = sl_sessions_first(srv); s && !found; s = sl_session_next(s))
        if (!s->slot.doomed && strcmp(s->id, id) == 0)
            found = s;
    pthread_mutex_unlock(&srv->lock);
    return found;
}

/* Frees a session (its slot's destroy: the render thread, once the slot is doomed and
 * unlinked and its scene and load released; or sl_sessions_destroy_all at shutdown). */
static void session_free(sl_render_slot *slot)
{
    sl_session *s = sl_session_of(slot);
    sl_frame_buf_unref(s->slot.latest);
    sl_frame_buf_unref(s->slot.snap_ready);
    free(s->slot.info_bounds);
    free(s->slot.info_counts);
    free(s->slot.info_attrs);
    for (int i = 0; i < SL_PROGRESS_RING; i++)
        free(s->slot.progress_text[i]);
    sl_record_free(s->slot.record);
    free(s->slot.record_text);
    sl_scene_path_destroy(s->play);
    free(s->play_text);
    cJSON_Delete(s->bounds);
    free(s);
}

/* The first catalog dataset the technique accepts; fills the state's dataset fields. */
static sl_status pick_default_dataset(sl_server *srv, const sl_technique *t, sl_session_state *st, sl_err *err)
{
    cJSON *list = sl_catalog_list_json(srv->db, 0);
    const cJSON *d;
    sl_status rc = sl_err_set(err, SL_ERR_INVALID, "the catalog has no dataset that %s accepts", t->name);
    cJSON_ArrayForEach(d, list) {
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(d, "name");
        int is_file = 0, kind = 0;
        if (srv->cfg.default_dataset && cJSON_IsString(name) && strcmp(name->valuestring, srv->cfg.default_dataset))
            continue;
        if (!cJSON_IsString(name) ||
            sl_catalog_lookup(srv->db, name->valuestring, st->dataset_source, sizeof st->dataset_source, &is_file,
                              &kind, st->dataset_checksum, err) != SL_OK)
            continue;
        if (!(t->dataset_kinds & (unsigned)kind))
            continue;
        snprintf(st->dataset, sizeof st->dataset, "%s", name->valuestring);
        st->dataset_is_file = is_file;
        st->dataset_kind = kind;
        rc = SL_OK;
        break;
    }
    cJSON_Delete(list);
    return rc;
}

/* A zeroed session for a new or restored one, after evicting the oldest
 * session without clients when --max-sessions are live; NULL (err set)
 * when every session has clients or memory is short. */
static sl_session *alloc_session(sl_server *srv, sl_err *err)
{
    /* Evict the oldest session without clients when at the cap. */
    if (srv->session_count >= srv->cfg.max_sessions) {
        sl_session *oldest = NULL;
        pthread_mutex_lock(&srv->lock);
        for (sl_session *s = sl_sessions_first(srv); s; s = sl_session_next(s))
            if (!s->slot.doomed && s->client_count == 0 && (!oldest || s->empty_since_ms < oldest->empty_since_ms))
                oldest = s;
        if (!oldest) {
            pthread_mutex_unlock(&srv->lock);
            sl_err_set(err, SL_ERR_LIMIT, "the server already has %d sessions (--max-sessions)", srv->cfg.max_sessions);
            return NULL;
        }
        char id[sizeof oldest->id];
        memcpy(id, oldest->id, sizeof id);
        oldest->slot.doomed = 1;   /* the render thread may free it from here on */
        srv->session_count--;
        pthread_cond_signal(&srv->wake);
        pthread_mutex_unlock(&srv->lock);
        sl_catalog_session_remove(srv->db, id, err);
    }
    sl_session *s = calloc(1, sizeof *s);
    if (!s)
        sl_err_set(err, SL_ERR_NOMEM, "session allocation failed");
    else
        s->slot.destroy = session_free;
    return s;
}

/* Puts a filled session on the list (the render thread sees it from here on). */
static void insert_session(sl_server *srv, sl_session *s)
{
    s->empty_since_ms = sl_clock_ms();
    s->slot.idle_since_ms = s->empty_since_ms;
    pthread_mutex_lock(&srv->lock);
    s->slot.next = srv->slots;
    srv->slots = &s->slot;
    srv->session_count++;
    pthread_cond_signal(&srv->wake);
    pthread_mutex_unlock(&srv->lock);
}

static sl_session *create_session(sl_server *srv, int width, int height, sl_err *err)
{
    sl_session *s = alloc_session(srv, err);
    if (!s)
        return NULL;
    /* "NODE.<16 hex>": the node id tells a balancer and a reader of the catalog who made it. */
    char hex[SL_SESSION_HEX + 1];
    sl_random_hex(hex, SL_SESSION_HEX / 2);
    snprintf(s->id, sizeof s->id, "%s.%s", srv->cfg.node_id, hex);
    sl_random_hex(s->token, 16);
    int tc = 0;
    const sl_technique *const *techs = sl_technique_list(&tc);
    sl_session_state *st = &s->slot.state;
    sl_status rc = SL_ERR_INVALID;
    for (int i = 0; i < tc && rc != SL_OK; i++) {
        rc = pick_default_dataset(srv, techs[i], st, err);
        if (rc == SL_OK) {
            snprintf(st->technique, sizeof st->technique, "%s", techs[i]->name);
            sl_params_init(&st->params, techs[i]->params, techs[i]->param_count);
        }
    }
    if (rc != SL_OK) {
        free(s);
        return NULL;
    }
    st->version = 1;
    st->camera = sl_camera_spec_default();
    st->width = width > 0 ? width : 640;
    st->height = height > 0 ? height : 480;
    st->background[0] = 0.1f; st->background[1] = 0.1f; st->background[2] = 0.12f; st->background[3] = 1.0f;
    st->stream = SL_STREAM_DEFAULTS;
    insert_session(srv, s);
    sl_checkpoint_write(srv, s);
    return s;
}

/* A session this node does not have, brought back from its checkpoint
 * (written by whichever node served it last, maybe one that died): same id
 * and token, so the client keeps its share link; a fresh render. *code is
 * the error for the client when NULL comes back: unknown_session (no
 * checkpoint, or one whose grace period ran out), bad_token, or
 * session_failed (the state does not restore here, or no slot). Two nodes
 * restoring one session at the same moment both succeed; the last
 * checkpoint written names the owner (PROTOCOL.md "Nodes"). */
static sl_session *restore_session(sl_server *srv, const sl_msg *m, const char **code, sl_err *err)
{
    char *json = NULL, hash[65], owner[SL_NODE_ID_MAX + 1];
    *code = "unknown_session";
    if (sl_catalog_session_get(srv->db, m->session, &json, hash, owner, sizeof owner, err) != SL_OK) {
        sl_err_set(err, SL_ERR_INVALID, "no such session (it may have expired)");
        return NULL;
    }
    if (!sl_checkpoint_token_matches(m->token, hash)) {
        free(json);
        *code = "bad_token";
        sl_err_set(err, SL_ERR_INVALID, "the join token does not match this session");
        return NULL;
    }
    sl_session_state st;
    memset(&st, 0, sizeof st);
    cJSON *bounds = NULL;
    double empty_since_s = 0;
    sl_status rc = sl_checkpoint_restore_state(srv, json, &st, &bounds, &empty_since_s, err);
    free(json);
    if (rc == SL_OK && empty_since_s > 0 && (double)time(NULL) - empty_since_s > srv->cfg.grace_s) {
        /* Nobody came back within the grace period: the session ended while it had no node. */
        sl_err rm = {0};
        sl_catalog_session_remove(srv->db, m->session, &rm);
        cJSON_Delete(bounds);
        sl_err_set(err, SL_ERR_INVALID, "no such session (it expired)");
        return NULL;
    }
    if (rc != SL_OK) {
        *code = "session_failed";
        return NULL;
    }
    sl_session *s = alloc_session(srv, err);
    if (!s) {
        cJSON_Delete(bounds);
        *code = "session_failed";
        return NULL;
    }
    /* Lengths checked: the parser's session id form, and a token whose hash matched one of 32 digits. */
    snprintf(s->id, sizeof s->id, "%.*s", (int)sizeof s->id - 1, m->session);
    snprintf(s->token, sizeof s->token, "%.*s", (int)sizeof s->token - 1, m->token);
    s->slot.state = st;
    s->bounds = bounds;
    insert_session(srv, s);
    sl_checkpoint_write(srv, s); /* ownership: this node's id in the row */
    fprintf(stderr, "sightline-server: restored session %s from the checkpoint of node %s\n", s->id, owner);
    return s;
}

static void attach(sl_server *srv, sl_session *s, sl_client *c)
{
    c->session = s;
    c->next = s->clients;
    s->clients = c;
    s->client_count++;
    if (!s->controller)
        s->controller = c->id;
    c->hello_done = 1;
    if (srv->transport.hello_done)
        srv->transport.hello_done(srv, c);
    /* Render errors from before the join are history, not news for this client. */
    /* So is a finished round of progress; one in flight is sent from its start. */
    pthread_mutex_lock(&srv->lock);
    srv->client_count++;
    c->error_seq = s->slot.error_seq;
    s->slot.idle_since_ms = 0;
    c->progress_seq = s->slot.progress_closed ? s->slot.progress_seq : s->slot.progress_round_start;
    /* The newest recording state is news while its job runs or waits to be fetched. */
    c->record_seq = s->slot.record && (!s->slot.record->finished || s->slot.record->ok) ? s->slot.record_seq - 1 : s->slot.record_seq;
    pthread_mutex_unlock(&srv->lock);
    c->play_seq = s->play ? s->play_seq - 1 : s->play_seq; /* a path playing is news; a stopped one is not */
    sl_msg_welcome w = {.session = s->id, .token = s->token, .node = srv->cfg.node_id, .client = c->id,
                        .is_controller = s->controller == c->id, .state = sl_session_state_json(s),
                        .techniques = cJSON_Duplicate(srv->techniques_json, 1),
                        .datasets = sl_catalog_list_json(srv->db, 0), .max_clients = srv->cfg.max_clients,
                        .grace_s = srv->cfg.grace_s};
    sl_client_queue_text(c, sl_msg_welcome_text(&w));
    /* A late joiner gets the latest frame at once: write_next sends it. */
    sl_client_wake(c);
    (void)srv;
}

/* ---------- message handlers ---------- */

static int require_control(sl_server *srv, sl_client *c, const char *what)
{
    if (c->session->controller == c->id)
        return 1;
    char msg[160];
    snprintf(msg, sizeof msg, "%s needs control of the session; send {\"type\":\"control\",\"action\":\"request\"}",
             what);
    sl_client_send_error(srv, c, "not_controller", msg, "type");
    return 0;
}

/* Parses a camera and checks it against the session's dataset bounds (when
 * known) into *out; on failure sends bad_field/camera and leaves *out. The
 * same check the render thread's resolution makes, so an accepted camera
 * renders. The camera is parsed here once; state keeps the typed camera. */
static int parse_camera(sl_server *srv, sl_client *c, const cJSON *cam, sl_camera_spec *out)
{
    sl_err err = {0};
    double bounds[2][3];
    int have_bounds = cJSON_GetArraySize(c->session->bounds) == 2;
    for (int i = 0; i < 2 && have_bounds; i++)
        for (int k = 0; k < 3 && have_bounds; k++) {
            const cJSON *v = cJSON_GetArrayItem(cJSON_GetArrayItem(c->session->bounds, i), k);
            have_bounds = cJSON_IsNumber(v);
            bounds[i][k] = have_bounds ? v->valuedouble : 0.0;
        }
    if (sl_msg_camera_check(cam, have_bounds ? (const double (*)[3])bounds : NULL, out, &err) != SL_OK) {
        sl_client_send_error(srv, c, "bad_field", err.message, "camera");
        return 0;
    }
    return 1;
}

/* Applies a params patch to *params (all or nothing); on failure names the offending key. */
static int apply_params(sl_server *srv, sl_client *c, sl_params *params, const cJSON *patch)
{
    sl_params copy = *params;
    sl_err err = {0};
    if (sl_params_apply_json(&copy, patch, &err) == SL_OK) {
        *params = copy;
        return 1;
    }
    char field[SL_PROTO_ID_MAX + 8] = "params";
    const cJSON *it;
    cJSON_ArrayForEach(it, patch) {
        sl_params one = *params;
        cJSON *single = cJSON_CreateObject();
        cJSON_AddItemToObject(single, it->string, cJSON_Duplicate(it, 1));
        sl_err e2 = {0};
        sl_status bad = sl_params_apply_json(&one, single, &e2);
        cJSON_Delete(single);
        if (bad) {
            snprintf(field, sizeof field, "params.%.56s", it->string);
            break;
        }
    }
    sl_client_send_error(srv, c, "bad_param", err.message, field);
    return 0;
}

static int parse_stream(sl_server *srv, sl_client *c, const cJSON *o, sl_stream_settings *out)
{
    char field[SL_PROTO_ID_MAX];
    sl_err err = {0};
    if (sl_msg_stream_apply(out, o, field, &err) == SL_OK)
        return 1;
    sl_client_send_error(srv, c, "bad_field", err.message, field);
    return 0;
}

/* Switches dataset and/or technique (and optionally params and camera): scene and load_view. */
void sl_session_apply_scene(sl_server *srv, sl_client *c, const char *dataset, const char *technique,
                            const cJSON *params, const cJSON *camera)
{
    sl_session *s = c->session;
    sl_session_state next = s->slot.state;
    sl_err err = {0};
    if (dataset && dataset[0] && strcmp(dataset, next.dataset) != 0) {
        if (sl_catalog_lookup(srv->db, dataset, next.dataset_source, sizeof next.dataset_source,
                              &next.dataset_is_file, &next.dataset_kind, next.dataset_checksum, &err) != SL_OK) {
            sl_client_send_error(srv, c, "not_found", err.message, "dataset");
            return;
        }
        snprintf(next.dataset, sizeof next.dataset, "%s", dataset);
    }
    const sl_technique *t = sl_technique_find(technique && technique[0] ? technique : next.technique);
    if (!t) {
        char msg[200];
        snprintf(msg, sizeof msg, "no technique named \"%.120s\"", technique ? technique : next.technique);
        sl_client_send_error(srv, c, "not_found", msg, "technique");
        return;
    }
    if (!(t->dataset_kinds & (unsigned)next.dataset_kind)) {
        /* Refused whole: the session keeps its state (nothing below ran). */
        char kinds[64] = "";
        const sl_dataset_kind *all = sl_dataset_kinds;
        for (size_t i = 0; i < SL_DATASET_KIND_COUNT; i++)
            if (t->dataset_kinds & (unsigned)all[i])
                snprintf(kinds + strlen(kinds), sizeof kinds - strlen(kinds), "%s%s", kinds[0] ? ", " : "",
                         sl_dataset_kind_name(all[i]));
        char msg[512];
        snprintf(msg, sizeof msg,
                 "technique \"%s\" cannot render dataset \"%.100s\": it is a %s dataset and %s renders %s; "
                 "the session keeps \"%.100s\" with \"%s\"",
                 t->name, next.dataset, sl_dataset_kind_name((sl_dataset_kind)next.dataset_kind), t->name, kinds,
                 s->slot.state.dataset, s->slot.state.technique);
        sl_client_send_error(srv, c, "bad_field", msg, technique && technique[0] ? "technique" : "dataset");
        return;
    }
    if (strcmp(t->name, next.technique) != 0) {
        snprintf(next.technique, sizeof next.technique, "%s", t->name);
        sl_params_init(&next.params, t->params, t->param_count);
    }
    if (params && !apply_params(srv, c, &next.params, params))
        return;
    if (camera && !parse_camera(srv, c, camera, &next.camera))
        return;
    next.phase = SL_PHASE_NONE;
    if (strcmp(next.dataset, s->slot.state.dataset) != 0) {
        cJSON_Delete(s->bounds);   /* known again once the render thread has loaded it */
        s->bounds = NULL;
    }
    pthread_mutex_lock(&srv->lock);
    s->slot.state = next;
    sl_session_state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *full = sl_session_state_json(s);
    cJSON_DeleteItemFromObjectCaseSensitive(full, "stream");
    sl_session_broadcast_patch(s, full);
}

static void on_hello(sl_server *srv, sl_client *c, const sl_msg *m)
{
    if (m->version != SL_PROTO_VERSION) {
        sl_client_refuse(srv, c, "bad_version", "this server speaks protocol version 1", "version");
        return;
    }
    if (srv->client_count >= srv->cfg.max_clients) {
        /* Pending connections are not counted at upgrade; the slot is taken here. */
        char msg[120];
        snprintf(msg, sizeof msg, "the server already has %d clients (--max-clients); retry later",
                 srv->cfg.max_clients);
        sl_client_refuse(srv, c, "full", msg, "");
        pthread_mutex_lock(&srv->lock);
        srv->metrics.refused_full++;
        pthread_mutex_unlock(&srv->lock);
        return;
    }
    pthread_mutex_lock(&srv->lock);
    int draining = srv->draining;
    pthread_mutex_unlock(&srv->lock);
    sl_session *s = m->session[0] ? find_session(srv, m->session) : NULL;
    if (!s && draining) {
        /* New and restored sessions belong on another node; the client reconnects through the balancer. */
        sl_client_refuse(srv, c, "draining",
               "this node is shutting down and takes no new sessions; reconnect to reach another node", "");
        return;
    }
    if (m->session[0] && !s) {
        const char *code = "unknown_session";
        sl_err err = {0};
        s = restore_session(srv, m, &code, &err);
        if (!s) {
            sl_client_refuse(srv, c, code, err.message, strcmp(code, "bad_token") == 0 ? "token"
                                                  : strcmp(code, "unknown_session") == 0 ? "session" : "");
            return;
        }
    } else if (s) {
        /* Compare every byte so timing does not reveal a matching prefix. */
        size_t lt = strlen(s->token), lm = strlen(m->token);
        unsigned diff = (unsigned)(lt ^ lm);
        for (size_t i = 0; i < lt; i++)
            diff |= (unsigned)(s->token[i] ^ (i < lm ? m->token[i] : 0));
        if (diff) {
            sl_client_refuse(srv, c, "bad_token", "the join token does not match this session", "token");
            return;
        }
    } else {
        sl_err err = {0};
        s = create_session(srv, m->width, m->height, &err);
        if (!s) {
            sl_client_refuse(srv, c, "session_failed", err.message, "");
            return;
        }
    }
    attach(srv, s, c);
}

static void on_set(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_session_state next = s->slot.state;
    if (m->params && !apply_params(srv, c, &next.params, m->params))
        return;
    if (m->stream && !parse_stream(srv, c, m->stream, &next.stream))
        return;
    if (m->background) {
        int i = 0;
        const cJSON *v;
        cJSON_ArrayForEach(v, m->background)
            next.background[i++] = (float)v->valuedouble;
    }
    next.phase = s->play ? s->slot.state.phase : SL_PHASE_NONE; /* a playing path keeps its interactive frames */
    if (s->play && m->params)
        s->play_base = next.params; /* keyed parameters still follow the path over the new values */
    pthread_mutex_lock(&srv->lock);
    s->slot.state = next;
    sl_session_state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *p = cJSON_CreateObject();
    if (m->params)
        cJSON_AddItemToObject(p, "params", sl_params_to_json(&next.params));
    if (m->stream)
        cJSON_AddItemToObject(p, "stream", sl_msg_stream_json(&next.stream));
    if (m->background)
        cJSON_AddItemToObject(p, "background", cJSON_CreateFloatArray(next.background, 4));
    sl_session_broadcast_patch(s, p);
}

static void on_camera(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_camera_spec cam;
    if (!parse_camera(srv, c, m->camera, &cam))
        return;
    pthread_mutex_lock(&srv->lock);
    s->slot.state.camera = cam;
    s->slot.state.camera_seq = (uint32_t)m->seq;
    s->slot.state.phase = m->phase;
    s->slot.state.camera_ms = sl_clock_ms();
    sl_session_state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *p = cJSON_CreateObject();
    cJSON_AddItemToObject(p, "camera", sl_camera_to_json(&cam));
    cJSON_AddNumberToObject(p, "camera_seq", (double)m->seq);
    sl_session_broadcast_patch(s, p);
}

static void on_control(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    switch (m->action) {
    case SL_CONTROL_REQUEST: {
        if (!s->controller || s->controller == c->id) {
            sl_session_set_controller(s, c->id);
            return;
        }
        /* One pending request per requester, not a message in the controller's
         * reply ring: repeated requests merge, and a viewer cannot fill the
         * controller's ring (which would close the controller). */
        c->wants_control = 1;
        sl_client *ctl = sl_session_find_client(s, s->controller);
        if (ctl)
            sl_client_wake(ctl);
        return;
    }
    case SL_CONTROL_GRANT:
        if (!require_control(srv, c, "control grant"))
            return;
        if (!sl_session_find_client(s, m->client)) {
            sl_client_send_error(srv, c, "not_found", "no client with that id in this session", "client");
            return;
        }
        sl_session_set_controller(s, m->client);
        return;
    case SL_CONTROL_RELEASE:
        if (!require_control(srv, c, "control release"))
            return;
        sl_session_pass_control(s, c->id);
        return;
    }
}

/* The messages whose handling is a few lines, as handlers of the table below. */
static void on_camera_msg(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_play_stop(srv, c->session, "camera"); /* the controller takes the camera back */
    on_camera(srv, c, m);
}

static void on_scene(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_play_stop(srv, c->session, "scene"); /* the path was checked against the technique it replaces */
    sl_session_apply_scene(srv, c, m->dataset, m->technique, m->params, m->camera);
}

static void on_resize(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    pthread_mutex_lock(&srv->lock);
    s->slot.state.width = m->width;
    s->slot.state.height = m->height;
    s->slot.state.phase = SL_PHASE_NONE;
    sl_session_state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *p = cJSON_CreateObject();
    cJSON_AddNumberToObject(p, "width", m->width);
    cJSON_AddNumberToObject(p, "height", m->height);
    sl_session_broadcast_patch(s, p);
}

static void on_ack(sl_server *srv, sl_client *c, const sl_msg *m)
{
    (void)srv;
    int keep = 0;
    for (int i = 0; i < c->inflight_count; i++)
        if (c->inflight[i] > m->frame_id)
            c->inflight[keep++] = c->inflight[i];
    c->inflight_count = keep;
    sl_client_wake(c);
}

static void on_snapshot(sl_server *srv, sl_client *c, const sl_msg *m)
{
    (void)m;
    sl_session *s = c->session;
    pthread_mutex_lock(&srv->lock);
    if (s->slot.snap_req_count < SL_SESSION_MAX_SNAPSHOTS) {
        s->slot.snap_req[s->slot.snap_req_count++] = c->id;
        pthread_cond_signal(&srv->wake);
        pthread_mutex_unlock(&srv->lock);
    } else {
        pthread_mutex_unlock(&srv->lock);
        sl_client_send_error(srv, c, "busy", "too many snapshots pending in this session; retry later", "type");
    }
}

static void on_ping(sl_server *srv, sl_client *c, const sl_msg *m)
{
    (void)srv;
    sl_client_queue_text(c, sl_msg_pong_text(m->seq));
}

/* Every message after parsing: its handler, and whether it needs control of the session
 * (then a viewer gets not_controller naming the message type). A new message type gets a
 * row here and its handler in the file of the job it serves. */
typedef void (*message_handler)(sl_server *srv, sl_client *c, const sl_msg *m);
static const struct {
    sl_msg_type type;
    int needs_control;
    message_handler handle;
} message_table[] = {
    {SL_MSG_HELLO, 0, on_hello},
    {SL_MSG_CAMERA, 1, on_camera_msg},
    {SL_MSG_SET, 1, on_set},
    {SL_MSG_SCENE, 1, on_scene},
    {SL_MSG_RESIZE, 1, on_resize},
    {SL_MSG_LIST_DATASETS, 0, sl_on_list_datasets},
    {SL_MSG_LIST_VIEWS, 0, sl_on_list_views},
    {SL_MSG_SAVE_VIEW, 1, sl_on_save_view},
    {SL_MSG_LOAD_VIEW, 1, sl_on_load_view},
    {SL_MSG_ACK, 0, on_ack},
    {SL_MSG_SNAPSHOT, 0, on_snapshot},
    {SL_MSG_CONTROL, 0, on_control},
    {SL_MSG_PING, 0, on_ping},
    {SL_MSG_RECORD, 1, sl_on_record},
    {SL_MSG_RECORD_CANCEL, 1, sl_on_record_cancel},
    {SL_MSG_SAVE_PATH, 1, sl_on_save_path},
    {SL_MSG_LIST_PATHS, 0, sl_on_list_paths},
    {SL_MSG_LOAD_PATH, 0, sl_on_load_path},
    {SL_MSG_PLAY_PATH, 1, sl_on_play},
    {SL_MSG_PLAY_STOP, 1, sl_on_play},
    {SL_MSG_PATH_SEEK, 1, sl_on_play},
};

void sl_sessions_on_text(sl_server *srv, sl_client *c, const char *text, size_t len)
{
    sl_msg m;
    char code[32], field[SL_PROTO_ID_MAX];
    sl_err err = {0};
    pthread_mutex_lock(&srv->lock);
    srv->metrics.messages_in++;
    pthread_mutex_unlock(&srv->lock);
    if (sl_msg_parse(text, len, &m, code, field, &err) != SL_OK) {
        if (c->hello_done)
            sl_client_send_error(srv, c, code, err.message, field);
        else
            sl_client_refuse(srv, c, code, err.message, field);
        return;
    }
    if (!c->hello_done && m.type != SL_MSG_HELLO) {
        sl_client_refuse(srv, c, "hello_required", "the first message must be hello", "type");
        sl_msg_deinit(&m);
        return;
    }
    if (c->hello_done && m.type == SL_MSG_HELLO) {
        sl_client_send_error(srv, c, "bad_field", "hello was already received on this connection", "type");
        sl_msg_deinit(&m);
        return;
    }
    for (size_t i = 0; i < sizeof message_table / sizeof message_table[0]; i++) {
        if (message_table[i].type != m.type)
            continue;
        if (!message_table[i].needs_control || require_control(srv, c, sl_msg_type_name(m.type)))
            message_table[i].handle(srv, c, &m);
        break;
    }
    sl_msg_deinit(&m);
}

void sl_sessions_on_close(sl_server *srv, sl_client *c)
{
    sl_session *s = c->session;
    if (s) {
        for (sl_client **pp = &s->clients; *pp; pp = &(*pp)->next)
            if (*pp == c) {
                *pp = c->next;
                break;
            }
        s->client_count--;
        if (s->controller == c->id)
            sl_session_pass_control(s, c->id);
        if (s->client_count == 0)
            s->empty_since_ms = sl_clock_ms();
        pthread_mutex_lock(&srv->lock);
        if (s->client_count == 0) {
            s->slot.idle_since_ms = s->empty_since_ms; /* the render thread lets go of its prepared state later */
            pthread_cond_signal(&srv->wake);
        }
        for (int i = 0; i < s->slot.snap_req_count; i++)
            if (s->slot.snap_req[i] == c->id)
                s->slot.snap_req[i] = 0;
        pthread_mutex_unlock(&srv->lock);
    }
    for (int i = 0; i < c->reply_count; i++)
        free(c->replies[(c->reply_head + i) % SL_CLIENT_MAX_TEXT].text);
    c->reply_count = 0;
    cJSON_Delete(c->patch);
    c->patch = NULL;
    sl_frame_buf_unref(c->snapshot);
    c->snapshot = NULL;
    free(c->rx);
    c->rx = NULL;
    c->session = NULL;
}
