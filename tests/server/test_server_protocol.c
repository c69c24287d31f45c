/* test_server_protocol.c — the sightline.v1 protocol against a running sightline-server.
 *
 * Starts a private server (sl_server_harness.h) on a free loopback port and
 * checks, each with assertions that fail on a wrong server: hello/welcome;
 * frames arrive, carry a valid header and decode to the session size; a
 * camera change gives a different image; dragging at the fixed half scale
 * gives half-size interactive frames then a full-size still; malformed JSON, unknown type,
 * unknown and out-of-range parameters each give an `error` and the
 * connection keeps working; oversize messages close only that connection
 * (1009); a wrong token is refused; two clients of one session see each
 * other's changes and the same frame ids; viewers are refused until granted
 * control; the ack window holds; snapshots are PNGs; views save and load;
 * scene switches (a vanished file gives load_failed without the server's
 * path); the Origin check; /healthz and /metrics; and a session
 * outlives its clients for the grace period, then expires. The server must
 * exit cleanly (status 0, so no ASan leak report) at the end.
 */
#include <math.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <arpa/inet.h>

#include "sl_server_harness.h"
#include "sl_test.h"
#include "image/sl_image.h"

#define W 128
#define H 96
#define T 20000   /* generous per-step timeout (ASan + llvmpipe on 2 busy cores) */

static int error_is(cJSON *j, const char *code, const char *field)
{
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(j, "code");
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(j, "field");
    int ok = j && cJSON_IsString(c) && strcmp(c->valuestring, code) == 0 &&
             (!field || (cJSON_IsString(f) && strcmp(f->valuestring, field) == 0));
    if (!ok) {
        char *t = j ? cJSON_PrintUnformatted(j) : NULL;
        fprintf(stderr, "expected error %s/%s, got %s\n", code, field ? field : "*", t ? t : "(nothing)");
        free(t);
    }
    return ok;
}

/* The connection still answers: ping -> pong with the same seq. */
static int still_usable(tclient *c, int seq)
{
    return tclient_ping(c, seq, T);
}

static int http_get(int port, const char *path, char *out, size_t out_size)
{
    return harness_http_get(port, NULL, path, out, out_size);
}

/* Waits for a state patch whose `key` is the string `value`; returns its version (0 on timeout). */
static uint32_t wait_patch(tclient *c, const char *key, const char *value)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *m = tclient_wait_type(c, "state", T);
        if (!m)
            return 0;
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), key);
        uint32_t version = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
        int hit = cJSON_IsString(v) && strcmp(v->valuestring, value) == 0;
        cJSON_Delete(m);
        if (hit)
            return version;
    }
    return 0;
}

/* Waits for a state patch carrying `key`; returns the message (caller frees) or NULL. */
static cJSON *wait_patch_key(tclient *c, const char *key)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *m = tclient_wait_type(c, "state", T);
        if (!m)
            return NULL;
        if (cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), key))
            return m;
        cJSON_Delete(m);
    }
    return NULL;
}

/* Waits for a patch that sets the controller; returns it (-1 on timeout). */
static int wait_controller(tclient *c)
{
    cJSON *m = wait_patch_key(c, "controller");
    int id = m ? cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), "controller")->valueint
               : -1;
    cJSON_Delete(m);
    return id;
}

/* Sends msg from a viewer and expects not_controller; the state must not change. */
static int refused_for_viewer(tclient *c, const char *msg)
{
    if (tclient_send(c, "%s", msg))
        return 0;
    cJSON *e = tclient_wait_type(c, "error", T);
    int ok = error_is(e, "not_controller", NULL);
    cJSON_Delete(e);
    if (!ok)
        fprintf(stderr, "viewer message not refused: %s\n", msg);
    return ok;
}

/* Waits for a text of the given type or an error; returns it (caller frees) or NULL. */
static cJSON *wait_reply(tclient *c, const char *type)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, T, &j);
        if (r == 1 && (strcmp(json_type(j), type) == 0 || strcmp(json_type(j), "error") == 0))
            return j;
        cJSON_Delete(j);
        if (r == 0)
            return NULL;
    }
    return NULL;
}

/* Upgrade with an explicit Host header and Origin; 0 when the server answers 101. */
static int upgrade_with(int port, const char *host, const char *origin)
{
    sl_wsclient *ws = NULL;
    sl_err err = {0};
    sl_status st = sl_wsclient_connect_host("127.0.0.1", port, host, "/ws", SL_PROTO_SUBPROTOCOL, origin, 10000, &ws,
                                            &err);
    sl_wsclient_destroy(ws);
    return st == SL_OK ? 0 : -1;
}

/* GET / with an explicit Host header; returns the HTTP status. */
static int http_status_with_host(int port, const char *host)
{
    char out[512];
    return harness_http_get(port, host, "/", out, sizeof out);
}

/* Waits for a still frame of camera_seq >= seq; counts the error messages
 * received meanwhile into *errors. 1 when the frame came. */
static int wait_still_counting_errors(tclient *c, uint32_t seq, int *errors)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int rr = tclient_next(c, T, &j);
        if (rr == 1 && strcmp(json_type(j), "error") == 0)
            (*errors)++;
        cJSON_Delete(j);
        if (rr == 2 && c->last.h.camera_seq >= seq && !(c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE))
            return 1;
        if (rr == 0)
            return 0;
    }
    return 0;
}

static double metric(const char *text, const char *name)
{
    char key[128];
    snprintf(key, sizeof key, "\n%s ", name);
    const char *p = strstr(text, key);
    return p ? atof(p + strlen(key)) : -1;
}

/* First int or float parameter of the current technique's schema: name, min, max. */
static int pick_numeric_param(const cJSON *welcome, char *name, size_t size, double *lo, double *hi, int *is_int)
{
    const cJSON *state = cJSON_GetObjectItemCaseSensitive(welcome, "state");
    const cJSON *tech = cJSON_GetObjectItemCaseSensitive(state, "technique");
    const cJSON *t;
    cJSON_ArrayForEach(t, cJSON_GetObjectItemCaseSensitive(welcome, "techniques")) {
        const cJSON *tn = cJSON_GetObjectItemCaseSensitive(t, "name");
        if (!cJSON_IsString(tn) || !cJSON_IsString(tech) || strcmp(tn->valuestring, tech->valuestring) != 0)
            continue;
        const cJSON *p;
        cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(t, "params")) {
            const cJSON *type = cJSON_GetObjectItemCaseSensitive(p, "type");
            if (cJSON_IsString(type) && (strcmp(type->valuestring, "int") == 0 || strcmp(type->valuestring, "float") == 0)) {
                snprintf(name, size, "%s", cJSON_GetObjectItemCaseSensitive(p, "name")->valuestring);
                *lo = cJSON_GetObjectItemCaseSensitive(p, "min")->valuedouble;
                *hi = cJSON_GetObjectItemCaseSensitive(p, "max")->valuedouble;
                *is_int = strcmp(type->valuestring, "int") == 0;
                return 0;
            }
        }
    }
    return -1;
}

int main(void)
{
    harness h;
    const char *extra[] = {"--grace", "2", "--hello-timeout", "2", "--allow-origin", "https://viz.example.org", NULL};
    HARNESS_START_OR_END(h, extra);
    printf("server on port %d\n", h.port);

    /* --- hello / welcome --- */
    tclient a;
    SL_CHECK(tclient_connect(&a, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&a, NULL, NULL, W, H) == 0);
    SL_CHECK(sl_session_id_valid(a.session) && strlen(a.token) == 32); /* NODE.<16 hex> */
    SL_CHECK(a.client_id > 0);
    const cJSON *wst = cJSON_GetObjectItemCaseSensitive(a.welcome, "state");
    SL_CHECK(cJSON_GetObjectItemCaseSensitive(wst, "width")->valueint == W);
    SL_CHECK(strcmp(cJSON_GetObjectItemCaseSensitive(wst, "dataset")->valuestring, "tiny") == 0);
    SL_CHECK(strcmp(cJSON_GetObjectItemCaseSensitive(a.welcome, "role")->valuestring, "controller") == 0);
    SL_CHECK(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(a.welcome, "techniques")) >= 1);
    SL_CHECK(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(a.welcome, "datasets")) >= 2);
    SL_CHECK(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(a.welcome, "limits"), "ack_window")
                 ->valueint == 2);
    /* The page's camera numbers: a new session starts at camera_default, and the limit is core's. */
    {
        const cJSON *me = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(a.welcome, "limits"),
                                                           "max_elevation");
        SL_CHECK(cJSON_IsNumber(me) && me->valuedouble == SL_ORBIT_MAX_ELEVATION);
        const cJSON *cd = cJSON_GetObjectItemCaseSensitive(a.welcome, "camera_default");
        SL_CHECK(cJSON_IsObject(cd) && cJSON_Compare(cd, cJSON_GetObjectItemCaseSensitive(wst, "camera"), 1));
    }
    a.auto_ack = 1;

    /* --- first frame arrives, header valid, decodes to the session size, shows something --- */
    SL_CHECK(tclient_wait_frame(&a, 0, 1, T) == 0);
    SL_CHECK(a.last.h.width == W && a.last.h.height == H);
    SL_CHECK(a.last.h.quality == 92 && a.last.h.subsampling == 0);
    SL_CHECK(a.last.h.state_version >= 1 && a.last.h.frame_id >= 1);
    sl_image first = tclient_decode_last(&a);
    SL_CHECK(first.width == W && first.height == H);
    double fg = harness_foreground_fraction(&first);
    SL_CHECK_MSG(fg > 0.01 && fg < 0.95, "foreground fraction %.3f", fg);

    /* --- a camera change produces a different frame --- */
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":5,\"camera\":{\"orbit\":{\"azimuth\":120,\"elevation\":-30,\"distance\":2}}}") == 0);
    SL_CHECK(tclient_wait_frame(&a, 5, 1, T) == 0);
    SL_CHECK(a.last.h.camera_seq == 5);
    sl_image second = tclient_decode_last(&a);
    double d = harness_mean_diff(&first, &second);
    SL_CHECK_MSG(d > 1.0, "mean abs difference after a camera change %.3f", d);

    /* --- dragging at a fixed scale (adaptive off, interactive_scale 0.5): half-size
     *     interactive frames, then a full-size still once the session's
     *     still_delay_ms (set to 1500 here, a stream setting) has passed;
     *     test_server_adaptive covers the adaptive scale --- */
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"stream\":{\"still_delay_ms\":1500,\"interactive_adaptive\":false,"
                              "\"interactive_scale\":0.5}}") == 0);
    cJSON *sp = tclient_wait_type(&a, "state", T);
    const cJSON *sd = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(sp, "patch"), "stream"), "still_delay_ms");
    SL_CHECK(sd && sd->valueint == 1500);
    cJSON_Delete(sp);
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"stream\":{\"still_delay_ms\":-1}}") == 0);
    cJSON *se = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(se, "bad_field", "stream.still_delay_ms"));
    cJSON_Delete(se);
    double move_sent = sl_clock_ms();
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":6,\"phase\":\"move\",\"camera\":{\"orbit\":{\"azimuth\":140,\"elevation\":-20,\"distance\":2}}}") == 0);
    SL_CHECK(tclient_wait_frame(&a, 6, 0, T) == 0);
    int saw_interactive = (a.last.h.flags & SL_FRAME_FLAG_INTERACTIVE) != 0;
    if (saw_interactive) {
        SL_CHECK(a.last.h.width == W / 2 && a.last.h.height == H / 2);
        SL_CHECK(a.last.h.quality == 60 && a.last.h.subsampling == 1);
        sl_image half = tclient_decode_last(&a);
        SL_CHECK(half.width == W / 2);
        sl_image_deinit(&half);
    }
    SL_CHECK_MSG(saw_interactive, "first frame after a move was not interactive (flags %u)", a.last.h.flags);
    SL_CHECK(tclient_wait_frame(&a, 6, 1, T) == 0);
    SL_CHECK(a.last.h.width == W && !(a.last.h.flags & SL_FRAME_FLAG_INTERACTIVE));
    SL_CHECK_MSG(a.last.arrival_ms - move_sent >= 1450, "still frame %.0f ms after the move (delay 1500)",
                 a.last.arrival_ms - move_sent);
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"stream\":{\"still_delay_ms\":200}}") == 0);

    /* --- malformed JSON, unknown type, bad parameter: error, connection stays usable --- */
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",") == 0);
    cJSON *e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "bad_json", NULL));
    cJSON_Delete(e);
    SL_CHECK(still_usable(&a, 1));
    SL_CHECK(tclient_send(&a, "{\"type\":\"teleport\"}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "unknown_type", "type"));
    cJSON_Delete(e);
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"no_such_param\":1}}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "bad_param", "params.no_such_param"));
    cJSON_Delete(e);
    char pname[64];
    double plo = 0, phi = 0;
    int pint = 0;
    SL_CHECK(pick_numeric_param(a.welcome, pname, sizeof pname, &plo, &phi, &pint) == 0);
    char pfield[80];
    snprintf(pfield, sizeof pfield, "params.%s", pname);
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"%s\":%.17g}}", pname, phi * 2 + 1) == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "bad_param", pfield));
    cJSON_Delete(e);
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":7,\"camera\":{\"orbit\":{\"azimuth\":1,\"elevation\":2,\"distance\":-1}}}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "bad_field", "camera"));
    cJSON_Delete(e);
    SL_CHECK(still_usable(&a, 2));

    /* --- cameras that would not render are refused on arrival, naming the field;
     *     the state does not change and no client gets render_failed --- */
    {
        SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":60,\"camera\":{\"orbit\":{\"azimuth\":10,\"elevation\":5,\"distance\":2}}}") == 0);
        cJSON *m = wait_patch_key(&a, "camera_seq");
        uint32_t v0 = m ? (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble : 0;
        cJSON_Delete(m);
        static const char *const bad[][2] = {
            {"{\"orbit\":{\"azimuth\":1e308,\"elevation\":0,\"distance\":2}}", "camera.orbit.azimuth"},
            {"{\"orbit\":{\"azimuth\":0,\"elevation\":0,\"distance\":1e300}}", "camera.orbit.distance"},
            {"{\"orbit\":{\"azimuth\":0,\"elevation\":91,\"distance\":2}}", "camera.orbit.elevation"},
            {"{\"eye\":[1e300,0,0],\"target\":[0,0,0]}", "camera.eye"},
            {"{\"eye\":[0,0,1],\"target\":[0,0,0],\"up\":[0,0,1]}", "camera.up"},
            {"{\"fov_y\":180,\"orbit\":{\"azimuth\":0,\"elevation\":0,\"distance\":2}}", "camera.fov_y"},
        };
        for (int i = 0; i < (int)(sizeof bad / sizeof bad[0]); i++) {
            SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":%d,\"camera\":%s}", 61 + i, bad[i][0]) == 0);
            e = tclient_wait_type(&a, "error", T);
            const cJSON *msg = cJSON_GetObjectItemCaseSensitive(e, "message");
            SL_CHECK(error_is(e, "bad_field", "camera"));
            SL_CHECK_MSG(cJSON_IsString(msg) && strstr(msg->valuestring, bad[i][1]), "camera %s: message %s", bad[i][0],
                         cJSON_IsString(msg) ? msg->valuestring : "(none)");
            cJSON_Delete(e);
        }
        SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":70,\"camera\":{\"orbit\":{\"azimuth\":15,\"elevation\":5,\"distance\":2}}}") == 0);
        m = wait_patch_key(&a, "camera_seq");
        uint32_t v1 = m ? (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble : 0;
        const cJSON *seq = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), "camera_seq");
        SL_CHECK_MSG(v0 > 0 && v1 == v0 + 1, "state version %u -> %u across refused cameras", v0, v1);
        SL_CHECK(seq && seq->valueint == 70);
        /* The state echoes the parsed camera, complete: the fov the client left out is the default. */
        const cJSON *pc = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), "camera");
        const cJSON *fov = cJSON_GetObjectItemCaseSensitive(pc, "fov_y");
        SL_CHECK_MSG(cJSON_IsNumber(fov) && fov->valuedouble == sl_orbit_default.fov_y_deg &&
                         cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(pc, "orbit"), "azimuth")
                                 ->valuedouble == 15.0,
                     "camera echo is not complete");
        cJSON_Delete(m);
        int render_failed = 0;
        int got = wait_still_counting_errors(&a, 70, &render_failed);
        SL_CHECK_MSG(got && render_failed == 0, "frame for seq 70: %d, errors meanwhile: %d", got, render_failed);
    }

    /* A valid parameter change is broadcast as a state patch and renders a new frame. */
    uint32_t before = a.max_frame_id;
    double newv = pint ? plo : fmin(phi, plo + 0.01);
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"%s\":%.17g}}", pname, newv) == 0);
    cJSON *st = tclient_wait_type(&a, "state", T);
    const cJSON *pp = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(st, "patch"), "params");
    SL_CHECK(pp && fabs(cJSON_GetObjectItemCaseSensitive(pp, pname)->valuedouble - newv) < 1e-9);
    uint32_t set_version = st ? (uint32_t)cJSON_GetObjectItemCaseSensitive(st, "version")->valuedouble : 0;
    cJSON_Delete(st);
    SL_CHECK(set_version > 0 && tclient_wait_version(&a, set_version, T) == 0 && a.max_frame_id > before);

    /* --- oversize messages close only that connection --- */
    tclient big;
    SL_CHECK(tclient_connect(&big, h.port, NULL) == 0);
    char *huge = malloc(SL_PROTO_MAX_HELLO + 100);
    memset(huge, ' ', SL_PROTO_MAX_HELLO + 100);
    huge[0] = '{';
    huge[SL_PROTO_MAX_HELLO + 99] = '}';
    SL_CHECK(sl_wsclient_send_text(big.ws, huge, SL_PROTO_MAX_HELLO + 100, &big.err) == SL_OK);
    free(huge);
    cJSON *junk = NULL;
    int r = tclient_next(&big, T, &junk);
    cJSON_Delete(junk);
    SL_CHECK_MSG(r == 0 && big.close_code == 1009, "before hello: r=%d close=%d", r, big.close_code);
    tclient_close(&big);
    SL_CHECK(tclient_connect(&big, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&big, NULL, NULL, 32, 32) == 0);
    size_t hn = SL_PROTO_MAX_MESSAGE + 10;
    huge = malloc(hn);
    memset(huge, ' ', hn);
    huge[0] = '{';
    huge[hn - 1] = '}';
    SL_CHECK(sl_wsclient_send_text(big.ws, huge, hn, &big.err) == SL_OK);
    free(huge);
    do {
        junk = NULL;
        r = tclient_next(&big, T, &junk);
        cJSON_Delete(junk);
    } while (r > 0);
    SL_CHECK_MSG(r == 0 && big.close_code == 1009, "after hello: r=%d close=%d", r, big.close_code);
    tclient_close(&big);
    SL_CHECK(still_usable(&a, 3));

    /* --- wrong token refused (error, then close); unknown session too --- */
    tclient bad;
    SL_CHECK(tclient_connect(&bad, h.port, NULL) == 0);
    SL_CHECK(tclient_send(&bad, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%s\"}", a.session,
                          "00000000000000000000000000000000") == 0);
    e = tclient_wait_type(&bad, "error", T);
    SL_CHECK(error_is(e, "bad_token", "token"));
    cJSON_Delete(e);
    r = tclient_next(&bad, T, NULL);
    SL_CHECK(r == 0 || bad.closed);
    tclient_close(&bad);
    SL_CHECK(tclient_connect(&bad, h.port, NULL) == 0);
    SL_CHECK(tclient_send(&bad, "{\"type\":\"camera\",\"seq\":1,\"camera\":{}}") == 0);
    e = tclient_wait_type(&bad, "error", T);
    SL_CHECK(error_is(e, "hello_required", "type"));
    cJSON_Delete(e);
    tclient_close(&bad);

    /* --- Origin and Host checks (DNS rebinding: a hostile name that resolves
     *     here sends its own name as Host and as Origin; both must be refused) --- */
    tclient o;
    SL_CHECK(tclient_connect(&o, h.port, "http://evil.example") != 0);
    char origin[64], hostport[64];
    snprintf(origin, sizeof origin, "http://127.0.0.1:%d", h.port);
    SL_CHECK(tclient_connect(&o, h.port, origin) == 0);
    tclient_close(&o);
    snprintf(hostport, sizeof hostport, "evil.example:%d", h.port);
    snprintf(origin, sizeof origin, "http://evil.example:%d", h.port);
    SL_CHECK_MSG(upgrade_with(h.port, hostport, origin) != 0, "rebinding pair Host+Origin %s accepted", hostport);
    SL_CHECK(upgrade_with(h.port, hostport, NULL) != 0);
    SL_CHECK(http_status_with_host(h.port, hostport) == 421);
    snprintf(hostport, sizeof hostport, "localhost:%d", h.port);
    snprintf(origin, sizeof origin, "http://localhost:%d", h.port);
    SL_CHECK(upgrade_with(h.port, hostport, origin) == 0);       /* the browser on http://localhost:PORT */
    SL_CHECK(http_status_with_host(h.port, hostport) == 200);
    snprintf(hostport, sizeof hostport, "[::1]:%d", h.port);
    SL_CHECK(upgrade_with(h.port, hostport, NULL) == 0);
    snprintf(hostport, sizeof hostport, "localhost:%d", h.port + 1); /* right name, wrong port */
    SL_CHECK(upgrade_with(h.port, hostport, NULL) != 0);
    SL_CHECK(upgrade_with(h.port, "viz.example.org", "https://viz.example.org") == 0); /* --allow-origin */
    SL_CHECK(upgrade_with(h.port, "viz.example.org", "http://evil.example") != 0);
    {   /* an Origin longer than the server's copy buffer is refused, not taken as absent */
        char long_origin[400];
        snprintf(long_origin, sizeof long_origin, "http://%0300d.example", 0);
        snprintf(hostport, sizeof hostport, "127.0.0.1:%d", h.port);
        SL_CHECK_MSG(upgrade_with(h.port, hostport, long_origin) != 0, "a %zu-byte Origin was accepted",
                     strlen(long_origin));
    }

    /* --- hello timeout (--hello-timeout 2 here): a silent connection is closed
     *     after 2 s (lws checks timeouts once a second), one that said hello is not --- */
    {
        tclient silent;
        SL_CHECK(tclient_connect(&silent, h.port, NULL) == 0);
        double t0 = sl_clock_ms();
        int rr;
        do {
            rr = tclient_next(&silent, 6000, NULL);
        } while (rr > 0);
        double waited = sl_clock_ms() - t0;
        SL_CHECK_MSG(silent.closed && waited >= 1900 && waited < 4500, "silent client closed=%d after %.0f ms",
                     silent.closed, waited);
        tclient_close(&silent);
        SL_CHECK(still_usable(&a, 6));   /* a said hello long ago and is still connected */
    }

    /* --- two clients, one session: same changes, same frame ids; control --- */
    tclient b;
    SL_CHECK(tclient_connect(&b, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&b, a.session, a.token, 999, 999) == 0);
    SL_CHECK(strcmp(cJSON_GetObjectItemCaseSensitive(b.welcome, "role")->valuestring, "viewer") == 0);
    SL_CHECK(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(b.welcome, "state"), "width")->valueint == W);
    b.auto_ack = 1;
    /* The late joiner gets the latest frame at once, without any change. */
    SL_CHECK(tclient_wait_frame(&b, 0, 0, T) == 0);
    SL_CHECK(b.last.h.frame_id == a.max_frame_id);
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":10,\"camera\":{\"orbit\":{\"azimuth\":200,\"elevation\":10,\"distance\":2.2}}}") == 0);
    st = tclient_wait_type(&b, "state", T);
    const cJSON *cs = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(st, "patch"), "camera_seq");
    SL_CHECK(cs && cs->valueint == 10);
    cJSON_Delete(st);
    SL_CHECK(tclient_wait_frame(&a, 10, 1, T) == 0);
    SL_CHECK(tclient_wait_frame(&b, 10, 1, T) == 0);
    SL_CHECK_MSG(a.last.h.frame_id == b.last.h.frame_id, "frame ids %u vs %u", a.last.h.frame_id, b.last.h.frame_id);
    SL_CHECK(a.last.h.payload_bytes == b.last.h.payload_bytes &&
             memcmp(a.last.payload, b.last.payload, a.last.h.payload_bytes) == 0);
    /* The viewer is refused until it holds control. */
    SL_CHECK(tclient_send(&b, "{\"type\":\"camera\",\"seq\":11,\"camera\":{\"orbit\":{\"azimuth\":10,\"elevation\":10,\"distance\":2}}}") == 0);
    e = tclient_wait_type(&b, "error", T);
    SL_CHECK(error_is(e, "not_controller", NULL));
    cJSON_Delete(e);
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"set\",\"params\":{}}"));
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"set\",\"stream\":{\"still_quality\":50}}"));
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"scene\",\"dataset\":\"tiny\"}"));
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"resize\",\"width\":64,\"height\":64}"));
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"load_view\",\"name\":\"front\"}"));
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"save_view\",\"name\":\"by-viewer\"}"));
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"control\",\"action\":\"release\"}"));
    SL_CHECK(refused_for_viewer(&b, "{\"type\":\"control\",\"action\":\"grant\",\"client\":1}"));

    /* --- a viewer floods control requests (100 in one TCP write): the requests
     *     merge into one pending request per requester, so the controller is
     *     never closed for a full reply queue and keeps control --- */
    {
        const char *flood[100];
        for (int i = 0; i < 100; i++)
            flood[i] = "{\"type\":\"control\",\"action\":\"request\"}";
        SL_CHECK(sl_wsclient_send_texts(b.ws, flood, 100, &b.err) == SL_OK);
        int notes = 0, wrong = 0;
        double until = sl_clock_ms() + 1500;
        while (sl_clock_ms() < until && !a.closed) {
            cJSON *j = NULL;
            if (tclient_next(&a, 100, &j) == 1 && strcmp(json_type(j), "control_request") == 0) {
                notes++;
                wrong += cJSON_GetObjectItemCaseSensitive(j, "client")->valueint != b.client_id;
            }
            cJSON_Delete(j);
        }
        SL_CHECK_MSG(!a.closed, "the controller was closed by a viewer's flood (close code %d)", a.close_code);
        SL_CHECK_MSG(notes >= 1 && notes <= 10 && !wrong, "%d control_request messages (%d wrong) for 100 merged requests",
                     notes, wrong);
        SL_CHECK(still_usable(&a, 7));
        SL_CHECK(refused_for_viewer(&b, "{\"type\":\"camera\",\"seq\":11,\"camera\":{\"orbit\":{\"azimuth\":1,\"elevation\":1,\"distance\":2}}}"));
    }
    SL_CHECK(tclient_send(&b, "{\"type\":\"control\",\"action\":\"request\"}") == 0);
    cJSON *req = tclient_wait_type(&a, "control_request", T);
    SL_CHECK(req && cJSON_GetObjectItemCaseSensitive(req, "client")->valueint == b.client_id);
    cJSON_Delete(req);
    SL_CHECK(tclient_send(&a, "{\"type\":\"control\",\"action\":\"grant\",\"client\":%d}", b.client_id) == 0);
    int granted = 0;
    for (int i = 0; i < 10 && !granted; i++) {
        st = tclient_wait_type(&b, "state", T);
        const cJSON *ctl = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(st, "patch"), "controller");
        granted = ctl && ctl->valueint == b.client_id;
        cJSON_Delete(st);
        if (!st)
            break;
    }
    SL_CHECK(granted);
    SL_CHECK(tclient_send(&b, "{\"type\":\"camera\",\"seq\":12,\"camera\":{\"orbit\":{\"azimuth\":20,\"elevation\":15,\"distance\":2}}}") == 0);
    SL_CHECK(tclient_wait_frame(&a, 12, 1, T) == 0);
    SL_CHECK(tclient_wait_frame(&b, 12, 1, T) == 0);
    SL_CHECK(a.last.h.frame_id == b.last.h.frame_id);
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":13,\"camera\":{\"orbit\":{\"azimuth\":20,\"elevation\":15,\"distance\":2}}}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "not_controller", NULL));
    cJSON_Delete(e);
    SL_CHECK(tclient_send(&b, "{\"type\":\"control\",\"action\":\"grant\",\"client\":%d}", a.client_id) == 0);
    SL_CHECK(still_usable(&b, 4));

    /* --- ack window: a client that never acks gets at most 2 frames; others keep receiving --- */
    tclient lazy;
    SL_CHECK(tclient_connect(&lazy, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&lazy, a.session, a.token, W, H) == 0);
    int a_before = a.frames;
    for (int i = 0; i < 6; i++) {
        SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":%d,\"camera\":{\"orbit\":{\"azimuth\":%d,\"elevation\":5,\"distance\":2}}}",
                              20 + i, 30 * i) == 0);
        SL_CHECK(tclient_wait_frame(&a, (uint32_t)(20 + i), 1, T) == 0);
    }
    /* Drain the lazy client for a while without acking. */
    double until = sl_clock_ms() + 1500;
    while (sl_clock_ms() < until)
        if (tclient_next(&lazy, 100, NULL) == 0)
            break;
    /* The frame at join plus one more fill the window of 2; six more renders send nothing. */
    SL_CHECK_MSG(lazy.frames == 2, "non-acking client received %d frames", lazy.frames);
    SL_CHECK_MSG(a.frames - a_before >= 6, "acking client received %d frames", a.frames - a_before);
    /* Once it acks, it receives the newest frame, not the backlog. */
    SL_CHECK(tclient_send(&lazy, "{\"type\":\"ack\",\"frame\":%u}", lazy.max_frame_id) == 0);
    SL_CHECK(tclient_wait_frame(&lazy, 25, 0, T) == 0);
    SL_CHECK(lazy.last.h.frame_id == a.max_frame_id);
    tclient_close(&lazy);

    /* --- snapshot: one lossless PNG of the current view; it must match the last
     *     still JPEG of the same state (same orientation: JPEG rows come from GL's
     *     bottom-up readback through TurboJPEG's bottom-up flag, PNG from a top-down read) --- */
    SL_CHECK(a.last.h.kind == SL_FRAME_JPEG && a.last.h.camera_seq == 25 &&
             !(a.last.h.flags & SL_FRAME_FLAG_INTERACTIVE));
    sl_image still_jpeg = tclient_decode_last(&a);
    SL_CHECK(tclient_send(&a, "{\"type\":\"snapshot\"}") == 0);
    int got_png = 0;
    double sdl = sl_clock_ms() + T;
    while (!got_png && sl_clock_ms() < sdl) {
        if (tclient_next(&a, T, NULL) == 2 && a.last.h.kind == SL_FRAME_PNG)
            got_png = 1;
    }
    SL_CHECK(got_png);
    if (got_png) {
        char path[400];
        snprintf(path, sizeof path, "%s/snap.png", h.dir);
        FILE *f = fopen(path, "wb");
        SL_CHECK(f && fwrite(a.last.payload, 1, a.last.h.payload_bytes, f) == a.last.h.payload_bytes);
        if (f)
            fclose(f);
        sl_image png = {0};
        sl_err err;
        SL_CHECK(sl_png_read(path, &png, &err) == SL_OK && png.width == W && png.height == H);
        SL_CHECK(harness_foreground_fraction(&png) > 0.01);
        double dj = harness_mean_diff(&png, &still_jpeg);
        SL_CHECK_MSG(dj >= 0 && dj < 4.0, "PNG snapshot vs still JPEG mean abs difference %.3f (bound 4)", dj);
        /* The same comparison against the JPEG flipped upside down must be clearly worse. */
        sl_image flipped = {.width = still_jpeg.width, .height = still_jpeg.height,
                            .rgba = malloc((size_t)still_jpeg.width * (size_t)still_jpeg.height * 4)};
        if (flipped.rgba && still_jpeg.rgba) {
            size_t row = (size_t)still_jpeg.width * 4;
            for (int y = 0; y < still_jpeg.height; y++)
                memcpy(flipped.rgba + row * (size_t)y, still_jpeg.rgba + row * (size_t)(still_jpeg.height - 1 - y), row);
            double df = harness_mean_diff(&png, &flipped);
            SL_CHECK_MSG(df > 2 * dj, "flipped difference %.3f vs %.3f", df, dj);
        }
        sl_image_deinit(&flipped);
        sl_image_deinit(&png);
    }

    /* --- save / list / load views --- */
    SL_CHECK(tclient_send(&a, "{\"type\":\"save_view\",\"name\":\"front\"}") == 0);
    cJSON *sv = tclient_wait_type(&a, "view_saved", T);
    SL_CHECK(sv != NULL);
    cJSON_Delete(sv);
    SL_CHECK(tclient_send(&a, "{\"type\":\"list_views\"}") == 0);
    cJSON *vl = tclient_wait_type(&a, "views", T);
    const cJSON *v0 = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(vl, "views"), 0);
    SL_CHECK(v0 && strcmp(cJSON_GetObjectItemCaseSensitive(v0, "name")->valuestring, "front") == 0);
    cJSON_Delete(vl);
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":40,\"camera\":{\"orbit\":{\"azimuth\":77,\"elevation\":7,\"distance\":3}}}") == 0);
    SL_CHECK(tclient_wait_frame(&a, 40, 1, T) == 0);
    SL_CHECK(tclient_send(&a, "{\"type\":\"load_view\",\"name\":\"front\"}") == 0);
    int restored = 0;
    for (int i = 0; i < 10 && !restored; i++) {
        st = tclient_wait_type(&a, "state", T);
        const cJSON *cam = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(st, "patch"), "camera");
        const cJSON *az = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(cam, "orbit"), "azimuth");
        restored = az && fabs(az->valuedouble - 150.0) < 1e-9; /* the last camera before save: 30*5 */
        cJSON_Delete(st);
        if (!st)
            break;
    }
    SL_CHECK(restored);
    SL_CHECK(tclient_send(&a, "{\"type\":\"load_view\",\"name\":\"nope\"}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "not_found", "name"));
    cJSON_Delete(e);
    /* The catalog holds at most 256 views (PROTOCOL.md): new names fail with
     * `limit` beyond that, replacing an existing one still works. One at a
     * time, since pipelining 256 replies would overflow our own reply ring. */
    {
        int saved = 1; /* "front" */
        cJSON *refusal = NULL;
        for (int i = 0; i < 300 && !refusal; i++) {
            SL_CHECK(tclient_send(&a, "{\"type\":\"save_view\",\"name\":\"cap-%d\"}", i) == 0);
            cJSON *m = wait_reply(&a, "view_saved");
            if (!m)
                break;
            if (strcmp(json_type(m), "error") == 0)
                refusal = m;
            else
                saved++, cJSON_Delete(m);
        }
        SL_CHECK_MSG(saved == 256, "%d views saved before the limit (256)", saved);
        SL_CHECK(error_is(refusal, "limit", "name"));
        cJSON_Delete(refusal);
        SL_CHECK(tclient_send(&a, "{\"type\":\"save_view\",\"name\":\"cap-3\"}") == 0);
        cJSON *m = wait_reply(&a, "view_saved");
        SL_CHECK(m && strcmp(json_type(m), "view_saved") == 0);
        cJSON_Delete(m);
    }

    /* --- list_datasets and scene switch --- */
    SL_CHECK(tclient_send(&a, "{\"type\":\"list_datasets\"}") == 0);
    cJSON *dl = tclient_wait_type(&a, "datasets", T);
    const cJSON *dsj;
    int has_tiny_bounds = 0;
    cJSON_ArrayForEach(dsj, cJSON_GetObjectItemCaseSensitive(dl, "datasets")) {
        if (strcmp(cJSON_GetObjectItemCaseSensitive(dsj, "name")->valuestring, "tiny") == 0)
            has_tiny_bounds = cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(dsj, "bounds")) == 2;
    }
    SL_CHECK(has_tiny_bounds);
    cJSON_Delete(dl);
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"no-such-dataset\"}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "not_found", "dataset"));
    cJSON_Delete(e);
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"technique\":\"no-such-technique\"}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_is(e, "not_found", "technique"));
    cJSON_Delete(e);

    /* --- scene switches: a file dataset added while the server runs, another technique,
     *     and a dataset whose file vanished (render_failed reaches every client) --- */
    {
        char objpath[512], datadir[400];
        snprintf(datadir, sizeof datadir, "%s/data", h.dir);
        snprintf(objpath, sizeof objpath, "%s/lines.obj", datadir);
        FILE *obj = fopen(objpath, "w");
        SL_CHECK(obj != NULL);
        if (obj) {
            fputs("v 0 0 0\nv 1 2 3\nv 0.5 1 0\nv 1 0 3\nl 1 2\nl 3 4\n", obj);
            fclose(obj);
        }
        char *add[] = {h.exe, "catalog", "add", objpath, "--db", h.db, "--data-dir", datadir, NULL};
        SL_CHECK(harness_run_wait(add) == 0);
        /* Clients learn that it is a file, never the server's path to it. */
        SL_CHECK(tclient_send(&a, "{\"type\":\"list_datasets\"}") == 0);
        cJSON *fl = tclient_wait_type(&a, "datasets", T);
        int file_entry = 0, paths = 0;
        cJSON_ArrayForEach(dsj, cJSON_GetObjectItemCaseSensitive(fl, "datasets")) {
            const cJSON *src = cJSON_GetObjectItemCaseSensitive(dsj, "source");
            paths += cJSON_GetObjectItemCaseSensitive(dsj, "path") != NULL;
            file_entry |= strcmp(cJSON_GetObjectItemCaseSensitive(dsj, "name")->valuestring, "lines.obj") == 0 &&
                          cJSON_IsString(src) && strcmp(src->valuestring, "file") == 0;
        }
        char *fl_text = fl ? cJSON_PrintUnformatted(fl) : NULL;
        SL_CHECK_MSG(file_entry && paths == 0 && fl_text && !strstr(fl_text, h.dir), "datasets list leaks paths: %.300s",
                     fl_text ? fl_text : "(none)");
        free(fl_text);
        cJSON_Delete(fl);
        SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"lines.obj\"}") == 0);
        int saw_dataset = 0, saw_bounds = 0;
        uint32_t version = 0;
        double deadline = sl_clock_ms() + T;
        while ((!saw_dataset || !saw_bounds) && sl_clock_ms() < deadline) {
            cJSON *m = tclient_wait_type(&a, "state", T);
            if (!m)
                break;
            const cJSON *patch = cJSON_GetObjectItemCaseSensitive(m, "patch");
            const cJSON *dsn = cJSON_GetObjectItemCaseSensitive(patch, "dataset");
            const cJSON *bounds = cJSON_GetObjectItemCaseSensitive(patch, "bounds");
            if (cJSON_IsString(dsn) && strcmp(dsn->valuestring, "lines.obj") == 0) {
                saw_dataset = 1;
                version = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
            }
            if (saw_dataset && cJSON_GetArraySize(bounds) == 2) {
                const double want[2][3] = {{0, 0, 0}, {1, 2, 3}};
                int ok = 1;
                for (int i = 0; i < 2; i++)
                    for (int k = 0; k < 3; k++)
                        ok = ok && fabs(cJSON_GetArrayItem(cJSON_GetArrayItem(bounds, i), k)->valuedouble - want[i][k]) < 1e-5;
                SL_CHECK_MSG(ok, "bounds of lines.obj");
                saw_bounds = 1;
            }
            cJSON_Delete(m);
        }
        SL_CHECK(saw_dataset && saw_bounds);
        SL_CHECK(tclient_wait_version(&a, version, T) == 0);

        /* Another technique that renders line sets, picked from the schema list (never by name). */
        const char *current = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(a.welcome, "state"),
                                                               "technique")->valuestring;
        const char *other = NULL;
        const cJSON *t;
        cJSON_ArrayForEach(t, cJSON_GetObjectItemCaseSensitive(a.welcome, "techniques")) {
            const cJSON *k;
            int lines = 0;
            cJSON_ArrayForEach(k, cJSON_GetObjectItemCaseSensitive(t, "dataset_kinds"))
                lines |= cJSON_IsString(k) && strcmp(k->valuestring, "lines") == 0;
            const char *name = cJSON_GetObjectItemCaseSensitive(t, "name")->valuestring;
            if (lines && strcmp(name, current) != 0 && !other)
                other = name;
        }
        if (other) {
            uint32_t before_id = a.max_frame_id;
            SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"technique\":\"%s\"}", other) == 0);
            uint32_t vo = wait_patch(&a, "technique", other);
            SL_CHECK_MSG(vo > 0 && tclient_wait_version(&a, vo, T) == 0 && a.max_frame_id > before_id,
                         "a frame from technique %s", other);
            SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"technique\":\"%s\"}", current) == 0);
        }

        /* The file vanishes; switching away (rendered) and back makes the render thread reload and fail:
         * load_failed reaches every client of the session, without the server's path. */
        SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"tiny\"}") == 0);
        uint32_t vt = wait_patch(&a, "dataset", "tiny");
        SL_CHECK(vt > 0 && tclient_wait_version(&a, vt, T) == 0);
        SL_CHECK(unlink(objpath) == 0);
        SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"lines.obj\"}") == 0);
        e = tclient_wait_type(&a, "error", T);
        SL_CHECK(error_is(e, "load_failed", "dataset"));
        const cJSON *em = cJSON_GetObjectItemCaseSensitive(e, "message");
        SL_CHECK_MSG(cJSON_IsString(em) && strstr(em->valuestring, "lines.obj") && !strstr(em->valuestring, h.dir),
                     "load_failed message %s", cJSON_IsString(em) ? em->valuestring : "(none)");
        cJSON_Delete(e);
        e = tclient_wait_type(&b, "error", T);
        SL_CHECK(error_is(e, "load_failed", "dataset"));
        cJSON_Delete(e);
        SL_CHECK(still_usable(&a, 5));
        SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"tiny\"}") == 0);
        vt = wait_patch(&a, "dataset", "tiny");
        SL_CHECK(vt > 0 && tclient_wait_version(&a, vt, T) == 0);
    }

    /* --- /healthz and /metrics --- */
    char body[16384];
    SL_CHECK(http_get(h.port, "/healthz", body, sizeof body) == 200 && strstr(body, "\"status\":\"ok\""));
    SL_CHECK(http_get(h.port, "/metrics", body, sizeof body) == 200);
    SL_CHECK(metric(body, "sightline_frames_rendered_total") >= 5);
    SL_CHECK(metric(body, "sightline_clients") >= 2);
    SL_CHECK(metric(body, "sightline_sessions") >= 1);
    SL_CHECK(strstr(body, "sightline_encode_ms_bucket{le=\"+Inf\"}") != NULL);
    SL_CHECK(http_get(h.port, "/no-such-file", body, sizeof body) == 404);

    /* --- two new sessions on the same dataset share one loaded copy: two
     *     datasets handed out, at most one of them loaded --- */
    {
        SL_CHECK(http_get(h.port, "/metrics", body, sizeof body) == 200);
        double loads0 = metric(body, "sightline_dataset_loads_total");
        double hits0 = metric(body, "sightline_dataset_cache_hits_total");
        SL_CHECK(loads0 >= 1 && hits0 >= 0);
        tclient s1, s2;
        SL_CHECK(tclient_connect(&s1, h.port, NULL) == 0 && tclient_hello(&s1, NULL, NULL, 32, 32) == 0);
        s1.auto_ack = 1;
        SL_CHECK(tclient_wait_frame(&s1, 0, 0, T) == 0);
        SL_CHECK(tclient_connect(&s2, h.port, NULL) == 0 && tclient_hello(&s2, NULL, NULL, 32, 32) == 0);
        s2.auto_ack = 1;
        SL_CHECK(tclient_wait_frame(&s2, 0, 0, T) == 0);
        SL_CHECK(strcmp(s1.session, s2.session) != 0);
        SL_CHECK(http_get(h.port, "/metrics", body, sizeof body) == 200);
        double loads1 = metric(body, "sightline_dataset_loads_total");
        double hits1 = metric(body, "sightline_dataset_cache_hits_total");
        SL_CHECK_MSG(loads1 + hits1 - loads0 - hits0 == 2 && loads1 - loads0 <= 1,
                     "loads %g -> %g, cache hits %g -> %g", loads0, loads1, hits0, hits1);
        tclient_close(&s1);
        tclient_close(&s2);
    }

    /* --- a late joiner is not told about a render error from before it joined
     *     (the vanished file above failed, then the session rendered again) --- */
    tclient late;
    SL_CHECK(tclient_connect(&late, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&late, a.session, a.token, W, H) == 0);
    late.auto_ack = 1;
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":80,\"camera\":{\"orbit\":{\"azimuth\":33,\"elevation\":3,\"distance\":2}}}") == 0);
    {
        int errors = 0;
        int got = wait_still_counting_errors(&late, 80, &errors);
        SL_CHECK_MSG(got && errors == 0, "late joiner: frame %d, stale errors %d", got, errors);
    }

    /* --- control release, then the controller leaving: control passes to the
     *     longest-connected remaining client each time --- */
    SL_CHECK(tclient_send(&a, "{\"type\":\"control\",\"action\":\"release\"}") == 0);
    SL_CHECK_MSG(wait_controller(&late) == b.client_id, "after release control went elsewhere than b");
    SL_CHECK(wait_controller(&a) == b.client_id);
    SL_CHECK(refused_for_viewer(&a, "{\"type\":\"camera\",\"seq\":81,\"camera\":{\"orbit\":{\"azimuth\":1,\"elevation\":1,\"distance\":2}}}"));
    SL_CHECK(tclient_send(&b, "{\"type\":\"camera\",\"seq\":82,\"camera\":{\"orbit\":{\"azimuth\":44,\"elevation\":4,\"distance\":2}}}") == 0);
    SL_CHECK(tclient_wait_frame(&late, 82, 1, T) == 0);
    tclient_close(&b);
    SL_CHECK_MSG(wait_controller(&late) == a.client_id, "after the controller left, control did not pass to a");
    SL_CHECK(wait_controller(&a) == a.client_id);
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":83,\"camera\":{\"orbit\":{\"azimuth\":55,\"elevation\":5,\"distance\":2}}}") == 0);
    SL_CHECK(tclient_wait_frame(&late, 83, 1, T) == 0);
    tclient_close(&late);

    /* --- grace period: rejoin after all clients left, then expiry --- */
    char sid[64], tok[64];
    snprintf(sid, sizeof sid, "%s", a.session);
    snprintf(tok, sizeof tok, "%s", a.token);
    uint32_t last_id = a.max_frame_id;
    tclient_close(&a);
    tclient_close(&b);
    usleep(300000);
    tclient re;
    SL_CHECK(tclient_connect(&re, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&re, sid, tok, W, H) == 0);
    SL_CHECK(tclient_wait_frame(&re, 0, 0, T) == 0 && re.last.h.frame_id >= last_id);
    tclient_close(&re);
    usleep(4500000); /* grace 2 s + sweep period 1 s + margin */
    SL_CHECK(tclient_connect(&re, h.port, NULL) == 0);
    SL_CHECK(tclient_send(&re, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%s\"}", sid, tok) == 0);
    e = tclient_wait_type(&re, "error", T);
    SL_CHECK(error_is(e, "unknown_session", "session"));
    cJSON_Delete(e);
    tclient_close(&re);

    sl_image_deinit(&still_jpeg);
    sl_image_deinit(&first);
    sl_image_deinit(&second);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
