/* test_server_limits.c — --max-sessions and the controller's resize and quality settings.
 *
 * The server runs with --max-sessions 2. Checks: with two sessions that
 * have clients, a third hello gets session_failed naming --max-sessions and
 * a close; once the second session has no client, a new session evicts it
 * (joining it then gives unknown_session) while the first, which has a
 * client, keeps rendering; /healthz counts 2 sessions. The controller's
 * resize reaches its viewer as a state patch and the next still frame of
 * both is the new size (header and decoded JPEG); out-of-range sizes give
 * bad_field naming width or height. still_quality / still_subsampling show
 * in the still frames' headers and a lower quality gives fewer bytes for
 * the same view; interactive_quality / interactive_subsampling (fixed scale
 * 0.5) show in the interactive frames of a drag, and the still after it
 * keeps the still settings. Exit status 0 required.
 */
#include "image/sl_image.h"
#include "sl_server_harness.h"
#include "sl_test.h"

#define W 64
#define H 48
#define T 20000

static int error_code_is(cJSON *j, const char *code, const char *field)
{
    const char *c = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "code"));
    const char *f = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "field"));
    int ok = c && strcmp(c, code) == 0 && (!field || (f && strcmp(f, field) == 0));
    if (!ok) {
        char *t = j ? cJSON_PrintUnformatted(j) : NULL;
        fprintf(stderr, "expected error %s/%s, got %s\n", code, field ? field : "*", t ? t : "(nothing)");
        free(t);
    }
    return ok;
}

/* Sends a one-off camera change and waits for its still frame. */
static int still_at(tclient *c, uint32_t seq, double azimuth)
{
    if (tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"camera\":{\"orbit\":{\"azimuth\":%.1f,\"elevation\":15,"
                        "\"distance\":2.5}}}", seq, azimuth))
        return -1;
    return tclient_wait_frame(c, seq, 1, T);
}

/* Waits for a state patch with key; returns its version, 0 on timeout; *patch_out (optional) the patch copy. */
static uint32_t wait_patch_key(tclient *c, const char *key, cJSON **patch_out)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *m = tclient_wait_type(c, "state", T);
        if (!m)
            return 0;
        const cJSON *patch = cJSON_GetObjectItemCaseSensitive(m, "patch");
        if (cJSON_GetObjectItemCaseSensitive(patch, key)) {
            uint32_t v = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
            if (patch_out)
                *patch_out = cJSON_Duplicate(patch, 1);
            cJSON_Delete(m);
            return v;
        }
        cJSON_Delete(m);
    }
    return 0;
}

static void max_sessions(const harness *h)
{
    tclient c1, c2, c3, join;
    SL_CHECK(tclient_connect(&c1, h->port, NULL) == 0 && tclient_hello(&c1, NULL, NULL, W, H) == 0);
    c1.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&c1, 0, 1, T) == 0);
    SL_CHECK(tclient_connect(&c2, h->port, NULL) == 0 && tclient_hello(&c2, NULL, NULL, W, H) == 0);
    c2.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&c2, 0, 1, T) == 0);
    char s2[64], t2[64];
    snprintf(s2, sizeof s2, "%s", c2.session);
    snprintf(t2, sizeof t2, "%s", c2.token);

    /* Both sessions have a client: nothing can be evicted. */
    SL_CHECK(tclient_connect(&c3, h->port, NULL) == 0);
    SL_CHECK(tclient_send(&c3, "{\"type\":\"hello\",\"version\":1,\"width\":%d,\"height\":%d}", W, H) == 0);
    cJSON *e = tclient_wait_type(&c3, "error", T);
    const char *msg = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(e, "message"));
    SL_CHECK(error_code_is(e, "session_failed", NULL));
    SL_CHECK_MSG(msg && strstr(msg, "--max-sessions"), "session_failed message: %s", msg ? msg : "(none)");
    cJSON_Delete(e);
    int r;
    do
        r = tclient_next(&c3, T, NULL);
    while (r > 0);
    SL_CHECK_MSG(c3.closed, "the refused hello was not closed");
    tclient_close(&c3);
    SL_CHECK(harness_healthz_number(h->port, "sessions") == 2);

    /* The second session loses its client: the next new session takes its place. */
    tclient_close(&c2);
    int ok = 0;
    for (int i = 0; i < 50 && !ok; i++) { /* the server notices the close asynchronously */
        SL_CHECK(tclient_connect(&c3, h->port, NULL) == 0);
        ok = tclient_hello(&c3, NULL, NULL, W, H) == 0;
        if (!ok) {
            tclient_close(&c3);
            usleep(100000);
        }
    }
    SL_CHECK_MSG(ok, "no new session after the second lost its client");
    c3.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&c3, 0, 1, T) == 0);
    SL_CHECK(strcmp(c3.session, s2) != 0 && strcmp(c3.session, c1.session) != 0);
    SL_CHECK(harness_healthz_number(h->port, "sessions") == 2);
    SL_CHECK(tclient_connect(&join, h->port, NULL) == 0);
    SL_CHECK(tclient_send(&join, "{\"type\":\"hello\",\"version\":1,\"session\":\"%s\",\"token\":\"%s\"}", s2, t2) == 0);
    e = tclient_wait_type(&join, "error", T);
    SL_CHECK_MSG(error_code_is(e, "unknown_session", "session"), "the evicted session can still be joined");
    cJSON_Delete(e);
    tclient_close(&join);

    /* The first session was kept and renders. */
    SL_CHECK(still_at(&c1, 1, 80) == 0);
    tclient_close(&c1);
    tclient_close(&c3);
}

static void resize_and_quality(const harness *h)
{
    tclient ctl, view;
    SL_CHECK(tclient_connect(&ctl, h->port, NULL) == 0 && tclient_hello(&ctl, NULL, NULL, W, H) == 0);
    ctl.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&ctl, 0, 1, T) == 0);
    SL_CHECK(tclient_connect(&view, h->port, NULL) == 0 && tclient_hello(&view, ctl.session, ctl.token, W, H) == 0);
    view.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&view, 0, 0, T) == 0);

    /* --- resize: out of range refused, naming the field; a valid one reaches both --- */
    SL_CHECK(tclient_send(&ctl, "{\"type\":\"resize\",\"width\":0,\"height\":60}") == 0);
    cJSON *e = tclient_wait_type(&ctl, "error", T);
    SL_CHECK(error_code_is(e, "bad_field", "width"));
    cJSON_Delete(e);
    SL_CHECK(tclient_send(&ctl, "{\"type\":\"resize\",\"width\":80,\"height\":4097}") == 0);
    e = tclient_wait_type(&ctl, "error", T);
    SL_CHECK(error_code_is(e, "bad_field", "height"));
    cJSON_Delete(e);
    SL_CHECK(tclient_send(&ctl, "{\"type\":\"resize\",\"width\":80,\"height\":60}") == 0);
    cJSON *patch = NULL;
    uint32_t v = wait_patch_key(&view, "width", &patch);
    SL_CHECK(v > 0);
    SL_CHECK(cJSON_GetObjectItemCaseSensitive(patch, "width") &&
             cJSON_GetObjectItemCaseSensitive(patch, "width")->valueint == 80 &&
             cJSON_GetObjectItemCaseSensitive(patch, "height") &&
             cJSON_GetObjectItemCaseSensitive(patch, "height")->valueint == 60);
    cJSON_Delete(patch);
    SL_CHECK(tclient_wait_version(&ctl, v, T) == 0 && tclient_wait_version(&view, v, T) == 0);
    SL_CHECK_MSG(ctl.last.h.width == 80 && ctl.last.h.height == 60 && view.last.h.width == 80 &&
                 view.last.h.height == 60, "frames after resize: %ux%u and %ux%u", ctl.last.h.width,
                 ctl.last.h.height, view.last.h.width, view.last.h.height);
    sl_image img = {0};
    sl_err err;
    SL_CHECK(sl_jpeg_decode(view.last.payload, view.last.h.payload_bytes, &img, &err) == SL_OK && img.width == 80 &&
             img.height == 60);
    sl_image_deinit(&img);

    /* --- still quality and subsampling: in the header, and in the bytes --- */
    SL_CHECK(tclient_send(&ctl, "{\"type\":\"set\",\"stream\":{\"still_quality\":95,\"still_subsampling\":\"444\"}}") == 0);
    SL_CHECK(still_at(&ctl, 10, 45) == 0);
    SL_CHECK_MSG(ctl.last.h.quality == 95 && ctl.last.h.subsampling == 0, "still q%u sub%u, want q95 4:4:4",
                 ctl.last.h.quality, ctl.last.h.subsampling);
    uint32_t bytes_q95 = ctl.last.h.payload_bytes;
    SL_CHECK(tclient_send(&ctl, "{\"type\":\"set\",\"stream\":{\"still_quality\":20,\"still_subsampling\":\"420\"}}") == 0);
    SL_CHECK(still_at(&ctl, 11, 45) == 0);  /* the same view as seq 10 */
    SL_CHECK_MSG(ctl.last.h.quality == 20 && ctl.last.h.subsampling == 1, "still q%u sub%u, want q20 4:2:0",
                 ctl.last.h.quality, ctl.last.h.subsampling);
    SL_CHECK_MSG(ctl.last.h.payload_bytes < bytes_q95, "q20 4:2:0 frame %u bytes, q95 4:4:4 %u bytes",
                 ctl.last.h.payload_bytes, bytes_q95);
    SL_CHECK(tclient_wait_frame(&view, 11, 1, T) == 0 && view.last.h.quality == 20);

    /* --- interactive quality and subsampling on a drag at the fixed half scale --- */
    SL_CHECK(tclient_send(&ctl, "{\"type\":\"set\",\"stream\":{\"interactive_quality\":30,\"interactive_subsampling\":"
                                "\"444\",\"interactive_adaptive\":false,\"interactive_scale\":0.5,"
                                "\"still_delay_ms\":1500}}") == 0);
    SL_CHECK(wait_patch_key(&ctl, "stream", NULL) > 0);
    SL_CHECK(tclient_send(&ctl, "{\"type\":\"camera\",\"seq\":20,\"phase\":\"move\",\"camera\":{\"orbit\":"
                                "{\"azimuth\":70,\"elevation\":15,\"distance\":2.5}}}") == 0);
    SL_CHECK(tclient_wait_frame(&ctl, 20, 0, T) == 0);
    int interactive = (ctl.last.h.flags & SL_FRAME_FLAG_INTERACTIVE) != 0;
    SL_CHECK_MSG(interactive && ctl.last.h.quality == 30 && ctl.last.h.subsampling == 0 && ctl.last.h.width == 40 &&
                 ctl.last.h.height == 30, "drag frame: interactive %d q%u sub%u %ux%u, want q30 4:4:4 40x30",
                 interactive, ctl.last.h.quality, ctl.last.h.subsampling, ctl.last.h.width, ctl.last.h.height);
    SL_CHECK(tclient_wait_frame(&ctl, 20, 1, T) == 0);
    SL_CHECK_MSG(ctl.last.h.quality == 20 && ctl.last.h.subsampling == 1 && ctl.last.h.width == 80,
                 "still after the drag q%u sub%u width %u", ctl.last.h.quality, ctl.last.h.subsampling,
                 ctl.last.h.width);
    tclient_close(&view);
    tclient_close(&ctl);
}

int main(void)
{
    harness h;
    const char *extra[] = {"--max-sessions", "2", "--grace", "60", NULL};
    HARNESS_START_OR_END(h, extra);
    max_sessions(&h);
    /* Both sessions now have no client; resize_and_quality's session evicts the older. */
    resize_and_quality(&h);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
