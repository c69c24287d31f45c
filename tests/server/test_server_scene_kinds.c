/* test_server_scene_kinds.c — a `scene` whose dataset and technique do not fit
 * (the technique's dataset_kinds lack the dataset's kind) is a bad_field error
 * that names both, and the session keeps its last good state: same state
 * version, dataset, technique, parameters and camera as a joining client sees
 * them, no state patch in between, and it keeps rendering. Tried three ways: a
 * new dataset alone (the technique stays), a new technique alone (the dataset
 * stays), and both at once with parameters (none of them applied). A fitting
 * pair then switches. Techniques and datasets are picked from `welcome` by
 * their kinds, never by name. Starts its own server (sl_server_harness.h).
 */
#include <stdio.h>
#include <string.h>

#include "sl_server_harness.h"
#include "sl_test.h"

#define T 20000 /* per-step timeout (ASan + llvmpipe on 2 busy cores) */

static int has_kind(const cJSON *technique, const char *kind)
{
    const cJSON *k;
    cJSON_ArrayForEach(k, cJSON_GetObjectItemCaseSensitive(technique, "dataset_kinds"))
        if (cJSON_IsString(k) && strcmp(k->valuestring, kind) == 0)
            return 1;
    return 0;
}

/* The first technique that accepts `want` and not `without` (NULL: any). */
static const char *technique_for(const cJSON *welcome, const char *want, const char *without)
{
    const cJSON *t;
    cJSON_ArrayForEach(t, cJSON_GetObjectItemCaseSensitive(welcome, "techniques"))
        if (has_kind(t, want) && (!without || !has_kind(t, without)))
            return cJSON_GetObjectItemCaseSensitive(t, "name")->valuestring;
    return NULL;
}

static const char *dataset_of_kind(const cJSON *welcome, const char *kind)
{
    const cJSON *d;
    cJSON_ArrayForEach(d, cJSON_GetObjectItemCaseSensitive(welcome, "datasets")) {
        const cJSON *k = cJSON_GetObjectItemCaseSensitive(d, "kind");
        if (cJSON_IsString(k) && strcmp(k->valuestring, kind) == 0)
            return cJSON_GetObjectItemCaseSensitive(d, "name")->valuestring;
    }
    return NULL;
}

/* The session's state as a client joining now receives it (caller frees). */
static cJSON *joined_state(int port, const tclient *a)
{
    tclient b;
    cJSON *st = NULL;
    if (tclient_connect(&b, port, NULL) == 0 && tclient_hello(&b, a->session, a->token, 64, 48) == 0)
        st = cJSON_DetachItemFromObjectCaseSensitive(b.welcome, "state");
    tclient_close(&b);
    return st;
}

/* Sends `msg`; expects exactly an error (bad_field) naming `dataset` and `technique`, and no
 * state patch before the pong of a ping sent right after it. */
static void expect_refused(tclient *a, const char *msg, const char *dataset, const char *technique, int seq)
{
    SL_CHECK(tclient_send(a, "%s", msg) == 0);
    SL_CHECK(tclient_send(a, "{\"type\":\"ping\",\"seq\":%d}", seq) == 0);
    int errors = 0, patches = 0, pong = 0;
    double deadline = sl_clock_ms() + T;
    while (!pong && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(a, T, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0) {
            errors++;
            const cJSON *code = cJSON_GetObjectItemCaseSensitive(j, "code");
            const cJSON *text = cJSON_GetObjectItemCaseSensitive(j, "message");
            const char *m = cJSON_IsString(text) ? text->valuestring : "";
            SL_CHECK_MSG(cJSON_IsString(code) && strcmp(code->valuestring, "bad_field") == 0, "%s: code %s", msg,
                         cJSON_IsString(code) ? code->valuestring : "(none)");
            SL_CHECK_MSG(strstr(m, dataset) && strstr(m, technique), "%s: the error names %s and %s: %s", msg,
                         dataset, technique, m);
            printf("refused: %s\n", m);
        } else if (r == 1 && strcmp(json_type(j), "state") == 0) {
            patches++;
        } else if (r == 1 && strcmp(json_type(j), "pong") == 0) {
            pong = 1;
        } else if (r <= 0 && a->closed) {
            cJSON_Delete(j);
            break;
        }
        cJSON_Delete(j);
    }
    SL_CHECK_MSG(pong, "%s: no pong", msg);
    SL_CHECK_MSG(errors == 1, "%s: %d error messages, want 1", msg, errors);
    SL_CHECK_MSG(patches == 0, "%s: %d state patches, want none", msg, patches);
}

int main(void)
{
    harness h;
    HARNESS_START_OR_END(h, NULL);
    tclient a;
    SL_CHECK(tclient_connect(&a, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&a, NULL, NULL, 64, 48) == 0);
    a.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&a, 0, 1, T) == 0);

    const cJSON *st0 = cJSON_GetObjectItemCaseSensitive(a.welcome, "state");
    const char *lines_ds = cJSON_GetObjectItemCaseSensitive(st0, "dataset")->valuestring;
    const char *lines_t = cJSON_GetObjectItemCaseSensitive(st0, "technique")->valuestring;
    const char *volume_ds = dataset_of_kind(a.welcome, "volume");
    const char *volume_t = technique_for(a.welcome, "volume", "lines");
    const char *lines_only = technique_for(a.welcome, "lines", "volume");
    SL_CHECK_MSG(volume_ds && volume_t && lines_only, "welcome lists a volume dataset (%s), a volume technique (%s) "
                 "and a lines-only technique (%s)", volume_ds ? volume_ds : "-", volume_t ? volume_t : "-",
                 lines_only ? lines_only : "-");
    SL_CHECK_MSG(strcmp(lines_t, lines_only ? lines_only : "") == 0, "the session starts on %s, a lines-only technique",
                 lines_t);
    if (!volume_ds || !volume_t || !lines_only) {
        tclient_close(&a);
        harness_stop(&h);
        SL_TEST_END();
    }

    /* A last good state that is not all defaults: a camera the session took. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":5,\"camera\":{\"orbit\":{\"azimuth\":77,\"elevation\":11,"
                              "\"distance\":3}}}") == 0);
    SL_CHECK(tclient_wait_frame(&a, 5, 1, T) == 0);
    cJSON *before = joined_state(h.port, &a);
    SL_CHECK(before != NULL);

    char msg[512];
    snprintf(msg, sizeof msg, "{\"type\":\"scene\",\"dataset\":\"%s\"}", volume_ds);
    expect_refused(&a, msg, volume_ds, lines_t, 1);
    snprintf(msg, sizeof msg, "{\"type\":\"scene\",\"technique\":\"%s\"}", volume_t);
    expect_refused(&a, msg, lines_ds, volume_t, 2);
    snprintf(msg, sizeof msg, "{\"type\":\"scene\",\"dataset\":\"%s\",\"technique\":\"%s\",\"params\":{\"radius\":0.5},"
             "\"camera\":{\"orbit\":{\"azimuth\":10}}}", volume_ds, lines_only);
    expect_refused(&a, msg, volume_ds, lines_only, 3);

    /* Nothing of the refused messages reached the session's state. */
    cJSON *after = joined_state(h.port, &a);
    SL_CHECK(after != NULL);
    char *tb = cJSON_PrintUnformatted(before), *ta = cJSON_PrintUnformatted(after);
    SL_CHECK_MSG(tb && ta && strcmp(tb, ta) == 0, "state kept:\n before %s\n after  %s", tb ? tb : "-", ta ? ta : "-");
    free(tb);
    free(ta);
    cJSON_Delete(before);
    cJSON_Delete(after);

    /* Still rendering the last good scene: a camera move gets its frame. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":6,\"camera\":{\"orbit\":{\"azimuth\":90}}}") == 0);
    SL_CHECK_MSG(tclient_wait_frame(&a, 6, 1, T) == 0, "a frame after the refused scenes");

    /* A fitting pair switches both in one state version, and a frame of it arrives. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"%s\",\"technique\":\"%s\"}", volume_ds, volume_t) == 0);
    uint32_t version = 0;
    double deadline = sl_clock_ms() + T;
    while (!version && sl_clock_ms() < deadline) {
        cJSON *m = tclient_wait_type(&a, "state", T);
        if (!m)
            break;
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(m, "patch");
        const cJSON *d = cJSON_GetObjectItemCaseSensitive(p, "dataset");
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(p, "technique");
        if (cJSON_IsString(d) && strcmp(d->valuestring, volume_ds) == 0 && cJSON_IsString(t) &&
            strcmp(t->valuestring, volume_t) == 0)
            version = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
        cJSON_Delete(m);
    }
    SL_CHECK_MSG(version > 0, "a state patch with %s and %s together", volume_ds, volume_t);
    SL_CHECK_MSG(version > 0 && tclient_wait_version(&a, version, 3 * T) == 0, "a frame of %s/%s", volume_ds, volume_t);

    tclient_close(&a);
    SL_CHECK(harness_stop(&h) == 0);
    SL_TEST_END();
}
