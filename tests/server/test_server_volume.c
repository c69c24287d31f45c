/* test_server_volume.c — a volume through the protocol: `scene` with the built-in
 * marschner_lobb and technique volume_dvr renders it (the frame shows the volume and
 * matches sightline-render of the same scene up to JPEG), a `set` of a bad
 * transfer-function point is a bad_param error naming the point, a valid new
 * transfer function changes the frame, the catalog then lists the volume's
 * histogram, "opacity": "auto" draws it, and a catalog row described before
 * histograms existed is described again when the volume is opened. Starts its own server (sl_server_harness.h).
 */
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/sl_image.h"
#include "sl_server_harness.h"
#include "sl_test.h"

#define W 96
#define H 96
#define T 20000 /* per-step timeout (ASan + llvmpipe on 2 busy cores) */

#define TF_A "[[0.3,0,0,0,0],[0.5,1,0.6,0.2,0.3],[0.7,0.2,0.5,1,0.6]]"
#define TF_B "[[0.2,0,0,0,0],[0.6,0.2,1,0.2,0.8]]"

/* Waits for a state patch whose `technique` is volume_dvr; returns its version (0 on timeout). */
static uint32_t wait_technique(tclient *c)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *m = tclient_wait_type(c, "state", T);
        if (!m)
            return 0;
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), "technique");
        uint32_t version = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
        int hit = cJSON_IsString(v) && strcmp(v->valuestring, "volume_dvr") == 0;
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

    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"marschner_lobb\",\"technique\":\"volume_dvr\","
                              "\"params\":{\"jitter\":false,\"transfer_function\":" TF_A "}}") == 0);
    uint32_t v = wait_technique(&a);
    SL_CHECK_MSG(v > 0, "no state patch switched to volume_dvr");
    SL_CHECK(v > 0 && tclient_wait_version(&a, v, T) == 0);
    sl_image first = tclient_decode_last(&a);
    double fg = harness_foreground_fraction(&first);
    SL_CHECK_MSG(fg > 0.1 && fg < 0.9, "volume frame foreground fraction %.3f", fg);

    /* The same scene through sightline-render (camera: the session's default). */
    sl_image cli = {0};
    const char *scene = "{\"dataset\":\"marschner_lobb\",\"technique\":\"volume_dvr\",\"params\":{\"jitter\":false,"
                        "\"transfer_function\":" TF_A "},\"width\":96,\"height\":96}";
    SL_CHECK(harness_cli_render(&h, scene, "volume_cli", &cli) == 0);
    double d = harness_mean_diff(&first, &cli);
    printf("server frame vs sightline-render: mean |diff| %.3f (JPEG), foreground %.3f\n", d, fg);
    SL_CHECK_MSG(d >= 0 && d < 3.0, "server frame differs from sightline-render by %.3f", d);

    /* A bad point: bad_param naming the field and the point; the session keeps rendering. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"transfer_function\":[[0,0,0,0,0],[1,1,1,1,1.5]]}}") == 0);
    cJSON *e = tclient_wait_type(&a, "error", T);
    const cJSON *code = cJSON_GetObjectItemCaseSensitive(e, "code");
    const cJSON *field = cJSON_GetObjectItemCaseSensitive(e, "field");
    const cJSON *msg = cJSON_GetObjectItemCaseSensitive(e, "message");
    SL_CHECK(cJSON_IsString(code) && strcmp(code->valuestring, "bad_param") == 0);
    SL_CHECK(cJSON_IsString(field) && strcmp(field->valuestring, "params.transfer_function") == 0);
    SL_CHECK_MSG(cJSON_IsString(msg) && strstr(msg->valuestring, "point 1") && strstr(msg->valuestring, "alpha"),
                 "message: %s", cJSON_IsString(msg) ? msg->valuestring : "(none)");
    cJSON_Delete(e);

    /* A valid new transfer function: a different frame. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"transfer_function\":" TF_B "}}") == 0);
    cJSON *m = NULL;
    uint32_t v2 = 0;
    double deadline = sl_clock_ms() + T;
    while (!v2 && sl_clock_ms() < deadline && (m = tclient_wait_type(&a, "state", T))) {
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), "params");
        if (cJSON_GetObjectItemCaseSensitive(p, "transfer_function"))
            v2 = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
        cJSON_Delete(m);
    }
    SL_CHECK_MSG(v2 > 0, "no state patch with the new transfer function");
    SL_CHECK(v2 > 0 && tclient_wait_version(&a, v2, T) == 0);
    sl_image second = tclient_decode_last(&a);
    double d2 = harness_mean_diff(&first, &second);
    printf("new transfer function: mean |diff| %.3f\n", d2);
    SL_CHECK_MSG(d2 > 2.0, "a new transfer function changed the frame by only %.3f", d2);

    /* The catalog now describes the volume, with its histogram (256 bins
     * summing to the voxel count: Marschner-Lobb has no NaN) and the ramp
     * "opacity": "auto" stands for. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"list_datasets\"}") == 0);
    cJSON *list = tclient_wait_type(&a, "datasets", T);
    const cJSON *ml = NULL, *ds;
    cJSON_ArrayForEach(ds, cJSON_GetObjectItemCaseSensitive(list, "datasets")) {
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(ds, "name");
        if (cJSON_IsString(name) && strcmp(name->valuestring, "marschner_lobb") == 0)
            ml = ds;
    }
    const cJSON *counts = cJSON_GetObjectItemCaseSensitive(ml, "counts");
    const cJSON *hist = cJSON_GetObjectItemCaseSensitive(counts, "histogram");
    const cJSON *dims = cJSON_GetObjectItemCaseSensitive(counts, "dims");
    const cJSON *ramp = cJSON_GetObjectItemCaseSensitive(counts, "auto_opacity");
    double sum = 0, voxels = 1;
    const cJSON *x;
    cJSON_ArrayForEach(x, hist) sum += x->valuedouble;
    cJSON_ArrayForEach(x, dims) voxels *= x->valuedouble;
    SL_CHECK_MSG(cJSON_GetArraySize(hist) == 256 && cJSON_GetArraySize(dims) == 3 && sum == voxels,
                 "histogram: %d bins summing to %.0f, %.0f voxels", cJSON_GetArraySize(hist), sum, voxels);
    SL_CHECK(cJSON_GetArraySize(ramp) >= 2);
    cJSON_Delete(list);

    /* "opacity": "auto" is a valid transfer function and draws the volume. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"params\":{\"transfer_function\":"
                              "{\"colormap\":\"magma\",\"opacity\":\"auto\"}}}") == 0);
    uint32_t v3 = 0;
    deadline = sl_clock_ms() + T;
    while (!v3 && sl_clock_ms() < deadline && (m = tclient_wait_type(&a, "state", T))) {
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "patch"), "params");
        const cJSON *tf = cJSON_GetObjectItemCaseSensitive(p, "transfer_function");
        const cJSON *op = cJSON_GetObjectItemCaseSensitive(tf, "opacity");
        if (cJSON_IsString(op) && strcmp(op->valuestring, "auto") == 0)
            v3 = (uint32_t)cJSON_GetObjectItemCaseSensitive(m, "version")->valuedouble;
        cJSON_Delete(m);
    }
    SL_CHECK_MSG(v3 > 0, "no state patch with the automatic opacity");
    SL_CHECK(v3 > 0 && tclient_wait_version(&a, v3, T) == 0);
    sl_image third = tclient_decode_last(&a);
    double fg3 = harness_foreground_fraction(&third);
    printf("automatic opacity: foreground %.3f\n", fg3);
    SL_CHECK_MSG(fg3 > 0.1, "the automatic opacity shows almost nothing (foreground %.3f)", fg3);

    /* A catalog written before histograms existed (the row described, its
     * counts without histogram): the next time a session opens the volume,
     * the row is described again. */
    sqlite3 *db = NULL;
    SL_CHECK(sqlite3_open(h.db, &db) == SQLITE_OK);
    sqlite3_busy_timeout(db, 5000);
    SL_CHECK(sqlite3_exec(db, "UPDATE datasets SET counts = json_remove(counts, '$.histogram', '$.auto_opacity')"
                              " WHERE name = 'marschner_lobb'", NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(db);
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"tiny\",\"technique\":\"tubes_mesh\"}") == 0);
    SL_CHECK(tclient_wait_frame(&a, 0, 1, T) == 0);
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"marschner_lobb\",\"technique\":\"volume_dvr\"}") == 0);
    SL_CHECK(wait_technique(&a) > 0);
    int refreshed = 0;
    deadline = sl_clock_ms() + T;
    while (!refreshed && sl_clock_ms() < deadline) {
        SL_CHECK(tclient_send(&a, "{\"type\":\"list_datasets\"}") == 0);
        cJSON *again = tclient_wait_type(&a, "datasets", T);
        cJSON_ArrayForEach(ds, cJSON_GetObjectItemCaseSensitive(again, "datasets")) {
            const cJSON *name = cJSON_GetObjectItemCaseSensitive(ds, "name");
            const cJSON *c = cJSON_GetObjectItemCaseSensitive(ds, "counts");
            if (cJSON_IsString(name) && strcmp(name->valuestring, "marschner_lobb") == 0)
                refreshed = cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(c, "histogram")) == 256;
        }
        cJSON_Delete(again);
        if (!refreshed)
            usleep(200000);
    }
    SL_CHECK_MSG(refreshed, "a volume row without a histogram was not described again");

    sl_image_deinit(&first);
    sl_image_deinit(&second);
    sl_image_deinit(&third);
    sl_image_deinit(&cli);
    tclient_close(&a);
    SL_CHECK(harness_stop(&h) == 0);
    SL_TEST_END();
}
