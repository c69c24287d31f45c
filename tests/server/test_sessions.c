/* test_sessions.c — the session layer without sockets (server/sessions library).
 *
 * Two fake clients (sl_client structs whose transport hooks count calls) talk to the
 * sessions through sl_sessions_on_text / on_close, as ws.c would hand them messages: no
 * lws context, no GL, no network, no render thread. The catalog is a temporary SQLite file.
 * Asserted: hello makes a session and a welcome (the creator controls it), a second hello
 * with the id and token joins it as a viewer, a viewer's camera is refused with
 * not_controller, `set` by the controller bumps the state version (a render request: the
 * render queue counts the session) and reaches the viewer as a coalesced patch, a control
 * request waits as a flag and wakes the controller, a grant moves control, the new
 * controller's camera is accepted, a path plays (the transport's timer is armed, a tick
 * moves the camera and arms it again), the controller leaving hands control on, the last
 * client leaving starts the grace period and the sweep ends the session once it is over.
 * Service thread only (this one).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sessions/sl_sessions.h"
#include "sl_test.h"

static int wakes[8], closings[8], hellos, play_schedules;
static double last_schedule_ms = -1.0;

static void fake_want_write(sl_client *c) { wakes[c->id]++; }
static void fake_closing(sl_client *c) { closings[c->id]++; }
static void fake_hello_done(sl_server *srv, sl_client *c)
{
    (void)srv;
    (void)c;
    hellos++;
}
static void fake_schedule_play(sl_server *srv, double ms)
{
    (void)srv;
    play_schedules++;
    last_schedule_ms = ms;
}

static void say(sl_server *srv, sl_client *c, const char *text) { sl_sessions_on_text(srv, c, text, strlen(text)); }

/* The newest queued reply of c (its text, or an error's code), "" when none. */
static const char *last_reply(const sl_client *c, char *out, size_t size)
{
    out[0] = '\0';
    if (c->reply_count == 0)
        return out;
    const sl_reply *r = &c->replies[(c->reply_head + c->reply_count - 1) % SL_CLIENT_MAX_TEXT];
    snprintf(out, size, "%s", r->code[0] ? r->code : r->text);
    return out;
}

/* Drops c's queued replies (as if the transport had written them). */
static void drain_replies(sl_client *c)
{
    for (int i = 0; i < c->reply_count; i++)
        free(c->replies[(c->reply_head + i) % SL_CLIENT_MAX_TEXT].text);
    memset(c->replies, 0, sizeof c->replies);
    c->reply_head = c->reply_count = 0;
}

static int patch_has(const sl_client *c, const char *key)
{
    return c->patch && cJSON_GetObjectItemCaseSensitive(c->patch, key) != NULL;
}

static void drop_patch(sl_client *c)
{
    cJSON_Delete(c->patch);
    c->patch = NULL;
}

int main(void)
{
    char catalog[] = "/tmp/sightline-test-sessions-XXXXXX";
    int fd = mkstemp(catalog);
    SL_CHECK(fd >= 0);
    close(fd);
    sl_server *srv = calloc(1, sizeof *srv);
    sl_err err = {0};
    snprintf(srv->cfg.node_id, sizeof srv->cfg.node_id, "unit");
    srv->cfg.max_clients = 8;
    srv->cfg.max_sessions = 4;
    srv->cfg.grace_s = 300;
    pthread_mutex_init(&srv->lock, NULL);
    pthread_cond_init(&srv->wake, NULL);
    SL_CHECK_MSG(sl_catalog_open(catalog, &srv->db, &err) == SL_OK && sl_catalog_init_defaults(srv->db, NULL, 0, &err) == SL_OK,
                 "%s", err.message);
    srv->techniques_json = cJSON_CreateArray();
    srv->transport = (sl_transport_hooks){.schedule_play = fake_schedule_play, .hello_done = fake_hello_done,
                                          .want_write = fake_want_write, .closing = fake_closing};
    sl_client a = {.id = 1, .transport = &srv->transport}, b = {.id = 2, .transport = &srv->transport};
    char reply[4096];

    /* hello: a new session, a controls it */
    say(srv, &a, "{\"type\":\"hello\",\"version\":1,\"width\":64,\"height\":48}");
    SL_CHECK(a.session != NULL && a.hello_done && hellos == 1);
    SL_CHECK_MSG(strstr(last_reply(&a, reply, sizeof reply), "\"welcome\"") != NULL, "%s", reply);
    SL_CHECK(srv->session_count == 1 && a.session && a.session->controller == a.id);
    cJSON *welcome = cJSON_Parse(reply);
    const cJSON *sid = cJSON_GetObjectItemCaseSensitive(welcome, "session");
    const cJSON *tok = cJSON_GetObjectItemCaseSensitive(welcome, "token");
    SL_CHECK(cJSON_IsString(sid) && cJSON_IsString(tok));
    char join[256];
    snprintf(join, sizeof join, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%s\"}",
             cJSON_IsString(sid) ? sid->valuestring : "", cJSON_IsString(tok) ? tok->valuestring : "");
    cJSON_Delete(welcome);
    drain_replies(&a);
    sl_session *s = a.session;
    if (!s)
        SL_TEST_END();

    /* a second client joins with the id and token: a viewer */
    say(srv, &b, join);
    SL_CHECK(b.session == s && s->client_count == 2 && s->controller == a.id);
    SL_CHECK_MSG(strstr(last_reply(&b, reply, sizeof reply), "\"role\":\"viewer\"") != NULL, "%s", reply);
    drain_replies(&b);
    /* a wrong token is refused and the link told to close */
    sl_client intruder = {.id = 3, .transport = &srv->transport};
    snprintf(join, sizeof join, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%032d\"}", s->id, 0);
    say(srv, &intruder, join);
    SL_CHECK(intruder.session == NULL && closings[3] == 1 && intruder.close_code == SL_CLOSE_POLICY_VIOLATION);
    sl_sessions_on_close(srv, &intruder);

    /* the viewer's camera is refused; its own reply names why */
    const char *camera = "{\"type\":\"camera\",\"seq\":1,\"phase\":\"move\","
                         "\"camera\":{\"orbit\":{\"azimuth\":75,\"elevation\":12,\"distance\":2.1},\"fov_y\":45}}";
    uint32_t v0 = s->slot.state.version;
    say(srv, &b, camera);
    SL_CHECK_MSG(strcmp(last_reply(&b, reply, sizeof reply), "not_controller") == 0, "%s", reply);
    SL_CHECK(s->slot.state.version == v0);
    drain_replies(&b);

    /* set by the controller: a render request, and a patch for the viewer */
    pthread_mutex_lock(&srv->lock);
    s->slot.rendered_version = s->slot.state.version; /* as if the render thread had drawn it */
    SL_CHECK(sl_sessions_render_queue_locked(srv) == 0);
    pthread_mutex_unlock(&srv->lock);
    int b_wakes = wakes[2];
    say(srv, &a, "{\"type\":\"set\",\"background\":[1,1,1,1]}");
    SL_CHECK(s->slot.state.version == v0 + 1 && s->slot.state.background[0] == 1.0f);
    pthread_mutex_lock(&srv->lock);
    SL_CHECK(sl_sessions_render_queue_locked(srv) == 1);
    pthread_mutex_unlock(&srv->lock);
    SL_CHECK(patch_has(&b, "background") && wakes[2] > b_wakes);
    /* a second change merges into the one pending patch (newest value wins) */
    say(srv, &a, "{\"type\":\"set\",\"background\":[0,0,0,1]}");
    SL_CHECK(patch_has(&b, "background") && b.patch_version == s->slot.state.version);
    const cJSON *bg = cJSON_GetObjectItemCaseSensitive(b.patch, "background");
    SL_CHECK(cJSON_IsArray(bg) && cJSON_GetArrayItem(bg, 0) && cJSON_GetArrayItem(bg, 0)->valuedouble == 0.0);
    drop_patch(&a);
    drop_patch(&b);

    /* a control request is a flag on the requester and wakes the controller; grant moves control */
    int a_wakes = wakes[1];
    say(srv, &b, "{\"type\":\"control\",\"action\":\"request\"}");
    say(srv, &b, "{\"type\":\"control\",\"action\":\"request\"}");
    SL_CHECK(b.wants_control == 1 && b.reply_count == 0 && wakes[1] >= a_wakes + 2 && s->controller == a.id);
    say(srv, &a, "{\"type\":\"control\",\"action\":\"grant\",\"client\":2}");
    SL_CHECK(s->controller == b.id && b.wants_control == 0 && patch_has(&a, "controller"));
    drop_patch(&a);
    drop_patch(&b);

    /* now b's camera is accepted and reaches a */
    uint32_t v1 = s->slot.state.version;
    say(srv, &b, camera);
    SL_CHECK(s->slot.state.version == v1 + 1 && s->slot.state.camera_seq == 1 && s->slot.state.phase == SL_PHASE_MOVE);
    SL_CHECK(patch_has(&a, "camera") && b.reply_count == 0);
    drop_patch(&a);
    drop_patch(&b);

    /* a path plays: the transport's timer is armed, a tick moves the camera and arms it again */
    say(srv, &b, "{\"type\":\"play_path\",\"path\":{\"fps\":24,\"keyframes\":[{\"t\":0,\"camera\":{\"orbit\":"
                 "{\"azimuth\":0}}},{\"t\":4,\"camera\":{\"orbit\":{\"azimuth\":90}}}]},\"loop\":false}");
    SL_CHECK_MSG(s->play != NULL && play_schedules == 1 && last_schedule_ms == 0.0, "%s",
                 last_reply(&b, reply, sizeof reply));
    uint32_t v2 = s->slot.state.version;
    double next = sl_play_tick(srv);
    SL_CHECK(s->slot.state.version > v2 && patch_has(&a, "camera") && next >= 0.0 && next <= 1000.0 / 24.0 + 1.0);
    /* the controller's own camera stops it */
    say(srv, &b, camera);
    SL_CHECK(s->play == NULL && sl_play_tick(srv) < 0.0);
    drop_patch(&a);
    drop_patch(&b);
    drain_replies(&a);
    drain_replies(&b);

    /* the controller leaves: control passes to a; the last one leaving starts the grace period */
    sl_sessions_on_close(srv, &b);
    SL_CHECK(s->client_count == 1 && s->controller == a.id);
    sl_sessions_on_close(srv, &a);
    SL_CHECK(s->client_count == 0 && s->empty_since_ms > 0.0);
    sl_sessions_sweep(srv);
    SL_CHECK(srv->session_count == 1 && !s->slot.doomed); /* grace not over */
    srv->cfg.grace_s = 0;
    sl_sessions_sweep(srv);
    SL_CHECK(srv->session_count == 0 && s->slot.doomed);

    sl_sessions_destroy_all(srv);
    cJSON_Delete(srv->techniques_json);
    sl_catalog_close(srv->db);
    unlink(catalog);
    char wal[sizeof catalog + 8];
    snprintf(wal, sizeof wal, "%s-wal", catalog);
    unlink(wal);
    snprintf(wal, sizeof wal, "%s-shm", catalog);
    unlink(wal);
    pthread_cond_destroy(&srv->wake);
    pthread_mutex_destroy(&srv->lock);
    free(srv);
    SL_TEST_END();
}
