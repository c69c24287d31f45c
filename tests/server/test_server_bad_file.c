/* test_server_bad_file.c — a dataset file that changed behind the catalog's
 * back, opened through the server.
 *
 * A small OBJ line file is written into the test's data directory and
 * registered (`catalog add` loads it and records its checksum). Session B
 * shows it; session A shows the generated "tiny". Then the file is truncated
 * in the middle of a vertex line and A switches to it. Checks: A gets `error`
 * load_failed (field dataset) whose message names the file and says it is not
 * the file the catalog registered (the node refuses it before parsing, as a
 * node whose data directory differs from the others' must), and never the
 * server's path; A's state goes back to
 * "tiny" with its technique (a state patch) and its bounds; A's next still
 * frame at the old camera is the image it showed before (mean abs
 * difference < 1), and a camera change still renders with no further error;
 * B receives no error, keeps its dataset (its loaded copy; the file is not
 * reread while B's dataset does not change) and renders on a camera change;
 * /metrics counts one load failure. Then a valid new content is written and
 * recorded with `catalog refresh`, and A switches to it without an error
 * (the new file's two lines, not B's cached copy). Exit status 0 required.
 */
#include <math.h>

#include "image/sl_image.h"
#include "sl_server_harness.h"
#include "sl_test.h"

#define W 96
#define H 72
#define T 20000
#define GOOD_OBJ "v 0 0 0\nv 1 2 3\nv 0.5 1 0\nv 1 0 3\nl 1 2\nl 3 4\n"
#define CHANGED_OBJ "v 0 0 0\nv 2 2 3\nv 0.5 1 0\nl 1 2 3\n"
#define TRUNCATED_OBJ "v 0 0 0\nv 1 2 3\nv 0.5 1 0\nv 1 0"

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    int ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* Waits for a still frame showing state version >= version; counts errors meanwhile. */
static int wait_still_version(tclient *c, uint32_t version, int *errors)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, T, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0) {
            char *t = cJSON_PrintUnformatted(j);
            fprintf(stderr, "unexpected error: %s\n", t ? t : "");
            free(t);
            (*errors)++;
        }
        cJSON_Delete(j);
        if (r == 2 && c->last.h.kind == SL_FRAME_JPEG && c->last.h.state_version >= version &&
            !(c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE))
            return 0;
        if (r == 0)
            return -1;
    }
    return -1;
}

/* Waits for a state patch setting dataset to name; returns its version (0 on timeout). */
static uint32_t wait_dataset_patch(tclient *c, const char *name, int *errors)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, T, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0)
            (*errors)++;
        const cJSON *d = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(j, "patch"), "dataset");
        uint32_t v = r == 1 && cJSON_IsString(d) && strcmp(d->valuestring, name) == 0
                         ? (uint32_t)cJSON_GetObjectItemCaseSensitive(j, "version")->valuedouble : 0;
        cJSON_Delete(j);
        if (v)
            return v;
        if (r == 0)
            return 0;
    }
    return 0;
}

int main(void)
{
    harness h;
    HARNESS_START_OR_END(h, NULL);
    char data[400], obj[512];
    snprintf(data, sizeof data, "%s/data", h.dir);
    snprintf(obj, sizeof obj, "%s/lines.obj", data);
    SL_CHECK(write_file(obj, GOOD_OBJ) == 0);
    char *add[] = {h.exe, "catalog", "add", obj, "--db", h.db, "--data-dir", data, NULL};
    SL_CHECK(harness_run_wait(add) == 0);

    /* A on tiny: its first still frame is the reference image. */
    tclient a, b;
    SL_CHECK(tclient_connect(&a, h.port, NULL) == 0 && tclient_hello(&a, NULL, NULL, W, H) == 0);
    a.auto_ack = 1;
    int a_errors = 0, b_errors = 0;
    SL_CHECK(wait_still_version(&a, 1, &a_errors) == 0);
    sl_image before = tclient_decode_last(&a);
    const char *technique = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(a.welcome, "state"),
                                                             "technique")->valuestring;

    /* B shows the file while it is still good. */
    SL_CHECK(tclient_connect(&b, h.port, NULL) == 0 && tclient_hello(&b, NULL, NULL, W, H) == 0);
    b.auto_ack = 1;
    SL_CHECK(tclient_send(&b, "{\"type\":\"scene\",\"dataset\":\"lines.obj\"}") == 0);
    uint32_t vb = wait_dataset_patch(&b, "lines.obj", &b_errors);
    SL_CHECK(vb > 0 && wait_still_version(&b, vb, &b_errors) == 0);

    /* The file is truncated in the middle of a vertex line; A asks for it. */
    SL_CHECK(write_file(obj, TRUNCATED_OBJ) == 0);
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"lines.obj\"}") == 0);
    cJSON *err_msg = NULL;
    uint32_t v_revert = 0;
    int saw_switch = 0, bounds_back = 0;
    const char *revert_technique = NULL;
    char technique_back[64] = "";
    double deadline = sl_clock_ms() + T;
    while ((!err_msg || !v_revert || !bounds_back) && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&a, T, &j);
        if (r == 0)
            break;
        if (r == 1 && strcmp(json_type(j), "error") == 0 && !err_msg) {
            err_msg = j;
            continue;
        }
        const cJSON *patch = cJSON_GetObjectItemCaseSensitive(j, "patch");
        const cJSON *d = cJSON_GetObjectItemCaseSensitive(patch, "dataset");
        const cJSON *bounds = cJSON_GetObjectItemCaseSensitive(patch, "bounds");
        if (cJSON_IsString(d) && strcmp(d->valuestring, "lines.obj") == 0)
            saw_switch = 1;
        /* A was on tiny: a patch naming tiny after the scene request is the revert
         * (it may arrive merged with the switch to lines.obj, which then never shows). */
        if (cJSON_IsString(d) && strcmp(d->valuestring, "tiny") == 0) {
            v_revert = (uint32_t)cJSON_GetObjectItemCaseSensitive(j, "version")->valuedouble;
            revert_technique = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(patch, "technique"));
            snprintf(technique_back, sizeof technique_back, "%s", revert_technique ? revert_technique : "");
        }
        if (v_revert && cJSON_GetArraySize(bounds) == 2)
            bounds_back = 1;
        cJSON_Delete(j);
    }
    const cJSON *code = cJSON_GetObjectItemCaseSensitive(err_msg, "code");
    const cJSON *field = cJSON_GetObjectItemCaseSensitive(err_msg, "field");
    const char *text = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(err_msg, "message"));
    printf("error for the truncated file: %s\n", text ? text : "(none)");
    SL_CHECK_MSG(cJSON_IsString(code) && strcmp(code->valuestring, "load_failed") == 0, "error code %s",
                 cJSON_IsString(code) ? code->valuestring : "(none)");
    SL_CHECK(cJSON_IsString(field) && strcmp(field->valuestring, "dataset") == 0);
    SL_CHECK_MSG(text && strstr(text, "lines.obj") && strstr(text, "not the one the catalog registered"),
                 "the message names the file and the reason: %s", text ? text : "(none)");
    SL_CHECK_MSG(text && !strstr(text, h.dir), "the message shows the server's path: %s", text ? text : "(none)");
    cJSON_Delete(err_msg);
    printf("state patches: switch to lines.obj seen separately: %d; back to tiny at version %u\n", saw_switch, v_revert);
    SL_CHECK_MSG(v_revert > 0, "state did not go back to tiny");
    SL_CHECK_MSG(strcmp(technique_back, technique) == 0, "technique after the revert \"%s\", before \"%s\"",
                 technique_back, technique);
    SL_CHECK_MSG(bounds_back, "bounds of tiny not restored after the revert");

    /* A still renders its previous dataset: the same image at the same camera. */
    SL_CHECK(wait_still_version(&a, v_revert, &a_errors) == 0);
    sl_image after = tclient_decode_last(&a);
    double d = harness_mean_diff(&before, &after);
    SL_CHECK_MSG(d >= 0 && d < 1.0, "A's frame after the failed load differs from before: mean abs %.3f", d);
    SL_CHECK(tclient_send(&a, "{\"type\":\"camera\",\"seq\":3,\"camera\":{\"orbit\":{\"azimuth\":100,\"elevation\":10,"
                              "\"distance\":2.5}}}") == 0);
    SL_CHECK(tclient_wait_frame(&a, 3, 1, T) == 0);
    SL_CHECK_MSG(a_errors == 0, "A got %d errors besides load_failed", a_errors);

    /* B is untouched: no error, same dataset, renders on a camera change. */
    SL_CHECK(tclient_send(&b, "{\"type\":\"camera\",\"seq\":4,\"camera\":{\"orbit\":{\"azimuth\":60,\"elevation\":10,"
                              "\"distance\":2.5}}}") == 0);
    double until = sl_clock_ms() + T;
    int b_frame = 0, b_switched = 0;
    while (!b_frame && sl_clock_ms() < until) {
        cJSON *j = NULL;
        int r = tclient_next(&b, T, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0)
            b_errors++;
        const cJSON *dd = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(j, "patch"), "dataset");
        b_switched |= cJSON_IsString(dd) && strcmp(dd->valuestring, "lines.obj") != 0;
        cJSON_Delete(j);
        b_frame = r == 2 && b.last.h.camera_seq >= 4 && !(b.last.h.flags & SL_FRAME_FLAG_INTERACTIVE);
        if (r == 0)
            break;
    }
    SL_CHECK_MSG(b_frame && b_errors == 0 && !b_switched && !b.closed, "B: frame %d, errors %d, dataset changed %d",
                 b_frame, b_errors, b_switched);
    SL_CHECK(harness_metric(h.port, "sightline_dataset_load_failures_total") == 1);

    /* A deliberate change, recorded with `catalog refresh`, loads again. */
    SL_CHECK(write_file(obj, CHANGED_OBJ) == 0);
    char *refresh[] = {h.exe, "catalog", "refresh", "lines.obj", "--db", h.db, "--data-dir", data, NULL};
    SL_CHECK(harness_run_wait(refresh) == 0);
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"lines.obj\"}") == 0);
    a_errors = 0;
    uint32_t va = wait_dataset_patch(&a, "lines.obj", &a_errors);
    SL_CHECK(va > 0 && wait_still_version(&a, va, &a_errors) == 0);
    SL_CHECK_MSG(a_errors == 0, "A got %d errors opening the refreshed file", a_errors);
    SL_CHECK(harness_metric(h.port, "sightline_dataset_load_failures_total") == 1);

    sl_image_deinit(&before);
    sl_image_deinit(&after);
    tclient_close(&a);
    tclient_close(&b);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
