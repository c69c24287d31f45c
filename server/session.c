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
#include "sl_server.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

#include <libwebsockets.h>

#include "core/sl_technique.h"
#include "sl_params_json.h"
#include "sl_scene.h"
#include "sl_scene_path.h"

void sl_random_hex(char *out, int bytes)
{
    unsigned char buf[32];
    if (getrandom(buf, (size_t)bytes, 0) != bytes) {
        /* getrandom on Linux does not fail for <= 256 bytes once seeded; mix the clock in as a fallback. */
        double t = sl_clock_ms();
        for (int i = 0; i < bytes; i++)
            buf[i] = (unsigned char)((long long)(t * 1000.0) >> (i % 8) ^ (unsigned)rand());
    }
    for (int i = 0; i < bytes; i++)
        snprintf(out + 2 * i, 3, "%02x", buf[i]);
}

/* ---------- outgoing messages ---------- */

/* text (consumed) copied behind the LWS_PRE bytes lws_write needs; NULL when
 * out of memory. */
static uint8_t *lws_text_buffer(char *text, size_t *len)
{
    *len = strlen(text);
    uint8_t *buf = malloc(LWS_PRE + *len);
    if (buf)
        memcpy(buf + LWS_PRE, text, *len);
    free(text);
    return buf;
}

void sl_client_close(sl_client *c, int code, const char *reason, int after_replies)
{
    if (c->close_code)
        return;
    c->close_code = code;
    c->close_after_replies = after_replies;
    snprintf(c->close_reason, sizeof c->close_reason, "%s", reason);
    lws_set_timeout(c->wsi, PENDING_TIMEOUT_CLOSE_SEND, SL_CLOSE_GRACE_S);
    lws_callback_on_writable(c->wsi);
}

/* The next free slot of c's reply ring, or NULL when the reply budget is
 * used up (the link is then told to close) or c is closing anyway. */
static sl_reply *reply_slot(sl_client *c)
{
    if (c->close_code)
        return NULL;
    if (c->reply_count >= SL_CLIENT_MAX_TEXT) {
        char reason[80];
        snprintf(reason, sizeof reason, "reply budget: %d replies not read", SL_CLIENT_MAX_TEXT);
        sl_client_close(c, LWS_CLOSE_STATUS_POLICY_VIOLATION, reason, 0);
        return NULL;
    }
    sl_reply *r = &c->replies[(c->reply_head + c->reply_count) % SL_CLIENT_MAX_TEXT];
    memset(r, 0, sizeof *r);
    c->reply_count++;
    lws_callback_on_writable(c->wsi);
    return r;
}

int sl_client_queue_text(sl_client *c, char *text)
{
    if (!text) {
        sl_client_close(c, LWS_CLOSE_STATUS_UNEXPECTED_CONDITION, "out of memory", 0);
        return -1;
    }
    sl_reply *r = reply_slot(c);
    if (!r) {
        free(text);
        return -1;
    }
    r->text = text;
    return 0;
}

int sl_client_queue_error(sl_client *c, const char *code, const char *message, const char *field)
{
    if (!field)
        field = "";
    char *text = strdup(message ? message : "");
    if (!text) {
        sl_client_close(c, LWS_CLOSE_STATUS_UNEXPECTED_CONDITION, "out of memory", 0);
        return -1;
    }
    for (int i = 0; i < c->reply_count; i++) {
        sl_reply *q = &c->replies[(c->reply_head + i) % SL_CLIENT_MAX_TEXT];
        if (q->code[0] && strcmp(q->code, code) == 0 && strncmp(q->field, field, sizeof q->field - 1) == 0) {
            free(q->text);
            q->text = text;
            q->repeated++;
            return 0;
        }
    }
    sl_reply *r = reply_slot(c);
    if (!r) {
        free(text);
        return -1;
    }
    r->text = text;
    snprintf(r->code, sizeof r->code, "%s", code);
    snprintf(r->field, sizeof r->field, "%s", field);
    return 0;
}

static char *print_and_free(cJSON *o)
{
    char *t = o ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    return t;
}

static void send_error(sl_server *srv, sl_client *c, const char *code, const char *message, const char *field)
{
    pthread_mutex_lock(&srv->lock);
    srv->metrics.errors_sent++;
    pthread_mutex_unlock(&srv->lock);
    sl_client_queue_error(c, code, message, field);
}

/* An error in or before hello: the link ends after it, with 1008 and the code as reason. */
static void refuse(sl_server *srv, sl_client *c, const char *code, const char *message, const char *field)
{
    send_error(srv, c, code, message, field);
    sl_client_close(c, LWS_CLOSE_STATUS_POLICY_VIOLATION, code, 1);
}

cJSON *sl_session_state_json(const sl_session *s)
{
    const sl_session_state *st = &s->state;
    sl_msg_state m = {.version = st->version, .dataset = st->dataset, .technique = st->technique,
                      .params = &st->params, .camera = &st->camera, .camera_seq = st->camera_seq,
                      .width = st->width, .height = st->height, .background = st->background, .stream = &st->stream,
                      .controller = s->controller, .bounds = s->bounds};
    return sl_msg_state_json(&m);
}

/* Merges patch (consumed) into every client's pending patch: newest value of each key wins. */
static void broadcast_patch(sl_session *s, cJSON *patch)
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
        c->patch_version = s->state.version;
        lws_callback_on_writable(c->wsi);
    }
    cJSON_Delete(patch);
}

/* Bumps the version, wakes the render thread; caller holds srv->lock. */
static void state_changed_locked(sl_server *srv, sl_session *s)
{
    s->state.version++;
    pthread_cond_signal(&srv->wake);
}

/* ---------- sessions ---------- */

/* The list is walked under the lock because the render thread unlinks doomed
 * sessions; the pointer stays valid after unlock because only this thread dooms. */
static sl_session *find_session(sl_server *srv, const char *id)
{
    sl_session *found = NULL;
    pthread_mutex_lock(&srv->lock);
    for (sl_session *s = srv->sessions; s && !found; s = s->next)
        if (!s->doomed && strcmp(s->id, id) == 0)
            found = s;
    pthread_mutex_unlock(&srv->lock);
    return found;
}

static sl_client *find_client(sl_session *s, int id)
{
    for (sl_client *c = s->clients; c; c = c->next)
        if (c->id == id)
            return c;
    return NULL;
}

void sl_session_free(sl_session *s)
{
    if (!s)
        return;
    sl_frame_buf_unref(s->latest);
    sl_frame_buf_unref(s->snap_ready);
    free(s->info_bounds);
    free(s->info_counts);
    free(s->info_attrs);
    for (int i = 0; i < SL_PROGRESS_RING; i++)
        free(s->progress_text[i]);
    sl_record_free(s->record);
    free(s->record_text);
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
        for (sl_session *s = srv->sessions; s; s = s->next)
            if (!s->doomed && s->client_count == 0 && (!oldest || s->empty_since_ms < oldest->empty_since_ms))
                oldest = s;
        if (!oldest) {
            pthread_mutex_unlock(&srv->lock);
            sl_err_set(err, SL_ERR_LIMIT, "the server already has %d sessions (--max-sessions)", srv->cfg.max_sessions);
            return NULL;
        }
        char id[sizeof oldest->id];
        memcpy(id, oldest->id, sizeof id);
        oldest->doomed = 1;   /* the render thread may free it from here on */
        srv->session_count--;
        pthread_cond_signal(&srv->wake);
        pthread_mutex_unlock(&srv->lock);
        sl_catalog_session_remove(srv->db, id, err);
    }
    sl_session *s = calloc(1, sizeof *s);
    if (!s)
        sl_err_set(err, SL_ERR_NOMEM, "session allocation failed");
    return s;
}

/* Puts a filled session on the list (the render thread sees it from here on). */
static void insert_session(sl_server *srv, sl_session *s)
{
    s->empty_since_ms = sl_clock_ms();
    s->idle_since_ms = s->empty_since_ms;
    pthread_mutex_lock(&srv->lock);
    s->next = srv->sessions;
    srv->sessions = s;
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
    sl_session_state *st = &s->state;
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
    s->state = st;
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
    sl_ws_pending_leave(srv, c);
    /* Render errors from before the join are history, not news for this client. */
    /* So is a finished round of progress; one in flight is sent from its start. */
    pthread_mutex_lock(&srv->lock);
    srv->client_count++;
    c->error_seq = s->error_seq;
    s->idle_since_ms = 0;
    c->progress_seq = s->progress_closed ? s->progress_seq : s->progress_round_start;
    /* The newest recording state is news while its job runs or waits to be fetched. */
    c->record_seq = s->record && (!s->record->finished || s->record->ok) ? s->record_seq - 1 : s->record_seq;
    pthread_mutex_unlock(&srv->lock);
    c->play_seq = s->play ? s->play_seq - 1 : s->play_seq; /* a path playing is news; a stopped one is not */
    lws_set_timeout(c->wsi, NO_PENDING_TIMEOUT, 0);
    lws_set_timer_usecs(c->wsi, LWS_SET_TIMER_USEC_CANCEL); /* the hello timeout (ws.c) */
    sl_msg_welcome w = {.session = s->id, .token = s->token, .node = srv->cfg.node_id, .client = c->id,
                        .is_controller = s->controller == c->id, .state = sl_session_state_json(s),
                        .techniques = cJSON_Duplicate(srv->techniques_json, 1),
                        .datasets = sl_catalog_list_json(srv->db, 0), .max_clients = srv->cfg.max_clients,
                        .grace_s = srv->cfg.grace_s};
    sl_client_queue_text(c, sl_msg_welcome_text(&w));
    /* A late joiner gets the latest frame at once: write_next sends it. */
    lws_callback_on_writable(c->wsi);
    (void)srv;
}

static void set_controller(sl_session *s, int id)
{
    s->controller = id;
    /* A client that holds control no longer waits for it; other pending
     * requests stay and go to the new controller (broadcast_patch wakes it). */
    sl_client *now = find_client(s, id);
    if (now)
        now->wants_control = 0;
    cJSON *p = cJSON_CreateObject();
    cJSON_AddNumberToObject(p, "controller", id);
    broadcast_patch(s, p);
}

/* Control passes to the longest-connected other client (the list's tail), or nobody. */
static void pass_control(sl_session *s, int leaving)
{
    int next = 0;
    for (sl_client *c = s->clients; c; c = c->next)
        if (c->id != leaving)
            next = c->id;
    set_controller(s, next);
}

/* ---------- message handlers ---------- */

static int require_control(sl_server *srv, sl_client *c, const char *what)
{
    if (c->session->controller == c->id)
        return 1;
    char msg[160];
    snprintf(msg, sizeof msg, "%s needs control of the session; send {\"type\":\"control\",\"action\":\"request\"}",
             what);
    send_error(srv, c, "not_controller", msg, "type");
    return 0;
}

/* record: a new recording job of the session (one at a time). */
static void on_record(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    pthread_mutex_lock(&srv->lock);
    int busy = s->record && !s->record->finished;
    pthread_mutex_unlock(&srv->lock);
    if (busy) {
        send_error(srv, c, "busy", "a recording is already running in this session (record_cancel stops it)", "type");
        return;
    }
    sl_record_job *j = NULL;
    sl_err err = {0};
    if (sl_record_create(srv, s, m->path, m->format, m->crf, &j, &err) != SL_OK) {
        send_error(srv, c, "bad_field", err.message, "path");
        return;
    }
    pthread_mutex_lock(&srv->lock);
    sl_record_job *old = s->record; /* finished: no thread works on it */
    s->record = j;
    sl_record_status_locked(s, j, "queued", NULL);
    pthread_cond_signal(&srv->wake);
    pthread_mutex_unlock(&srv->lock);
    sl_record_free(old);
    for (sl_client *o = s->clients; o; o = o->next)
        lws_callback_on_writable(o->wsi);
}

/* record_cancel: stops the running job (its partial file is removed). */
static void on_record_cancel(sl_server *srv, sl_client *c)
{
    sl_session *s = c->session;
    pthread_mutex_lock(&srv->lock);
    int running = s->record && !s->record->finished;
    if (running) {
        s->record->cancel = 1;
        pthread_cond_signal(&srv->wake);
    }
    pthread_mutex_unlock(&srv->lock);
    if (!running)
        send_error(srv, c, "bad_field", "no recording is running in this session", "type");
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
        send_error(srv, c, "bad_field", err.message, "camera");
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
    send_error(srv, c, "bad_param", err.message, field);
    return 0;
}

static int parse_stream(sl_server *srv, sl_client *c, const cJSON *o, sl_stream_settings *out)
{
    char field[SL_PROTO_ID_MAX];
    sl_err err = {0};
    if (sl_msg_stream_apply(out, o, field, &err) == SL_OK)
        return 1;
    send_error(srv, c, "bad_field", err.message, field);
    return 0;
}

/* Switches dataset and/or technique (and optionally params and camera): scene and load_view. */
static void apply_scene(sl_server *srv, sl_client *c, const char *dataset, const char *technique,
                        const cJSON *params, const cJSON *camera)
{
    sl_session *s = c->session;
    sl_session_state next = s->state;
    sl_err err = {0};
    if (dataset && dataset[0] && strcmp(dataset, next.dataset) != 0) {
        if (sl_catalog_lookup(srv->db, dataset, next.dataset_source, sizeof next.dataset_source,
                              &next.dataset_is_file, &next.dataset_kind, next.dataset_checksum, &err) != SL_OK) {
            send_error(srv, c, "not_found", err.message, "dataset");
            return;
        }
        snprintf(next.dataset, sizeof next.dataset, "%s", dataset);
    }
    const sl_technique *t = sl_technique_find(technique && technique[0] ? technique : next.technique);
    if (!t) {
        char msg[200];
        snprintf(msg, sizeof msg, "no technique named \"%.120s\"", technique ? technique : next.technique);
        send_error(srv, c, "not_found", msg, "technique");
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
                 s->state.dataset, s->state.technique);
        send_error(srv, c, "bad_field", msg, technique && technique[0] ? "technique" : "dataset");
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
    if (strcmp(next.dataset, s->state.dataset) != 0) {
        cJSON_Delete(s->bounds);   /* known again once the render thread has loaded it */
        s->bounds = NULL;
    }
    pthread_mutex_lock(&srv->lock);
    s->state = next;
    state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *full = sl_session_state_json(s);
    cJSON_DeleteItemFromObjectCaseSensitive(full, "stream");
    broadcast_patch(s, full);
}

static void on_hello(sl_server *srv, sl_client *c, const sl_msg *m)
{
    if (m->version != SL_PROTO_VERSION) {
        refuse(srv, c, "bad_version", "this server speaks protocol version 1", "version");
        return;
    }
    if (srv->client_count >= srv->cfg.max_clients) {
        /* Pending connections are not counted at upgrade; the slot is taken here. */
        char msg[120];
        snprintf(msg, sizeof msg, "the server already has %d clients (--max-clients); retry later",
                 srv->cfg.max_clients);
        refuse(srv, c, "full", msg, "");
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
        refuse(srv, c, "draining",
               "this node is shutting down and takes no new sessions; reconnect to reach another node", "");
        return;
    }
    if (m->session[0] && !s) {
        const char *code = "unknown_session";
        sl_err err = {0};
        s = restore_session(srv, m, &code, &err);
        if (!s) {
            refuse(srv, c, code, err.message, strcmp(code, "bad_token") == 0 ? "token"
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
            refuse(srv, c, "bad_token", "the join token does not match this session", "token");
            return;
        }
    } else {
        sl_err err = {0};
        s = create_session(srv, m->width, m->height, &err);
        if (!s) {
            refuse(srv, c, "session_failed", err.message, "");
            return;
        }
    }
    attach(srv, s, c);
}

static void on_set(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_session_state next = s->state;
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
    next.phase = s->play ? s->state.phase : SL_PHASE_NONE; /* a playing path keeps its interactive frames */
    if (s->play && m->params)
        s->play_base = next.params; /* keyed parameters still follow the path over the new values */
    pthread_mutex_lock(&srv->lock);
    s->state = next;
    state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *p = cJSON_CreateObject();
    if (m->params)
        cJSON_AddItemToObject(p, "params", sl_params_to_json(&next.params));
    if (m->stream)
        cJSON_AddItemToObject(p, "stream", sl_msg_stream_json(&next.stream));
    if (m->background)
        cJSON_AddItemToObject(p, "background", cJSON_CreateFloatArray(next.background, 4));
    broadcast_patch(s, p);
}

static void on_camera(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_camera_spec cam;
    if (!parse_camera(srv, c, m->camera, &cam))
        return;
    pthread_mutex_lock(&srv->lock);
    s->state.camera = cam;
    s->state.camera_seq = (uint32_t)m->seq;
    s->state.phase = m->phase;
    s->state.camera_ms = sl_clock_ms();
    state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *p = cJSON_CreateObject();
    cJSON_AddItemToObject(p, "camera", sl_camera_to_json(&cam));
    cJSON_AddNumberToObject(p, "camera_seq", (double)m->seq);
    broadcast_patch(s, p);
}

void sl_session_set_view(sl_server *srv, sl_session *s, const sl_camera_spec *camera, const sl_params *params,
                         sl_camera_phase phase)
{
    pthread_mutex_lock(&srv->lock);
    s->state.camera = *camera;
    if (params)
        s->state.params = *params;
    s->state.phase = phase;
    s->state.camera_ms = sl_clock_ms();
    state_changed_locked(srv, s);
    pthread_mutex_unlock(&srv->lock);
    cJSON *p = cJSON_CreateObject();
    cJSON_AddItemToObject(p, "camera", sl_camera_to_json(camera));
    if (params)
        cJSON_AddItemToObject(p, "params", sl_params_to_json(params));
    broadcast_patch(s, p);
}

/* play_path, play_stop, path_seek (controller): playback.c does the work. */
static void on_play(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_err err = {0};
    sl_status st = SL_OK;
    if (m->type == SL_MSG_PLAY_STOP) {
        if (!s->play)
            send_error(srv, c, "bad_field", "no path is playing in this session", "type");
        sl_play_stop(srv, s, "play_stop");
        return;
    }
    if (m->type == SL_MSG_PLAY_PATH)
        st = sl_play_start(srv, s, m->path, m->loop, &err);
    else
        st = sl_play_seek(srv, s, m->path, m->t, &err);
    if (st != SL_OK)
        send_error(srv, c, st == SL_ERR_NOMEM ? "internal" : "bad_field", err.message, "path");
}

/* save_path (controller): the path checked against the session's technique, stored by name. */
static void on_save_path(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    sl_err err = {0};
    const sl_technique *t = sl_technique_find(s->state.technique);
    sl_scene_path *p = NULL;
    if (!t || sl_scene_path_parse(m->path, t, &p, &err) != SL_OK) {
        send_error(srv, c, "bad_field", t ? err.message : "the session's technique is not in this build", "path");
        return;
    }
    char *text = cJSON_PrintUnformatted(m->path);
    if (text && strlen(text) > SL_CATALOG_MAX_PATH_BYTES) {
        char msg[160];
        snprintf(msg, sizeof msg, "path: %zu bytes of JSON; a saved path holds at most %d", strlen(text),
                 SL_CATALOG_MAX_PATH_BYTES);
        send_error(srv, c, "limit", msg, "path");
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
        send_error(srv, c, st == SL_ERR_LIMIT ? "limit" : "internal", err.message, "name");
    else
        sl_client_queue_text(c, sl_msg_named_text("path_saved", m->name, NULL));
}

/* load_path (any client): the stored path, to the requester only. */
static void on_load_path(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_err err = {0};
    cJSON *p = NULL;
    if (sl_catalog_load_path(srv->db, m->name, &p, &err) != SL_OK || !p) {
        send_error(srv, c, p ? "internal" : "not_found", p ? err.message : "no saved path with that name", "name");
        cJSON_Delete(p);
        return;
    }
    sl_client_queue_text(c, sl_msg_named_text("path", m->name, p));
}

static void on_control(sl_server *srv, sl_client *c, const sl_msg *m)
{
    sl_session *s = c->session;
    switch (m->action) {
    case SL_CONTROL_REQUEST: {
        if (!s->controller || s->controller == c->id) {
            set_controller(s, c->id);
            return;
        }
        /* One pending request per requester, not a message in the controller's
         * reply ring: repeated requests merge, and a viewer cannot fill the
         * controller's ring (which would close the controller). */
        c->wants_control = 1;
        sl_client *ctl = find_client(s, s->controller);
        if (ctl)
            lws_callback_on_writable(ctl->wsi);
        return;
    }
    case SL_CONTROL_GRANT:
        if (!require_control(srv, c, "control grant"))
            return;
        if (!find_client(s, m->client)) {
            send_error(srv, c, "not_found", "no client with that id in this session", "client");
            return;
        }
        set_controller(s, m->client);
        return;
    case SL_CONTROL_RELEASE:
        if (!require_control(srv, c, "control release"))
            return;
        pass_control(s, c->id);
        return;
    }
}

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
            send_error(srv, c, code, err.message, field);
        else
            refuse(srv, c, code, err.message, field);
        return;
    }
    if (!c->hello_done && m.type != SL_MSG_HELLO) {
        refuse(srv, c, "hello_required", "the first message must be hello", "type");
        sl_msg_deinit(&m);
        return;
    }
    if (c->hello_done && m.type == SL_MSG_HELLO) {
        send_error(srv, c, "bad_field", "hello was already received on this connection", "type");
        sl_msg_deinit(&m);
        return;
    }
    sl_session *s = c->session;
    switch (m.type) {
    case SL_MSG_HELLO:
        on_hello(srv, c, &m);
        break;
    case SL_MSG_CAMERA:
        if (require_control(srv, c, "camera")) {
            sl_play_stop(srv, s, "camera"); /* the controller takes the camera back */
            on_camera(srv, c, &m);
        }
        break;
    case SL_MSG_SET:
        if (require_control(srv, c, "set"))
            on_set(srv, c, &m);
        break;
    case SL_MSG_SCENE:
        if (require_control(srv, c, "scene")) {
            sl_play_stop(srv, s, "scene"); /* the path was checked against the technique it replaces */
            apply_scene(srv, c, m.dataset, m.technique, m.params, m.camera);
        }
        break;
    case SL_MSG_RESIZE:
        if (require_control(srv, c, "resize")) {
            pthread_mutex_lock(&srv->lock);
            s->state.width = m.width;
            s->state.height = m.height;
            s->state.phase = SL_PHASE_NONE;
            state_changed_locked(srv, s);
            pthread_mutex_unlock(&srv->lock);
            cJSON *p = cJSON_CreateObject();
            cJSON_AddNumberToObject(p, "width", m.width);
            cJSON_AddNumberToObject(p, "height", m.height);
            broadcast_patch(s, p);
        }
        break;
    case SL_MSG_LIST_DATASETS:
        sl_client_queue_text(c, sl_msg_list_text("datasets", "datasets", sl_catalog_list_json(srv->db, 0)));
        break;
    case SL_MSG_LIST_VIEWS:
        sl_client_queue_text(c, sl_msg_list_text("views", "views", sl_catalog_list_views_json(srv->db)));
        break;
    case SL_MSG_SAVE_VIEW: {
        /* Views are one catalog-wide namespace that save_view may overwrite,
         * so only a controller (who can change what the session shows
         * anyway) may write it. */
        if (!require_control(srv, c, "save_view"))
            break;
        char *params = print_and_free(sl_params_to_json(&s->state.params));
        char *camera = print_and_free(sl_camera_to_json(&s->state.camera));
        sl_status st = camera ? sl_catalog_save_view(srv->db, m.name, s->state.dataset, s->state.technique,
                                                     params ? params : "{}", camera, &err)
                              : sl_err_set(&err, SL_ERR_NOMEM, "out of memory writing the view's camera");
        free(params);
        free(camera);
        if (st) {
            send_error(srv, c, st == SL_ERR_LIMIT ? "limit" : "internal", err.message, "name");
        } else {
            sl_client_queue_text(c, sl_msg_view_saved_text(m.name));
        }
        break;
    }
    case SL_MSG_LOAD_VIEW: {
        if (!require_control(srv, c, "load_view"))
            break;
        sl_play_stop(srv, s, "scene");
        cJSON *v = NULL;
        if (sl_catalog_load_view(srv->db, m.name, &v, &err) != SL_OK || !v) {
            send_error(srv, c, "not_found", v ? err.message : "no saved view with that name", "name");
            cJSON_Delete(v);
            break;
        }
        const cJSON *ds = cJSON_GetObjectItemCaseSensitive(v, "dataset");
        const cJSON *tq = cJSON_GetObjectItemCaseSensitive(v, "technique");
        const cJSON *pa = cJSON_GetObjectItemCaseSensitive(v, "params");
        const cJSON *ca = cJSON_GetObjectItemCaseSensitive(v, "camera");
        apply_scene(srv, c, cJSON_IsString(ds) ? ds->valuestring : NULL, cJSON_IsString(tq) ? tq->valuestring : NULL,
                    cJSON_IsObject(pa) ? pa : NULL, cJSON_IsObject(ca) ? ca : NULL);
        cJSON_Delete(v);
        break;
    }
    case SL_MSG_ACK: {
        int keep = 0;
        for (int i = 0; i < c->inflight_count; i++)
            if (c->inflight[i] > m.frame_id)
                c->inflight[keep++] = c->inflight[i];
        c->inflight_count = keep;
        lws_callback_on_writable(c->wsi);
        break;
    }
    case SL_MSG_SNAPSHOT:
        pthread_mutex_lock(&srv->lock);
        if (s->snap_req_count < SL_SESSION_MAX_SNAPSHOTS) {
            s->snap_req[s->snap_req_count++] = c->id;
            pthread_cond_signal(&srv->wake);
            pthread_mutex_unlock(&srv->lock);
        } else {
            pthread_mutex_unlock(&srv->lock);
            send_error(srv, c, "busy", "too many snapshots pending in this session; retry later", "type");
        }
        break;
    case SL_MSG_CONTROL:
        on_control(srv, c, &m);
        break;
    case SL_MSG_PING:
        sl_client_queue_text(c, sl_msg_pong_text(m.seq));
        break;
    case SL_MSG_RECORD:
        if (require_control(srv, c, "record"))
            on_record(srv, c, &m);
        break;
    case SL_MSG_RECORD_CANCEL:
        if (require_control(srv, c, "record_cancel"))
            on_record_cancel(srv, c);
        break;
    case SL_MSG_SAVE_PATH:
        if (require_control(srv, c, "save_path"))
            on_save_path(srv, c, &m);
        break;
    case SL_MSG_LIST_PATHS:
        sl_client_queue_text(c, sl_msg_list_text("paths", "paths", sl_catalog_list_paths_json(srv->db)));
        break;
    case SL_MSG_LOAD_PATH:
        on_load_path(srv, c, &m);
        break;
    case SL_MSG_PLAY_PATH:
    case SL_MSG_PLAY_STOP:
    case SL_MSG_PATH_SEEK:
        if (require_control(srv, c, sl_msg_type_name(m.type)))
            on_play(srv, c, &m);
        break;
    default:
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
            pass_control(s, c->id);
        if (s->client_count == 0)
            s->empty_since_ms = sl_clock_ms();
        pthread_mutex_lock(&srv->lock);
        if (s->client_count == 0) {
            s->idle_since_ms = s->empty_since_ms; /* the render thread lets go of its prepared state later */
            pthread_cond_signal(&srv->wake);
        }
        for (int i = 0; i < s->snap_req_count; i++)
            if (s->snap_req[i] == c->id)
                s->snap_req[i] = 0;
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

/* Dataset loads that failed (render.c): the session goes back to the last
 * scene that rendered, unless its desired dataset changed since. The bounds
 * follow as the render thread's description of the kept dataset. */
static void apply_reverts(sl_server *srv)
{
    for (;;) {
        sl_session *s = NULL;
        pthread_mutex_lock(&srv->lock);
        for (sl_session *t = srv->sessions; t && !s; t = t->next)
            if (!t->doomed && t->revert_pending)
                s = t;
        int reverted = 0;
        if (s) {
            s->revert_pending = 0;
            sl_session_state *st = &s->state;
            const sl_session_state *to = &s->revert_to;
            if (strcmp(st->dataset_source, s->revert_failed_source) == 0) {
                memcpy(st->dataset, to->dataset, sizeof st->dataset);
                memcpy(st->dataset_source, to->dataset_source, sizeof st->dataset_source);
                st->dataset_is_file = to->dataset_is_file;
                st->dataset_kind = to->dataset_kind;
                memcpy(st->technique, to->technique, sizeof st->technique);
                st->params = to->params;
                st->phase = SL_PHASE_NONE;
                state_changed_locked(srv, s);
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
        broadcast_patch(s, full);
    }
}

void sl_sessions_on_wake(sl_server *srv)
{
    pthread_mutex_lock(&srv->lock);
    for (sl_session *s = srv->sessions; s; s = s->next) {
        if (s->doomed)
            continue;
        if (s->latest && s->latest->header.frame_id != s->dispatched_frame) {
            s->dispatched_frame = s->latest->header.frame_id;
            for (sl_client *c = s->clients; c; c = c->next)
                lws_callback_on_writable(c->wsi);
        }
        if (s->snap_ready) {
            for (int i = 0; i < s->snap_ready_count; i++) {
                sl_client *c = s->snap_ready_ids[i] ? find_client(s, s->snap_ready_ids[i]) : NULL;
                if (c && !c->snapshot) {
                    sl_frame_buf_ref(s->snap_ready);
                    c->snapshot = s->snap_ready;
                    lws_callback_on_writable(c->wsi);
                }
            }
            sl_frame_buf_unref(s->snap_ready);
            s->snap_ready = NULL;
            s->snap_ready_count = 0;
        }
        /* The session's newest render error is sent by write_next (coalesced:
         * a client that is behind gets the latest error once, not a backlog). */
        for (sl_client *c = s->clients; c; c = c->next)
            if (c->error_seq != s->error_seq || c->progress_seq != s->progress_seq || c->record_seq != s->record_seq)
                lws_callback_on_writable(c->wsi);
    }
    pthread_mutex_unlock(&srv->lock);
    apply_reverts(srv);
    /* Checkpoints the render thread asked for (a still frame of a new state
     * version): written here, outside the lock, one session per pass. */
    for (;;) {
        sl_session *s = NULL;
        pthread_mutex_lock(&srv->lock);
        for (sl_session *t = srv->sessions; t && !s; t = t->next)
            if (!t->doomed && t->checkpoint_due)
                s = t;
        if (s)
            s->checkpoint_due = 0;
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
        for (sl_session *t = srv->sessions; t && !s; t = t->next) {
            if (!t->doomed && t->info_pending) {
                s = t;
                s->info_pending = 0;
                bounds = s->info_bounds;
                counts = s->info_counts;
                attrs = s->info_attrs;
                s->info_bounds = s->info_counts = s->info_attrs = NULL;
                memcpy(name, s->info_dataset, sizeof name);
            }
        }
        pthread_mutex_unlock(&srv->lock);
        if (!s)
            break;
        sl_err err = {0};
        if (bounds && counts && attrs)
            sl_catalog_set_info(srv->db, name, bounds, counts, attrs, &err);
        cJSON *b = bounds ? cJSON_Parse(bounds) : NULL;
        if (b && strcmp(name, s->state.dataset) == 0) {
            cJSON_Delete(s->bounds);
            s->bounds = b;
            cJSON *p = cJSON_CreateObject();
            cJSON_AddItemToObject(p, "bounds", cJSON_Duplicate(b, 1));
            broadcast_patch(s, p);
        } else {
            cJSON_Delete(b);
        }
        free(bounds);
        free(counts);
        free(attrs);
    }
}

static int write_buf(struct lws *wsi, uint8_t *data, size_t len, enum lws_write_protocol proto)
{
    int n = lws_write(wsi, data, len, proto);
    return n < (int)len ? -1 : 0;
}

/* Writes text (consumed) at once and asks for the next writable callback. */
static int write_text_now(sl_client *c, char *text)
{
    if (!text)
        return -1;
    size_t len;
    uint8_t *buf = lws_text_buffer(text, &len);
    if (!buf)
        return -1;
    int rc = write_buf(c->wsi, buf + LWS_PRE, len, LWS_WRITE_TEXT);
    free(buf);
    lws_callback_on_writable(c->wsi);
    return rc;
}

int sl_client_write_next(sl_server *srv, sl_client *c)
{
    if (c->close_code && (!c->close_after_replies || c->reply_count == 0)) {
        lws_close_reason(c->wsi, (enum lws_close_status)c->close_code, (unsigned char *)c->close_reason,
                         strlen(c->close_reason));
        return -1;
    }
    if (c->reply_count > 0) {
        sl_reply r = c->replies[c->reply_head];
        memset(&c->replies[c->reply_head], 0, sizeof r);
        c->reply_head = (c->reply_head + 1) % SL_CLIENT_MAX_TEXT;
        c->reply_count--;
        char *text = r.text;
        if (r.code[0]) {
            text = sl_msg_error_repeat_text(r.code, r.text, r.field, r.repeated);
            free(r.text);
        }
        if (!text) {
            sl_client_close(c, LWS_CLOSE_STATUS_UNEXPECTED_CONDITION, "out of memory", 0);
            return 0;
        }
        return write_text_now(c, text);
    }
    sl_session *s = c->session;
    if (!s)
        return 0;
    if (c->patch) {
        cJSON *patch = c->patch;
        c->patch = NULL;
        return write_text_now(c, sl_msg_state_text(c->patch_version, patch));
    }
    if (s->controller == c->id) {
        for (sl_client *r = s->clients; r; r = r->next) {
            if (!r->wants_control || r == c)
                continue;
            r->wants_control = 0;
            return write_text_now(c, sl_msg_control_request_text(r->id));
        }
    }
    /* The session's progress texts, each once and in order (a client more
     * than the ring behind skips the oldest); before errors, so a failed
     * load's `done` precedes its load_failed. */
    char *progress = NULL;
    pthread_mutex_lock(&srv->lock);
    if (c->progress_seq != s->progress_seq) {
        uint32_t next = c->progress_seq + 1, oldest = s->progress_seq - (SL_PROGRESS_RING - 1);
        if (s->progress_seq >= SL_PROGRESS_RING && next < oldest)
            next = oldest;
        c->progress_seq = next;
        progress = strdup(s->progress_text[next % SL_PROGRESS_RING]);
    }
    pthread_mutex_unlock(&srv->lock);
    if (progress)
        return write_text_now(c, progress);
    char *error = NULL;
    pthread_mutex_lock(&srv->lock);
    if (c->error_seq != s->error_seq) {
        c->error_seq = s->error_seq;
        srv->metrics.errors_sent++;
        int load = strcmp(s->error_code, "load_failed") == 0;
        error = sl_msg_error_text(load ? "load_failed" : "render_failed", s->error_text, load ? "dataset" : "");
    }
    pthread_mutex_unlock(&srv->lock);
    if (error)
        return write_text_now(c, error);
    char *recording = NULL;
    pthread_mutex_lock(&srv->lock);
    if (c->record_seq != s->record_seq) {
        c->record_seq = s->record_seq;
        recording = s->record_text ? strdup(s->record_text) : NULL;
    }
    pthread_mutex_unlock(&srv->lock);
    if (recording)
        return write_text_now(c, recording);
    if (c->play_seq != s->play_seq) {
        c->play_seq = s->play_seq;
        if (s->play_text)
            return write_text_now(c, strdup(s->play_text));
    }
    if (c->snapshot) {
        sl_frame_buf *f = c->snapshot;
        c->snapshot = NULL;
        int rc = write_buf(c->wsi, f->data, f->size, LWS_WRITE_BINARY);
        sl_frame_buf_unref(f);
        lws_callback_on_writable(c->wsi);
        return rc;
    }
    sl_frame_buf *f = NULL;
    pthread_mutex_lock(&srv->lock);
    if (s->latest && s->latest->header.frame_id > c->sent_frame_id && c->inflight_count < SL_PROTO_ACK_WINDOW) {
        f = s->latest;
        sl_frame_buf_ref(f);
        if (c->sent_frame_id)
            srv->metrics.frames_dropped += f->header.frame_id - c->sent_frame_id - 1;
        srv->metrics.frames_sent++;
        srv->metrics.bytes_sent += f->size;
    }
    pthread_mutex_unlock(&srv->lock);
    if (!f)
        return 0;
    c->sent_frame_id = f->header.frame_id;
    c->inflight[c->inflight_count++] = f->header.frame_id;
    int rc = write_buf(c->wsi, f->data, f->size, LWS_WRITE_BINARY);
    sl_frame_buf_unref(f);
    return rc;
}

void sl_sessions_sweep(sl_server *srv)
{
    double now = sl_clock_ms();
    /* One expired session per pass under the lock; its catalog row is deleted
     * after unlocking, so a WAL commit never stalls the render thread. */
    for (;;) {
        char id[sizeof srv->sessions->id] = "";
        pthread_mutex_lock(&srv->lock);
        for (sl_session *s = srv->sessions; s && !id[0]; s = s->next) {
            if (s->doomed || s->client_count > 0 || now - s->empty_since_ms < srv->cfg.grace_s * 1000.0)
                continue;
            memcpy(id, s->id, sizeof id);
            s->doomed = 1;   /* the render thread may free it from here on */
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
    sl_session *s = srv->sessions;
    srv->sessions = NULL;
    pthread_mutex_unlock(&srv->lock);
    while (s) {
        sl_session *next = s->next;
        sl_session_free(s);
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
    for (sl_session *s = srv->sessions; s && !busy; s = s->next)
        busy = !s->doomed && s->client_count > 0;
    pthread_mutex_unlock(&srv->lock);
    if (busy && sl_clock_ms() - srv->drain_start_ms < srv->cfg.grace_s * 1000.0)
        return 0;
    /* What stays is handed over: each checkpoint is current, so the node a
     * client reaches next restores the session as it was. */
    pthread_mutex_lock(&srv->lock);
    int n = 0, cap = srv->session_count;
    sl_session **live = cap > 0 ? malloc(sizeof *live * (size_t)cap) : NULL;
    for (sl_session *s = srv->sessions; s && live && n < cap; s = s->next)
        if (!s->doomed)
            live[n++] = s;
    pthread_mutex_unlock(&srv->lock);
    for (int i = 0; i < n; i++) /* valid outside the lock: only this thread dooms a session */
        sl_checkpoint_write(srv, live[i]);
    free(live);
    fprintf(stderr, "sightline-server: drained%s\n", busy ? " (--grace passed; clients left are closed)" : "");
    return 1;
}

int sl_sessions_render_queue_locked(const sl_server *srv)
{
    int n = 0;
    for (const sl_session *s = srv->sessions; s; s = s->next)
        n += !s->doomed && (s->snap_req_count > 0 || s->state.version != s->rendered_version ||
                            s->rendered_interactive);
    return n;
}
