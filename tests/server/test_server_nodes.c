/* test_server_nodes.c — several sightline-server nodes on one catalog (issue 16).
 *
 * Three servers share ONE SQLite catalog file (WAL: safe across processes on
 * one machine): node-A (--agent-port, --max-sessions 4), node-B and node-C
 * (--grace 20). Checks:
 *  (a) session ids are "node-A.<16 hex>" and welcome.node names the node;
 *  (b) /healthz answers 200 with node, status ok, sessions, clients,
 *      render_queue and last_frame_ms, and the agent port answers
 *      "up ready W%" with W = 100 - 99 * sessions / max_sessions;
 *  (c) a session on A whose camera moved and whose still frame arrived is
 *      checkpointed (its row names node-A, holds the camera and only the
 *      SHA-256 of the token); after SIGKILL of A, a hello on B with the same
 *      id and token restores it: same id, node-B in welcome, same camera,
 *      dataset and size, a frame arrives, and the row now names node-B (the
 *      upgrade on /ws?session=ID, the page's form, is accepted); a
 *      second checkpointed session of A refuses a wrong token on B
 *      (bad_token) and a made-up id is unknown_session;
 *  (d) SIGTERM on C with one client connected: /healthz 503 "draining",
 *      the agent answers "drain",
 *      a new-session hello gets `draining`, the connected client still gets
 *      the frame of a camera move, and when it leaves C exits 0 within 10 s,
 *      its session's checkpoint left in the catalog for another node.
 * Loopback only; about 10-20 s (Release).
 */
#include <sqlite3.h>

#include "sl_server_harness.h"
#include "sl_test.h"

#define W 64
#define H 48
#define T 20000

static int error_code_is(cJSON *j, const char *code)
{
    const char *c = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "code"));
    int ok = c && strcmp(c, code) == 0;
    if (!ok) {
        char *t = j ? cJSON_PrintUnformatted(j) : NULL;
        fprintf(stderr, "expected error %s, got %s\n", code, t ? t : "(nothing)");
        free(t);
    }
    return ok;
}

/* The agent-check line of 127.0.0.1:port into out; 0, or -1 (5 s at most). */
static int agent_line(int port, char *out, size_t size)
{
    out[0] = 0;
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        if (fd >= 0)
            close(fd);
        return -1;
    }
    size_t len = 0;
    double deadline = sl_clock_ms() + 5000;
    while (len + 1 < size && sl_clock_ms() < deadline) {
        struct pollfd p = {.fd = fd, .events = POLLIN};
        if (poll(&p, 1, 200) <= 0)
            continue;
        ssize_t r = read(fd, out + len, size - 1 - len);
        if (r <= 0)
            break;
        len += (size_t)r;
    }
    out[len] = 0;
    close(fd);
    return len > 0 ? 0 : -1;
}

/* The checkpoint row of session id: node and state (owned, or NULL when absent). */
static char *checkpoint_row(const char *db_path, const char *id, char *node, size_t node_size, char *hash,
                            size_t hash_size)
{
    sqlite3 *db = NULL;
    char *state = NULL;
    node[0] = hash[0] = 0;
    if (sqlite3_open_v2(db_path, &db, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK) {
        sqlite3_busy_timeout(db, 2000);
        sqlite3_stmt *q = NULL;
        if (sqlite3_prepare_v2(db, "SELECT node, token_hash, state FROM sessions WHERE id = ?1", -1, &q, NULL) ==
            SQLITE_OK) {
            sqlite3_bind_text(q, 1, id, -1, SQLITE_TRANSIENT);
            if (sqlite3_step(q) == SQLITE_ROW) {
                snprintf(node, node_size, "%s", (const char *)sqlite3_column_text(q, 0));
                snprintf(hash, hash_size, "%s", (const char *)sqlite3_column_text(q, 1));
                state = strdup((const char *)sqlite3_column_text(q, 2));
            }
        }
        sqlite3_finalize(q);
    }
    sqlite3_close(db);
    return state;
}

/* Polls the catalog (50 ms) until session id's checkpoint is owned by node
 * and its state text contains want; 0, or -1 after 10 s. */
static int wait_checkpoint(const char *db, const char *id, const char *node, const char *want)
{
    double deadline = sl_clock_ms() + 10000;
    while (sl_clock_ms() < deadline) {
        char n[64], hash[80];
        char *state = checkpoint_row(db, id, n, sizeof n, hash, sizeof hash);
        int ok = state && strcmp(n, node) == 0 && strstr(state, want);
        free(state);
        if (ok)
            return 0;
        usleep(50000);
    }
    return -1;
}

static const char *str_of(const cJSON *j)
{
    const char *v = cJSON_GetStringValue(j);
    return v ? v : "";
}

static double orbit_azimuth(const cJSON *state)
{
    const cJSON *orbit = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(state, "camera"), "orbit");
    const cJSON *az = cJSON_GetObjectItemCaseSensitive(orbit, "azimuth");
    return cJSON_IsNumber(az) ? az->valuedouble : -1;
}

static const char *welcome_string(const tclient *c, const char *key)
{
    return cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(c->welcome, key));
}

static int camera_still(tclient *c, uint32_t seq, double azimuth)
{
    if (tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"camera\":{\"orbit\":{\"azimuth\":%.1f,\"elevation\":15,"
                        "\"distance\":2.5}}}", seq, azimuth))
        return -1;
    return tclient_wait_frame(c, seq, 1, T);
}

/* hello naming (session, token) or a new session; the error's code must be `code`, then a close. */
static int refused_with(int port, const char *session, const char *token, const char *code)
{
    tclient c;
    if (tclient_connect(&c, port, NULL) != 0)
        return 0;
    if (session)
        tclient_send(&c, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%s\"}", session, token);
    else
        tclient_send(&c, "{\"type\":\"hello\",\"version\":1,\"width\":%d,\"height\":%d}", W, H);
    cJSON *e = tclient_wait_type(&c, "error", T);
    int ok = error_code_is(e, code);
    cJSON_Delete(e);
    int r = tclient_next(&c, T, NULL);
    ok = ok && (r == 0 || c.closed);
    tclient_close(&c);
    return ok;
}

int main(void)
{
    harness a, b, c;
    memset(&b, 0, sizeof b);
    memset(&c, 0, sizeof c);
    b.pid = c.pid = -1;
    int agent_port = harness_free_port();
    char agent_arg[16];
    snprintf(agent_arg, sizeof agent_arg, "%d", agent_port);
    const char *args_a[] = {"--node-id", "node-A", "--agent-port", agent_arg, "--max-sessions", "4", NULL};
    HARNESS_START_OR_END(a, args_a);
    const char *args_b[] = {"--node-id", "node-B", NULL};
    int agent_port_c = harness_free_port();
    char agent_arg_c[16];
    snprintf(agent_arg_c, sizeof agent_arg_c, "%d", agent_port_c);
    const char *args_c[] = {"--node-id", "node-C", "--grace", "20", "--agent-port", agent_arg_c, NULL};
    SL_CHECK(harness_start_shared(&b, &a, args_b) == 0);
    SL_CHECK(harness_start_shared(&c, &a, args_c) == 0);

    /* (a) ids carry the node */
    tclient x;
    SL_CHECK(tclient_connect(&x, a.port, NULL) == 0);
    SL_CHECK(tclient_hello(&x, NULL, NULL, W, H) == 0);
    SL_CHECK_MSG(strncmp(x.session, "node-A.", 7) == 0 && strlen(x.session) == 7 + 16, "session id %s", x.session);
    const char *node = welcome_string(&x, "node");
    SL_CHECK_MSG(node && strcmp(node, "node-A") == 0, "welcome.node %s", node ? node : "(none)");
    SL_CHECK(tclient_wait_frame(&x, 0, 1, T) == 0);

    /* (b) /healthz and the agent */
    char body[2048];
    SL_CHECK(harness_http_get(a.port, NULL, "/healthz", body, sizeof body) == 200);
    const char *json = strstr(body, "\r\n\r\n");
    cJSON *hz = json ? cJSON_Parse(json + 4) : NULL;
    SL_CHECK_MSG(hz, "healthz body: %s", body);
    SL_CHECK(strcmp(str_of(cJSON_GetObjectItem(hz, "node")), "node-A") == 0);
    SL_CHECK(strcmp(str_of(cJSON_GetObjectItem(hz, "status")), "ok") == 0);
    SL_CHECK(cJSON_GetNumberValue(cJSON_GetObjectItem(hz, "sessions")) == 1);
    SL_CHECK(cJSON_GetNumberValue(cJSON_GetObjectItem(hz, "clients")) == 1);
    SL_CHECK(cJSON_IsNumber(cJSON_GetObjectItem(hz, "render_queue")));
    SL_CHECK_MSG(cJSON_GetNumberValue(cJSON_GetObjectItem(hz, "last_frame_ms")) > 0, "a frame was rendered: %s",
                 json ? json + 4 : "");
    cJSON_Delete(hz);
    char line[64];
    SL_CHECK(agent_line(agent_port, line, sizeof line) == 0);
    /* one session of --max-sessions 4: 100 - 99 * 1 / 4 = 76 */
    SL_CHECK_MSG(strcmp(line, "up ready 76%\n") == 0, "agent said \"%s\"", line);
    SL_CHECK(harness_metric(a.port, "sightline_draining") == 0);

    /* (c) checkpoint on A, SIGKILL, restore on B */
    SL_CHECK(camera_still(&x, 7, 123.0) == 0);
    SL_CHECK(x.last.h.camera_seq == 7);
    SL_CHECK_MSG(wait_checkpoint(a.db, x.session, "node-A", "\"azimuth\":123") == 0,
                 "checkpoint of the moved camera written by node-A");
    char owner[64], hash[80];
    char *state = checkpoint_row(a.db, x.session, owner, sizeof owner, hash, sizeof hash);
    SL_CHECK_MSG(state && strlen(hash) == 64 && !strstr(state, x.token) && strcmp(hash, x.token) != 0,
                 "only the token's hash is stored (%s)", hash);
    free(state);
    tclient y; /* a second session: its wrong token is refused from its checkpoint */
    SL_CHECK(tclient_connect(&y, a.port, NULL) == 0);
    SL_CHECK(tclient_hello(&y, NULL, NULL, W, H) == 0);
    SL_CHECK(tclient_wait_frame(&y, 0, 1, T) == 0);
    SL_CHECK(wait_checkpoint(a.db, y.session, "node-A", "\"dataset\":\"tiny\"") == 0);
    SL_CHECK(agent_line(agent_port, line, sizeof line) == 0 && strcmp(line, "up ready 51%\n") == 0);
    char sid[64], tok[64], sid2[64];
    snprintf(sid, sizeof sid, "%s", x.session);
    snprintf(tok, sizeof tok, "%s", x.token);
    snprintf(sid2, sizeof sid2, "%s", y.session);
    harness_signal(&a, SIGKILL);
    SL_CHECK(harness_wait(&a, 5000) == -1);
    tclient_close(&x);
    tclient_close(&y);

    tclient r; /* the page's URL form: the session id in the query, for a balancer; the server ignores it */
    memset(&r, 0, sizeof r);
    char ws_path[128];
    snprintf(ws_path, sizeof ws_path, "/ws?session=%s", sid);
    SL_CHECK_MSG(sl_wsclient_connect("127.0.0.1", b.port, ws_path, SL_PROTO_SUBPROTOCOL, NULL, 10000, &r.ws, &r.err) ==
                 SL_OK, "upgrade on %s: %s", ws_path, r.err.message);
    SL_CHECK(tclient_hello(&r, sid, tok, W, H) == 0);
    SL_CHECK_MSG(strcmp(r.session, sid) == 0 && strcmp(r.token, tok) == 0, "restored as %s", r.session);
    node = welcome_string(&r, "node");
    SL_CHECK(node && strcmp(node, "node-B") == 0);
    const cJSON *ws = cJSON_GetObjectItemCaseSensitive(r.welcome, "state");
    SL_CHECK_MSG(fabs(orbit_azimuth(ws) - 123.0) < 1e-6, "restored azimuth %g", orbit_azimuth(ws));
    SL_CHECK(strcmp(str_of(cJSON_GetObjectItem(ws, "dataset")), "tiny") == 0);
    SL_CHECK(cJSON_GetNumberValue(cJSON_GetObjectItem(ws, "width")) == W &&
             cJSON_GetNumberValue(cJSON_GetObjectItem(ws, "height")) == H);
    SL_CHECK(tclient_wait_frame(&r, 0, 1, T) == 0);
    SL_CHECK(r.last.h.width == W && r.last.h.height == H);
    state = checkpoint_row(a.db, sid, owner, sizeof owner, hash, sizeof hash);
    SL_CHECK_MSG(state && strcmp(owner, "node-B") == 0, "owner after the restore: %s", owner);
    free(state);
    SL_CHECK(refused_with(b.port, sid2, "00000000000000000000000000000000", "bad_token"));
    SL_CHECK(refused_with(b.port, "node-A.0123456789abcdef", tok, "unknown_session"));
    SL_CHECK(camera_still(&r, 8, 45.0) == 0); /* the restored session is live: B renders its camera */
    tclient_close(&r);

    /* (d) drain */
    tclient d;
    SL_CHECK(tclient_connect(&d, c.port, NULL) == 0);
    SL_CHECK(tclient_hello(&d, NULL, NULL, W, H) == 0);
    d.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&d, 0, 1, T) == 0);
    harness_signal(&c, SIGTERM);
    int status = 0;
    double deadline = sl_clock_ms() + 5000;
    while ((status = harness_http_get(c.port, NULL, "/healthz", body, sizeof body)) != 503 && sl_clock_ms() < deadline)
        usleep(50000);
    SL_CHECK_MSG(status == 503 && strstr(body, "\"status\":\"draining\"") && strstr(body, "\"node\":\"node-C\""),
                 "healthz while draining: %d %s", status, body);
    SL_CHECK(harness_metric(c.port, "sightline_draining") == 1);
    SL_CHECK(agent_line(agent_port_c, line, sizeof line) == 0 && strcmp(line, "drain\n") == 0);
    SL_CHECK(refused_with(c.port, NULL, NULL, "draining"));
    SL_CHECK(harness_wait(&c, 0) == -2); /* still running for its client */
    SL_CHECK(camera_still(&d, 3, 200.0) == 0);
    SL_CHECK(d.last.h.camera_seq == 3);
    char csid[64];
    snprintf(csid, sizeof csid, "%s", d.session);
    tclient_close(&d);
    double t0 = sl_clock_ms();
    status = harness_wait(&c, 10000);
    SL_CHECK_MSG(status == 0, "drained node exit status %d after %.0f ms", status, sl_clock_ms() - t0);
    fprintf(stderr, "node-C exited %.0f ms after its last client left\n", sl_clock_ms() - t0);
    SL_CHECK_MSG(wait_checkpoint(a.db, csid, "node-C", "\"azimuth\":200") == 0,
                 "the drained session is handed over through its checkpoint");

    harness_stop(&c);
    status = harness_stop(&b);
    SL_CHECK_MSG(status == 0, "node-B exit status %d", status);
    harness_stop(&a);
    SL_TEST_END();
}
