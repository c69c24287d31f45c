/* test_server_paths.c — named camera paths in the catalog (save_path, list_paths, load_path; catalog.c).
 *
 * One session: A (controller) and B (viewer). Checks: A saves a 3-key path
 * (path_saved); list_paths lists it with its key count, duration and the
 * session's technique; load_path (by the viewer too) gives back an object
 * equal to the one saved; saving the same name again replaces it; an empty
 * name and one of 64 bytes are bad_field naming `name`; a viewer's
 * save_path is not_controller; an invalid path is bad_field naming
 * path.fps; a valid path of more than SL_CATALOG_MAX_PATH_BYTES (32768)
 * bytes of JSON is `limit` naming `path` and is not stored; an unknown name
 * is not_found; the server exits cleanly.
 */
#include "sl_server_harness.h"
#include "sl_test.h"

#define T 30000

static const char *path_3 =
    "{\"fps\":10,\"interpolation\":\"linear\",\"keyframes\":["
    "{\"t\":0,\"camera\":{\"orbit\":{\"azimuth\":0}}},"
    "{\"t\":0.75,\"camera\":{\"eye\":[0,0,4],\"target\":[0,0,0]},\"params\":{\"radius\":0.02}},"
    "{\"t\":1.5,\"camera\":{\"orbit\":{\"azimuth\":120,\"distance\":2}}}]}";

static int error_is(cJSON *e, const char *code, const char *field)
{
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(e, "code"), *f = cJSON_GetObjectItemCaseSensitive(e, "field");
    int ok = e && cJSON_IsString(c) && strcmp(c->valuestring, code) == 0 && cJSON_IsString(f) &&
             strcmp(f->valuestring, field) == 0;
    if (!ok)
        fprintf(stderr, "expected error %s (field %s), got %s\n", code, field, e ? cJSON_PrintUnformatted(e) : "nothing");
    cJSON_Delete(e);
    return ok;
}

/* The entry of `name` in a `paths` reply (borrowed), or NULL. */
static const cJSON *find_entry(const cJSON *reply, const char *name)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(reply, "paths")) {
        const cJSON *n = cJSON_GetObjectItemCaseSensitive(e, "name");
        if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0)
            return e;
    }
    return NULL;
}

static double num(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : -1;
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

    /* Save, list, load back equal. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"save_path\",\"name\":\"orbit three\",\"path\":%s}", path_3) == 0);
    cJSON *saved = tclient_wait_type(&a, "path_saved", T);
    const cJSON *sn = cJSON_GetObjectItemCaseSensitive(saved, "name");
    SL_CHECK_MSG(cJSON_IsString(sn) && strcmp(sn->valuestring, "orbit three") == 0, "path_saved names the path");
    cJSON_Delete(saved);
    SL_CHECK(tclient_send(&b, "{\"type\":\"list_paths\"}") == 0);
    cJSON *list = tclient_wait_type(&b, "paths", T);
    const cJSON *entry = find_entry(list, "orbit three");
    const cJSON *tech = cJSON_GetObjectItemCaseSensitive(entry, "technique");
    const cJSON *state_tech = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(a.welcome, "state"),
                                                               "technique");
    SL_CHECK_MSG(entry && num(entry, "keys") == 3 && num(entry, "duration") == 1.5 && cJSON_IsString(tech) &&
                 cJSON_IsString(state_tech) && strcmp(tech->valuestring, state_tech->valuestring) == 0,
                 "list_paths: %s", entry ? cJSON_PrintUnformatted(entry) : "no entry");
    cJSON_Delete(list);
    SL_CHECK(tclient_send(&b, "{\"type\":\"load_path\",\"name\":\"orbit three\"}") == 0);
    cJSON *loaded = tclient_wait_type(&b, "path", T);
    cJSON *want = cJSON_Parse(path_3);
    SL_CHECK_MSG(loaded && cJSON_Compare(cJSON_GetObjectItemCaseSensitive(loaded, "path"), want, 1),
                 "load_path gives back the saved path: %s", loaded ? cJSON_PrintUnformatted(loaded) : "nothing");
    cJSON_Delete(loaded);
    cJSON_Delete(want);

    /* The same name again replaces it. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"save_path\",\"name\":\"orbit three\",\"path\":{\"fps\":5,\"keyframes\":"
                              "[{\"t\":0,\"camera\":{\"orbit\":{}}},{\"t\":4,\"camera\":{\"orbit\":{\"azimuth\":9}}}]}}") == 0);
    cJSON_Delete(tclient_wait_type(&a, "path_saved", T));
    SL_CHECK(tclient_send(&a, "{\"type\":\"list_paths\"}") == 0);
    list = tclient_wait_type(&a, "paths", T);
    entry = find_entry(list, "orbit three");
    SL_CHECK_MSG(entry && num(entry, "keys") == 2 && num(entry, "duration") == 4 &&
                 cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(list, "paths")) == 1,
                 "a second save_path of the name replaced the first");
    cJSON_Delete(list);

    /* Refusals. */
    SL_CHECK(tclient_send(&a, "{\"type\":\"save_path\",\"name\":\"\",\"path\":%s}", path_3) == 0);
    SL_CHECK(error_is(tclient_wait_type(&a, "error", T), "bad_field", "name"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"save_path\",\"name\":\"%064d\",\"path\":%s}", 7, path_3) == 0);
    SL_CHECK(error_is(tclient_wait_type(&a, "error", T), "bad_field", "name"));
    SL_CHECK(tclient_send(&b, "{\"type\":\"save_path\",\"name\":\"mine\",\"path\":%s}", path_3) == 0);
    SL_CHECK(error_is(tclient_wait_type(&b, "error", T), "not_controller", "type"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"save_path\",\"name\":\"bad\",\"path\":{\"fps\":0,\"keyframes\":[]}}") == 0);
    cJSON *e = tclient_wait_type(&a, "error", T);
    const cJSON *em = cJSON_GetObjectItemCaseSensitive(e, "message");
    SL_CHECK_MSG(cJSON_IsString(em) && strstr(em->valuestring, "path.fps"), "an invalid path names path.fps");
    SL_CHECK(error_is(e, "bad_field", "path"));
    /* A valid path of 450 keys, about 45 KB of JSON: inside the message limit, over the path limit. */
    static char big[60000];
    size_t n = (size_t)snprintf(big, sizeof big, "{\"fps\":24,\"keyframes\":[");
    for (int k = 0; k < 450; k++)
        n += (size_t)snprintf(big + n, sizeof big - n,
                              "%s{\"t\":%d.125,\"camera\":{\"orbit\":{\"azimuth\":123.456789,\"elevation\":12.345678,"
                              "\"distance\":2.345678}}}", k ? "," : "", k);
    n += (size_t)snprintf(big + n, sizeof big - n, "]}");
    SL_CHECK(n > 40000 && n < sizeof big);
    static char msg[sizeof big + 64];
    int mlen = snprintf(msg, sizeof msg, "{\"type\":\"save_path\",\"name\":\"huge\",\"path\":%s}", big);
    SL_CHECK(sl_wsclient_send_text(a.ws, msg, (size_t)mlen, &a.err) == SL_OK); /* tclient_send holds 8 KiB */
    SL_CHECK(error_is(tclient_wait_type(&a, "error", T), "limit", "path"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"load_path\",\"name\":\"huge\"}") == 0);
    SL_CHECK(error_is(tclient_wait_type(&a, "error", T), "not_found", "name"));
    SL_CHECK(tclient_send(&a, "{\"type\":\"load_path\",\"name\":\"nobody\"}") == 0);
    SL_CHECK(error_is(tclient_wait_type(&a, "error", T), "not_found", "name"));

    tclient_close(&a);
    tclient_close(&b);
    SL_CHECK_MSG(harness_stop(&h) == 0, "server exit status");
    SL_TEST_END();
}
