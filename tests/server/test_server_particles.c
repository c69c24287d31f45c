/* test_server_particles.c — `particles` through the protocol: a `scene` with
 * the built-in marschner_lobb and technique particles renders stipples (the
 * frame shows them and matches sightline-render of the same scene up to
 * JPEG), a second isovalue (a PREPARED parameter: new particle sets) changes
 * the frame, an isovalue outside the value range is a render_failed error
 * that names it while the session keeps its last good frame, and the
 * session renders again after a valid set. Starts its own server
 * (sl_server_harness.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/sl_image.h"
#include "sl_server_harness.h"
#include "sl_test.h"

#define W 96
#define H 96
#define T 30000 /* per-step timeout (ASan + llvmpipe on 2 busy cores) */

/* Waits for a state patch carrying params.isovalues; returns its version (0 on timeout). */
static uint32_t wait_isovalues(tclient *c)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *m = tclient_wait_type(c, "state", T);
        if (!m)
            return 0;
        const cJSON *patch = cJSON_GetObjectItemCaseSensitive(m, "patch");
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(patch, "params");
        uint32_t version = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
        int hit = cJSON_GetObjectItemCaseSensitive(p, "isovalues") != NULL;
        cJSON_Delete(m);
        if (hit)
            return version;
    }
    return 0;
}

int main(void)
{
    harness h;
    HARNESS_START_OR_END(h, NULL);
    tclient a;
    SL_CHECK(tclient_connect(&a, h.port, NULL) == 0);
    SL_CHECK(tclient_hello(&a, NULL, NULL, W, H) == 0);
    a.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&a, 0, 1, T) == 0);

    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"marschner_lobb\",\"technique\":\"particles\","
                              "\"params\":{\"isovalues\":[0.5],\"stipple_size\":1.2}}") == 0);
    uint32_t v = wait_isovalues(&a);
    SL_CHECK_MSG(v > 0, "no state patch switched to particles");
    SL_CHECK(v > 0 && tclient_wait_version(&a, v, T) == 0);
    sl_image first = tclient_decode_last(&a);
    double fg = harness_foreground_fraction(&first);
    SL_CHECK_MSG(fg > 0.02 && fg < 0.9, "particles frame foreground fraction %.3f", fg);

    sl_image cli = {0};
    const char *scene = "{\"dataset\":\"marschner_lobb\",\"technique\":\"particles\",\"params\":{\"isovalues\":[0.5],"
                        "\"stipple_size\":1.2},\"width\":96,\"height\":96}";
    SL_CHECK(harness_cli_render(&h, scene, "particles_cli", &cli) == 0);
    double d = harness_mean_diff(&first, &cli);
    printf("server frame vs sightline-render: mean |diff| %.3f (JPEG), foreground %.3f\n", d, fg);
    SL_CHECK_MSG(d >= 0 && d < 4.0, "server frame differs from sightline-render by %.3f", d);

    /* A second isovalue: two particle sets, a different frame. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"isovalues\":[0.5,0.3]}}") == 0);
    uint32_t v2 = wait_isovalues(&a);
    SL_CHECK(v2 > 0 && tclient_wait_version(&a, v2, T) == 0);
    sl_image second = tclient_decode_last(&a);
    double d2 = harness_mean_diff(&first, &second);
    printf("second isovalue: mean |diff| %.3f\n", d2);
    SL_CHECK_MSG(d2 > 0.5, "a second isovalue changed the frame by only %.3f", d2);

    /* An isovalue beyond the value range: render_failed naming it. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"isovalues\":[7]}}") == 0);
    cJSON *e = tclient_wait_type(&a, "error", T);
    const cJSON *code = cJSON_GetObjectItemCaseSensitive(e, "code");
    const cJSON *msg = cJSON_GetObjectItemCaseSensitive(e, "message");
    SL_CHECK_MSG(cJSON_IsString(code) && strcmp(code->valuestring, "render_failed") == 0, "code: %s",
                 cJSON_IsString(code) ? code->valuestring : "(none)");
    SL_CHECK_MSG(cJSON_IsString(msg) && strstr(msg->valuestring, "isovalue 7") &&
                     strstr(msg->valuestring, "value range"),
                 "message: %s", cJSON_IsString(msg) ? msg->valuestring : "(none)");
    cJSON_Delete(e);

    /* A valid isovalue again: the session renders. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"isovalues\":[0.6]}}") == 0);
    uint32_t v3 = 0;
    double deadline = sl_clock_ms() + T;
    while (!v3 && sl_clock_ms() < deadline) {
        uint32_t got = wait_isovalues(&a);
        if (!got)
            break;
        v3 = got;
    }
    SL_CHECK(v3 > 0 && tclient_wait_version(&a, v3, T) == 0);
    sl_image third = tclient_decode_last(&a);
    double fg3 = harness_foreground_fraction(&third);
    double d3 = harness_mean_diff(&first, &third);
    printf("after the error, isovalue 0.6: foreground %.3f, mean |diff| to isovalue 0.5 %.3f\n", fg3, d3);
    SL_CHECK_MSG(fg3 > 0.02, "no particles after a valid isovalue (foreground %.3f)", fg3);
    SL_CHECK_MSG(d3 > 0.5, "the frame of isovalue 0.6 is the one of 0.5 (mean |diff| %.3f)", d3);

    sl_image_deinit(&first);
    sl_image_deinit(&second);
    sl_image_deinit(&third);
    sl_image_deinit(&cli);
    tclient_close(&a);
    SL_CHECK(harness_stop(&h) == 0);
    SL_TEST_END();
}
