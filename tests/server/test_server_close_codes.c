/* test_server_close_codes.c — a link that ends says why (proto/PROTOCOL.md, "Close codes").
 *
 * A raw client (sl_server_harness.h) does what an attacker would and reads
 * the close frame each time: a binary frame ends the link with 1003, text
 * that is not UTF-8 with 1007, a message over the size limit (before hello
 * and a 4 MB one after) with 1009, a request before hello with 1008
 * "hello_required", the pending budget (--max-pending 2) and the hello
 * timeout (a second server, --hello-timeout 1) with 1008 naming the limit,
 * and a flood of pings nobody reads with 1008 "reply budget". What must not
 * end the link: 5000 cameras in one burst (the link stays open, the newest
 * camera wins: a still frame carries seq 5000) and 50 bad `set`s (radius -1
 * and 1e999) in one burst (errors that account for all 50, merged with a
 * `repeated` count, then a ping gets its pong). No check measures time.
 */
#include "sl_server_harness.h"
#include "sl_test.h"

#define W 64
#define H 48
#define T 20000   /* per step (ASan + llvmpipe on 2 busy cores); never a measured limit */
#define REPLY_BUDGET 32 /* the server's reply budget (SL_CLIENT_MAX_TEXT) */

static int reason_has(const tclient *c, const char *word)
{
    return strstr(c->close_reason, word) != NULL;
}

/* A client past hello on a session of its own; 0 on success. */
static int hello_client(tclient *c, const harness *h)
{
    if (tclient_connect(c, h->port, NULL) != 0 || tclient_hello(c, NULL, NULL, W, H) != 0) {
        fprintf(stderr, "connect/hello failed: %s\n", c->err.message);
        return -1;
    }
    return 0;
}

static void binary_frame(const harness *h)
{
    tclient c;
    SL_CHECK(hello_client(&c, h) == 0);
    const uint8_t bytes[] = {1, 2, 3, 4};
    SL_CHECK(sl_wsclient_send_frame(c.ws, 2, bytes, sizeof bytes, &c.err) == SL_OK);
    SL_CHECK_MSG(tclient_wait_close(&c, T) == 0 && c.close_code == 1003 && reason_has(&c, "binary"),
                 "binary frame: close %d \"%s\"", c.close_code, c.close_reason);
    tclient_close(&c);
}

static void not_utf8(const harness *h)
{
    tclient c;
    SL_CHECK(hello_client(&c, h) == 0);
    const char bad[] = "{\"type\":\"ping\",\"seq\":1,\"x\":\"\xc3\x28\"}";
    SL_CHECK(sl_wsclient_send_text(c.ws, bad, sizeof bad - 1, &c.err) == SL_OK);
    SL_CHECK_MSG(tclient_wait_close(&c, T) == 0 && c.close_code == 1007, "invalid UTF-8: close %d \"%s\"",
                 c.close_code, c.close_reason);
    tclient_close(&c);
}

/* A text message of n bytes: a JSON object padded with spaces. */
static char *padded_message(size_t n)
{
    char *m = malloc(n);
    if (m) {
        memset(m, ' ', n);
        m[0] = '{';
        m[n - 1] = '}';
    }
    return m;
}

static void oversize(const harness *h)
{
    tclient c;
    SL_CHECK(tclient_connect(&c, h->port, NULL) == 0);
    size_t n = SL_PROTO_MAX_HELLO + 100;
    char *m = padded_message(n);
    SL_CHECK(m && sl_wsclient_send_text(c.ws, m, n, &c.err) == SL_OK);
    free(m);
    SL_CHECK_MSG(tclient_wait_close(&c, T) == 0 && c.close_code == 1009 && reason_has(&c, "4096"),
                 "before hello: close %d \"%s\"", c.close_code, c.close_reason);
    tclient_close(&c);

    SL_CHECK(hello_client(&c, h) == 0);
    n = 4u << 20;
    m = padded_message(n);
    SL_CHECK(m != NULL);
    /* The server may close before it has read all 4 MB, so the send may fail; the close frame came first. */
    if (m)
        (void)sl_wsclient_send_text(c.ws, m, n, &c.err);
    free(m);
    SL_CHECK_MSG(tclient_wait_close(&c, T) == 0 && c.close_code == 1009 && reason_has(&c, "65536"),
                 "4 MB after hello: close %d \"%s\"", c.close_code, c.close_reason);
    tclient_close(&c);
}

static void before_hello(const harness *h)
{
    tclient c;
    SL_CHECK(tclient_connect(&c, h->port, NULL) == 0);
    SL_CHECK(tclient_send(&c, "{\"type\":\"camera\",\"seq\":1,\"camera\":{}}") == 0);
    cJSON *e = tclient_wait_type(&c, "error", T);
    SL_CHECK(e && strcmp(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(e, "code")), "hello_required") == 0);
    cJSON_Delete(e);
    SL_CHECK_MSG(tclient_wait_close(&c, T) == 0 && c.close_code == 1008 && reason_has(&c, "hello_required"),
                 "camera before hello: close %d \"%s\"", c.close_code, c.close_reason);
    tclient_close(&c);
}

/* --max-pending 2: the third connection without hello evicts the first. */
static void pending_budget(const harness *h)
{
    tclient p[3];
    /* tclient_connect returns after the 101, which the server writes in the
     * pass that establishes the connection: the three are pending in order. */
    for (int i = 0; i < 3; i++)
        SL_CHECK(tclient_connect(&p[i], h->port, NULL) == 0);
    SL_CHECK_MSG(tclient_wait_close(&p[0], T) == 0 && p[0].close_code == 1008 && reason_has(&p[0], "max-pending"),
                 "evicted pending connection: close %d \"%s\"", p[0].close_code, p[0].close_reason);
    for (int i = 0; i < 3; i++)
        tclient_close(&p[i]);
}

static void hello_timeout(void)
{
    harness h2;
    const char *extra[] = {"--hello-timeout", "1", NULL};
    if (harness_start(&h2, extra) != 0) {
        SL_CHECK_MSG(0, "second server (--hello-timeout 1) did not start");
        return;
    }
    tclient c;
    SL_CHECK(tclient_connect(&c, h2.port, NULL) == 0);
    SL_CHECK_MSG(tclient_wait_close(&c, T) == 0 && c.close_code == 1008 && reason_has(&c, "hello-timeout"),
                 "silent connection: close %d \"%s\"", c.close_code, c.close_reason);
    tclient_close(&c);
    int status = harness_stop(&h2);
    SL_CHECK_MSG(status == 0, "second server exit status %d", status);
}

/* 5000 cameras in one write: coalesced, the link stays open, seq 5000 renders. */
static void camera_burst(const harness *h)
{
    tclient c;
    SL_CHECK(hello_client(&c, h) == 0);
    c.auto_ack = 1;
    enum { N = 5000 };
    char **texts = calloc(N, sizeof *texts);
    SL_CHECK(texts != NULL);
    if (!texts)
        return;
    for (int i = 0; i < N; i++) {
        char buf[200];
        snprintf(buf, sizeof buf,
                 "{\"type\":\"camera\",\"seq\":%d,\"camera\":{\"orbit\":{\"azimuth\":%d,\"elevation\":5,\"distance\":2}}}",
                 i + 1, i % 360);
        texts[i] = strdup(buf);
    }
    SL_CHECK(sl_wsclient_send_texts(c.ws, (const char *const *)texts, N, &c.err) == SL_OK);
    for (int i = 0; i < N; i++)
        free(texts[i]);
    free(texts);
    int errors = 0, seen = 0;
    double deadline = sl_clock_ms() + 3 * T;
    while (!seen && !c.closed && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&c, T, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0) {
            char *t = cJSON_PrintUnformatted(j);
            fprintf(stderr, "camera burst: %s\n", t ? t : "?");
            free(t);
            errors++;
        }
        cJSON_Delete(j);
        if (r == 2 && c.last.h.kind == SL_FRAME_JPEG && c.last.h.camera_seq >= N &&
            !(c.last.h.flags & SL_FRAME_FLAG_INTERACTIVE))
            seen = 1;
        if (r < 0 && c.closed)
            break;
    }
    SL_CHECK_MSG(seen && c.last.h.camera_seq == N, "still frame after the burst: seen %d, camera_seq %u", seen,
                 c.last.h.camera_seq);
    SL_CHECK_MSG(!c.closed, "the burst closed the link: %d \"%s\"", c.close_code, c.close_reason);
    SL_CHECK(errors == 0);
    SL_CHECK(tclient_ping(&c, 77, T));
    tclient_close(&c);
}

/* 50 bad sets in one write: errors that account for all 50, the link stays open. */
static void bad_sets(const harness *h)
{
    tclient c;
    SL_CHECK(hello_client(&c, h) == 0);
    c.auto_ack = 1;
    enum { N = 50 };
    const char *texts[N];
    for (int i = 0; i < N; i++)
        texts[i] = i % 2 ? "{\"type\":\"set\",\"params\":{\"radius\":1e999}}"
                         : "{\"type\":\"set\",\"params\":{\"radius\":-1}}";
    SL_CHECK(sl_wsclient_send_texts(c.ws, texts, N, &c.err) == SL_OK);
    SL_CHECK(tclient_send(&c, "{\"type\":\"ping\",\"seq\":88}") == 0);
    int errors = 0, counted = 0, pong = 0;
    double deadline = sl_clock_ms() + 3 * T;
    while (!pong && !c.closed && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&c, T, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0) {
            const cJSON *rep = cJSON_GetObjectItemCaseSensitive(j, "repeated");
            errors++;
            counted += 1 + (cJSON_IsNumber(rep) ? rep->valueint : 0);
        }
        if (r == 1 && strcmp(json_type(j), "pong") == 0)
            pong = cJSON_GetObjectItemCaseSensitive(j, "seq")->valueint == 88;
        cJSON_Delete(j);
        if (r < 0 && c.closed)
            break;
    }
    printf("50 bad sets: %d error message(s) accounting for %d, pong %d\n", errors, counted, pong);
    SL_CHECK_MSG(!c.closed, "50 bad sets closed the link: %d \"%s\"", c.close_code, c.close_reason);
    SL_CHECK_MSG(pong && errors >= 1 && counted == N, "pong %d, %d error messages for %d of %d bad sets", pong,
                 errors, counted, N);
    SL_CHECK(tclient_ping(&c, 89, T));
    tclient_close(&c);
}

/* 1000 pings in one write and nothing read: the reply budget ends the link, and says so. */
static void reply_budget(const harness *h)
{
    tclient c;
    SL_CHECK(hello_client(&c, h) == 0);
    enum { N = 1000 };
    const char *texts[N];
    for (int i = 0; i < N; i++)
        texts[i] = "{\"type\":\"ping\",\"seq\":1}";
    SL_CHECK(sl_wsclient_send_texts(c.ws, texts, N, &c.err) == SL_OK);
    int pongs = 0;
    while (!c.closed) {
        cJSON *j = NULL;
        int r = tclient_next(&c, T, &j);
        pongs += r == 1 && strcmp(json_type(j), "pong") == 0;
        cJSON_Delete(j);
        if (r < 0)
            break;
    }
    printf("1000 pings unread: %d pongs, then close %d \"%s\"\n", pongs, c.close_code, c.close_reason);
    SL_CHECK(pongs <= REPLY_BUDGET);
    SL_CHECK_MSG(tclient_wait_close(&c, T) == 0 && c.close_code == 1008 && reason_has(&c, "reply budget"),
                 "ping flood: close %d \"%s\"", c.close_code, c.close_reason);
    tclient_close(&c);
}

int main(void)
{
    harness h;
    const char *extra[] = {"--max-pending", "2", NULL};
    HARNESS_START_OR_END(h, extra);
    binary_frame(&h);
    not_utf8(&h);
    oversize(&h);
    before_hello(&h);
    camera_burst(&h);
    bad_sets(&h);
    reply_budget(&h);
    pending_budget(&h);
    /* The server survived all of it and still serves a new client. */
    tclient c;
    SL_CHECK(hello_client(&c, &h) == 0);
    SL_CHECK(tclient_ping(&c, 5, T));
    tclient_close(&c);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    hello_timeout();
    SL_TEST_END();
}
