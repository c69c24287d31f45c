/* test_server_play.c — live path playback and path_seek (server/sessions/playback.c; PROTOCOL.md "Playback").
 *
 * One session, two clients at 64x48: A (controller) and B (viewer). A plays
 * a 3-key linear orbit path (azimuth 0, 60, 120 at t = 0, 0.75, 1.5 s; 10
 * fps), so the path's camera at frame k is azimuth 8k exactly. Checks: B's
 * play_path is not_controller; a bad path is bad_field naming path.fps; B
 * hears `playback` playing and then stopped with reason "end"; the frames B
 * receives show (frame header state_version -> the camera of that state
 * version in B's state patches) at least 3 different azimuths, each 8k,
 * never decreasing; the last state is the last key (120) and a still frame
 * of it arrives; a camera message from A stops a looping playback (reason
 * "camera") and the camera is then A's; path_seek to t = 0.75 sets azimuth
 * 60; play_stop with nothing playing is an error; the server exits cleanly.
 */
#include <math.h>

#include "sl_server_harness.h"
#include "sl_test.h"

#define T 30000
#define MAX_STATES 4096

static const char *path_3 =
    "{\"fps\":10,\"interpolation\":\"linear\",\"keyframes\":["
    "{\"t\":0,\"camera\":{\"orbit\":{\"azimuth\":0}}},"
    "{\"t\":0.75,\"camera\":{\"orbit\":{\"azimuth\":60}}},"
    "{\"t\":1.5,\"camera\":{\"orbit\":{\"azimuth\":120}}}]}";

/* B's view of the session: state versions and their cameras' azimuths. */
typedef struct seen {
    uint32_t version[MAX_STATES];
    double azimuth[MAX_STATES];
    int n;
} seen;

static double patch_azimuth(const cJSON *patch)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(patch, "camera"), "orbit"), "azimuth");
    return cJSON_IsNumber(a) ? a->valuedouble : NAN;
}

/* Notes a state message's camera (if it has one). */
static void note_state(seen *s, const cJSON *j)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(j, "version");
    double az = patch_azimuth(cJSON_GetObjectItemCaseSensitive(j, "patch"));
    if (strcmp(json_type(j), "state") == 0 && cJSON_IsNumber(v) && !isnan(az) && s->n < MAX_STATES) {
        s->version[s->n] = (uint32_t)v->valuedouble;
        s->azimuth[s->n++] = az;
    }
}

/* The azimuth of the newest state at or before version (NAN when none was seen). */
static double azimuth_of(const seen *s, uint32_t version)
{
    double az = NAN;
    for (int i = 0; i < s->n; i++)
        if (s->version[i] <= version)
            az = s->azimuth[i];
    return az;
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

static const char *playback_state(const cJSON *j, const char **reason)
{
    if (strcmp(json_type(j), "playback") != 0)
        return "";
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(j, "state"), *r = cJSON_GetObjectItemCaseSensitive(j, "reason");
    *reason = cJSON_IsString(r) ? r->valuestring : "";
    return cJSON_IsString(s) ? s->valuestring : "";
}

static void drain(tclient *c)
{
    for (cJSON *x = NULL; tclient_next(c, 0, &x) > 0; x = NULL)
        cJSON_Delete(x);
}

int main(void)
{
    harness h;
    HARNESS_START_OR_END(h, NULL);
    tclient a, b;
    SL_CHECK(tclient_connect(&a, h.port, NULL) == 0 && tclient_hello(&a, NULL, NULL, 64, 48) == 0);
    a.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&a, 0, 0, T) == 0);
    SL_CHECK(tclient_connect(&b, h.port, NULL) == 0 && tclient_hello(&b, a.session, a.token, 64, 48) == 0);
    b.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&b, 0, 0, T) == 0);

    /* Refusals. */
    SL_CHECK(tclient_send(&b, "{\"type\":\"play_path\",\"path\":%s}", path_3) == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&b, "error", T), "not_controller", "play_path"));
    SL_CHECK(tclient_send(&b, "{\"type\":\"path_seek\",\"path\":%s,\"t\":1}", path_3) == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&b, "error", T), "not_controller", "path_seek"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"play_path\",\"path\":{\"fps\":0,\"keyframes\":[]}}") == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&a, "error", T), "bad_field", "path.fps"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"play_stop\"}") == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&a, "error", T), "bad_field", "no path is playing"));
    drain(&a);
    drain(&b);

    /* A plays the path; B follows it frame by frame. */
    static seen st;
    SL_CHECK(tclient_send(&a, "{\"type\":\"play_path\",\"path\":%s}", path_3) == 0);
    int playing = 0, stopped = 0, frames = 0, distinct = 0, bad = 0, decreasing = 0;
    double last_az = -1;
    uint32_t stop_version = 0;
    const char *reason = "";
    char stop_reason[32] = "";
    double deadline = sl_clock_ms() + T;
    while (!stopped && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&b, 200, &j);
        if (r == 2 && playing) {
            double az = azimuth_of(&st, b.last.h.state_version);
            frames++;
            if (isnan(az) || fabs(az / 8.0 - round(az / 8.0)) > 1e-6 || az < 0 || az > 120) {
                bad++;
                fprintf(stderr, "frame of version %u shows azimuth %g\n", b.last.h.state_version, az);
            }
            if (!isnan(az) && az != last_az) {
                distinct++;
                decreasing += az < last_az;
                last_az = az;
            }
        }
        if (r == 1) {
            note_state(&st, j);
            const char *ps = playback_state(j, &reason);
            if (strcmp(ps, "playing") == 0)
                playing++;
            if (strcmp(ps, "stopped") == 0) {
                stopped = 1;
                snprintf(stop_reason, sizeof stop_reason, "%s", reason);
                stop_version = st.n ? st.version[st.n - 1] : 0;
            }
        }
        cJSON_Delete(j);
        drain(&a);
    }
    fprintf(stderr, "playback: B heard %d playing messages and received %d frames showing %d cameras\n", playing,
            frames, distinct);
    SL_CHECK_MSG(playing >= 1, "B heard `playback` playing (%d times)", playing);
    SL_CHECK_MSG(stopped && strcmp(stop_reason, "end") == 0, "B heard playback stopped at the end (\"%s\")",
                 stop_reason);
    SL_CHECK_MSG(frames >= 3 && distinct >= 3, "B received %d frames during playback showing %d cameras", frames,
                 distinct);
    SL_CHECK_MSG(bad == 0 && decreasing == 0, "every played camera is on the path (%d off) and in order (%d back)",
                 bad, decreasing);
    SL_CHECK_MSG(st.n > 0 && st.azimuth[st.n - 1] == 120, "the session ends at the last key (azimuth %g)",
                 st.n ? st.azimuth[st.n - 1] : NAN);
    /* The still of the last key reaches B. */
    int still = 0;
    deadline = sl_clock_ms() + T;
    while (!still && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&b, 200, &j);
        if (r == 2 && b.last.h.state_version >= stop_version && !(b.last.h.flags & SL_FRAME_FLAG_INTERACTIVE))
            still = 1;
        cJSON_Delete(j);
    }
    if (!still && b.last.h.state_version >= stop_version && !(b.last.h.flags & SL_FRAME_FLAG_INTERACTIVE))
        still = 1; /* it had arrived with the stopped message */
    SL_CHECK_MSG(still, "a still frame of the last key arrives (version %u)", stop_version);

    /* A camera message stops a looping playback. */
    drain(&b);
    SL_CHECK(tclient_send(&a, "{\"type\":\"play_path\",\"path\":%s,\"loop\":true}", path_3) == 0);
    cJSON *p = NULL;
    deadline = sl_clock_ms() + T;
    while (!p && sl_clock_ms() < deadline) {
        cJSON *j = tclient_wait_type(&b, "playback", 1000);
        if (j && strcmp(playback_state(j, &reason), "playing") == 0)
            p = j;
        else
            cJSON_Delete(j);
    }
    SL_CHECK_MSG(p != NULL, "the looping path plays");
    cJSON_Delete(p);
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":5,\"camera\":{\"orbit\":{\"azimuth\":33}}}") == 0);
    cJSON *s = NULL;
    deadline = sl_clock_ms() + T;
    while (!s && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&b, 200, &j);
        if (r == 1) {
            note_state(&st, j);
            if (strcmp(playback_state(j, &reason), "stopped") == 0) {
                s = j;
                j = NULL;
            }
        }
        cJSON_Delete(j);
    }
    SL_CHECK_MSG(s != NULL && strcmp(playback_state(s, &reason), "stopped") == 0 && strcmp(reason, "camera") == 0,
                 "a camera message stopped playback (reason \"%s\")", s ? reason : "none");
    cJSON_Delete(s);
    /* Nothing more is played: B's newest camera settles on A's. */
    double settle = sl_clock_ms() + 600;
    int played_after = 0;
    while (sl_clock_ms() < settle) {
        cJSON *j = NULL;
        if (tclient_next(&b, 50, &j) == 1) {
            note_state(&st, j);
            played_after += strcmp(playback_state(j, &reason), "playing") == 0;
        }
        cJSON_Delete(j);
    }
    SL_CHECK_MSG(played_after == 0 && st.n > 0 && st.azimuth[st.n - 1] == 33,
                 "after the stop the camera is A's (azimuth %g, %d playing messages)", st.n ? st.azimuth[st.n - 1] : NAN,
                 played_after);

    /* path_seek: the path's camera at t, computed by the server. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"path_seek\",\"path\":%s,\"t\":0.75}", path_3) == 0);
    double az = NAN;
    deadline = sl_clock_ms() + T;
    while (az != 60 && sl_clock_ms() < deadline) {
        cJSON *j = tclient_wait_type(&b, "state", 1000);
        if (j)
            az = patch_azimuth(cJSON_GetObjectItemCaseSensitive(j, "patch"));
        cJSON_Delete(j);
    }
    SL_CHECK_MSG(az == 60, "path_seek to t = 0.75 sets azimuth 60 (got %g)", az);
    SL_CHECK(tclient_send(&a, "{\"type\":\"path_seek\",\"path\":%s,\"t\":-1}", path_3) == 0);
    SL_CHECK(error_code_is(tclient_wait_type(&a, "error", T), "bad_field", "\"t\""));

    tclient_close(&a);
    tclient_close(&b);
    SL_CHECK_MSG(harness_stop(&h) == 0, "server exit status");
    SL_TEST_END();
}
