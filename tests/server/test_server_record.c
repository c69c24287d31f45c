/* test_server_record.c — recording jobs (server/sessions/record.c, render/render_record.c; PROTOCOL.md "Recordings").
 *
 * One session, two clients: A (controller) and B (viewer), 64x48. The
 * server runs with --test-frame-fixed-ms 40, so a 25-frame job takes over a
 * second. Checks: a viewer's record is not_controller; a bad path is
 * bad_field naming path.fps; A's job is announced as `recording` queued,
 * running (frame counts rising) and done to both clients; a second record
 * while it runs is busy; during the job A's camera moves keep producing
 * frames that B receives (at least 3 between running and done); the done
 * message gives a URL that refuses a wrong or missing token (403), serves
 * the video once with the session's token (read back independently by
 * tests/support/video_reader: H.264, exactly 25 frames, 64x48) and refuses
 * a second fetch (410); a long job cancelled after it started ends
 * `cancelled`; a job after it runs again; the server exits cleanly (ASan).
 */
#include "sl_server_harness.h"
#include "sl_test.h"
#include "video_reader.h"

#define T 30000

static const char *path_25 =
    "{\"fps\":12,\"keyframes\":[{\"t\":0,\"camera\":{\"orbit\":{\"azimuth\":0}}},"
    "{\"t\":2,\"camera\":{\"orbit\":{\"azimuth\":90,\"distance\":2}}}]}";

/* Waits for a `recording` message of a job after min_id whose state is
 * `state` (others are consumed; *running counts the running ones seen,
 * *frames_seen the frames that arrived meanwhile). Returns it (caller
 * frees) or NULL. */
static cJSON *wait_recording(tclient *c, double min_id, const char *state, int *running, int *frames_seen)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, 1000, &j);
        if (r == 2 && frames_seen)
            (*frames_seen)++;
        if (r != 1) {
            if (r == 0)
                return NULL;
            continue;
        }
        const cJSON *id = cJSON_GetObjectItemCaseSensitive(j, "id");
        if (strcmp(json_type(j), "recording") == 0 && cJSON_IsNumber(id) && id->valuedouble > min_id) {
            const cJSON *s = cJSON_GetObjectItemCaseSensitive(j, "state");
            if (cJSON_IsString(s) && strcmp(s->valuestring, "running") == 0 && running)
                (*running)++;
            if (cJSON_IsString(s) && strcmp(s->valuestring, state) == 0)
                return j;
        }
        cJSON_Delete(j);
    }
    return NULL;
}

static int error_code_is(cJSON *e, const char *code, const char *in_message)
{
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(e, "code"), *m = cJSON_GetObjectItemCaseSensitive(e, "message");
    int ok = e && cJSON_IsString(c) && strcmp(c->valuestring, code) == 0 &&
             (!in_message || (cJSON_IsString(m) && strstr(m->valuestring, in_message)));
    if (!ok)
        fprintf(stderr, "expected error %s (%s), got %s\n", code, in_message ? in_message : "",
                e ? cJSON_PrintUnformatted(e) : "nothing");
    cJSON_Delete(e);
    return ok;
}

int main(void)
{
    harness h;
    const char *extra[] = {"--test-frame-fixed-ms", "40", NULL};
    HARNESS_START_OR_END(h, extra);
    tclient a, b;
    SL_CHECK(tclient_connect(&a, h.port, NULL) == 0 && tclient_hello(&a, NULL, NULL, 64, 48) == 0);
    a.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&a, 0, 0, T) == 0);
    SL_CHECK(tclient_connect(&b, h.port, NULL) == 0 && tclient_hello(&b, a.session, a.token, 64, 48) == 0);
    b.auto_ack = 1;

    /* Refusals before any job. */
    SL_CHECK(tclient_send(&b, "{\"type\":\"record\",\"path\":%s}", path_25) == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&b, "error", T), "not_controller", "record"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"record\",\"path\":{\"fps\":0,\"keyframes\":[]}}") == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&a, "error", T), "bad_field", "path.fps"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"record_cancel\"}") == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&a, "error", T), "bad_field", "no recording"));

    /* A job of 25 frames; A drags the camera meanwhile and B must keep getting frames. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"record\",\"path\":%s,\"format\":\"mp4\"}", path_25) == 0);
    cJSON *q = wait_recording(&b, 0, "queued", NULL, NULL);
    SL_CHECK_MSG(q != NULL, "B heard the job queued");
    cJSON_Delete(q);
    int running = 0, frames = 0;
    cJSON *first = wait_recording(&b, 0, "running", &running, &frames);
    SL_CHECK_MSG(first != NULL, "B heard the job running");
    cJSON_Delete(first);
    SL_CHECK(tclient_send(&a, "{\"type\":\"record\",\"path\":%s}", path_25) == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&a, "error", T), "busy", "already running"));
    frames = 0;
    cJSON *done = NULL;
    for (int k = 0; k < 400 && !done; k++) {
        tclient_send(&a, "{\"type\":\"camera\",\"seq\":%d,\"phase\":\"move\",\"camera\":{\"orbit\":{\"azimuth\":%d}}}",
                     100 + k, 10 + k);
        double until = sl_clock_ms() + 60;
        while (!done && sl_clock_ms() < until) {
            cJSON *j = NULL;
            int r = tclient_next(&b, 20, &j);
            if (r == 2)
                frames++;
            if (r == 1 && strcmp(json_type(j), "recording") == 0) {
                const cJSON *s = cJSON_GetObjectItemCaseSensitive(j, "state");
                if (cJSON_IsString(s) && strcmp(s->valuestring, "done") == 0) {
                    done = j;
                    j = NULL;
                }
            }
            cJSON_Delete(j);
            for (cJSON *x = NULL; tclient_next(&a, 0, &x) > 0;)
                cJSON_Delete(x); /* A's own traffic */
        }
    }
    SL_CHECK_MSG(done != NULL, "B heard the job done");
    SL_CHECK_MSG(frames >= 3, "B received %d frames while the job ran (camera moves keep flowing)", frames);
    const cJSON *job = cJSON_GetObjectItemCaseSensitive(done, "id");
    double job1 = cJSON_IsNumber(job) ? job->valuedouble : 1e9;
    const cJSON *url = cJSON_GetObjectItemCaseSensitive(done, "url");
    const cJSON *nf = cJSON_GetObjectItemCaseSensitive(done, "frames");
    SL_CHECK(cJSON_IsString(url) && cJSON_IsNumber(nf) && nf->valueint == 25);
    if (cJSON_IsString(url)) {
        static char body[8 << 20];
        char path[256];
        size_t len = 0;
        snprintf(path, sizeof path, "%s?token=wrong", url->valuestring);
        SL_CHECK_MSG(harness_http_get(h.port, NULL, path, body, sizeof body) == 403, "a wrong token is 403");
        SL_CHECK_MSG(harness_http_get(h.port, NULL, url->valuestring, body, sizeof body) == 403, "no token is 403");
        snprintf(path, sizeof path, "%s?token=%s", url->valuestring, a.token);
        int status = harness_http_get_n(h.port, NULL, path, body, sizeof body, &len);
        SL_CHECK_MSG(status == 200, "the download is 200 (got %d)", status);
        const char *sep = status == 200 ? strstr(body, "\r\n\r\n") : NULL;
        if (sep) {
            char file[300];
            snprintf(file, sizeof file, "%s/recording.mp4", h.dir);
            FILE *f = fopen(file, "wb");
            size_t off = (size_t)(sep + 4 - body);
            SL_CHECK(f && fwrite(body + off, 1, len - off, f) == len - off);
            if (f)
                fclose(f);
            video_info info;
            char msg[256] = "";
            SL_CHECK_MSG(video_read(file, 0, NULL, 0, &info, msg, sizeof msg) == 0, "%s", msg);
            SL_CHECK_MSG(strcmp(info.codec, "h264") == 0 && info.frames == 25 && info.width == 64 &&
                         info.height == 48, "%s, %d frames, %dx%d", info.codec, info.frames, info.width, info.height);
            unlink(file);
        }
        SL_CHECK_MSG(harness_http_get(h.port, NULL, path, body, sizeof body) == 410, "a second download is 410");
    }
    cJSON_Delete(done);

    /* A long job cancelled once it runs; then another job works. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"record\",\"path\":{\"fps\":24,\"keyframes\":[{\"t\":0,\"camera\":"
                              "{\"orbit\":{}}},{\"t\":20,\"camera\":{\"orbit\":{\"azimuth\":300}}}]},\"format\":\"webm\"}") == 0);
    cJSON *r = wait_recording(&a, job1, "running", NULL, NULL);
    SL_CHECK_MSG(r != NULL, "the long job runs");
    cJSON_Delete(r);
    SL_CHECK(tclient_send(&a, "{\"type\":\"record_cancel\"}") == 0);
    cJSON *c = wait_recording(&a, job1, "cancelled", NULL, NULL);
    SL_CHECK_MSG(c != NULL, "the long job ended cancelled");
    cJSON_Delete(c);
    SL_CHECK(tclient_send(&a, "{\"type\":\"record\",\"path\":{\"fps\":4,\"keyframes\":[{\"t\":0,\"camera\":"
                              "{\"orbit\":{}}},{\"t\":1,\"camera\":{\"orbit\":{}}}]}}") == 0);
    cJSON *d2 = wait_recording(&a, job1 + 1, "done", NULL, NULL);
    SL_CHECK_MSG(d2 != NULL, "a job after the cancelled one finishes");
    cJSON_Delete(d2);

    tclient_close(&a);
    tclient_close(&b);
    SL_CHECK_MSG(harness_stop(&h) == 0, "server exit status");
    SL_TEST_END();
}
