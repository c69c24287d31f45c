/* test_protocol.c — proto/sl_protocol: client message parsing and the frame header.
 *
 * Every message type parses with its fields; every kind of bad input gives
 * SL_ERR_INVALID with the documented code and offending field and leaves the
 * message zeroed; stream settings patch all or nothing, naming the bad key;
 * welcome carries core's default camera and elevation limit, and state the
 * complete camera; the frame header round-trips every field bit-exactly and
 * rejects short buffers, a wrong magic, an unknown kind and a payload size
 * that disagrees with the message. No server, no GL.
 */
#include <stdlib.h>
#include <string.h>

#include "sl_protocol.h"
#include "sl_test.h"

static sl_msg msg;
static char code[32], field[SL_PROTO_ID_MAX];
static sl_err err;

static sl_status parse(const char *text)
{
    sl_msg_deinit(&msg);
    return sl_msg_parse(text, strlen(text), &msg, code, field, &err);
}

static int fails_with(const char *text, const char *want_code, const char *want_field)
{
    sl_status st = parse(text);
    int ok = st == SL_ERR_INVALID && strcmp(code, want_code) == 0 && strcmp(field, want_field) == 0 &&
             msg.root == NULL && msg.type == SL_MSG_INVALID;
    if (!ok)
        fprintf(stderr, "%s: status %d code %s field %s (%s)\n", text, st, code, field, err.message);
    return ok;
}

int main(void)
{
    /* hello */
    SL_CHECK(parse("{\"type\":\"hello\",\"version\":1,\"width\":320,\"height\":200}") == SL_OK);
    SL_CHECK(msg.type == SL_MSG_HELLO && msg.version == 1 && msg.width == 320 && msg.height == 200 && !msg.session[0]);
    SL_CHECK(parse("{\"type\":\"hello\",\"version\":1,\"session\":\"node-1_A.0123456789abcdef\",\"token\":\"def\"}")
             == SL_OK);
    SL_CHECK(strcmp(msg.session, "node-1_A.0123456789abcdef") == 0 && strcmp(msg.token, "def") == 0 && msg.width == 0);
    /* Session ids are NODE.HEX (issue 16): a node id of 1-32 [A-Za-z0-9_-], '.', 16 lowercase hex digits. */
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"session\":\"abc\",\"token\":\"def\"}", "bad_field",
                        "session"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"session\":\".0123456789abcdef\"}", "bad_field", "session"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"session\":\"a b.0123456789abcdef\"}", "bad_field",
                        "session"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"session\":\"n.0123456789ABCDEF\"}", "bad_field", "session"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"session\":\"n.0123456789abcde\"}", "bad_field", "session"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"session\":\"aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa.0123456789abcdef\"}",
                        "bad_field", "session")); /* a 33-character node id */
    SL_CHECK(sl_node_id_valid("aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa") && !sl_node_id_valid("") && !sl_node_id_valid("a.b"));
    SL_CHECK(sl_session_id_valid("aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa.0123456789abcdef"));
    SL_CHECK(fails_with("{\"type\":\"hello\"}", "bad_field", "version"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"width\":5000}", "bad_field", "width"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"height\":0}", "bad_field", "height"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"width\":10.5}", "bad_field", "width"));
    SL_CHECK(fails_with("{\"type\":\"hello\",\"version\":1,\"session\":7}", "bad_field", "session"));
    char longtok[200];
    snprintf(longtok, sizeof longtok, "{\"type\":\"hello\",\"version\":1,\"token\":\"%0100d\"}", 0);
    SL_CHECK(fails_with(longtok, "bad_field", "token"));

    /* playback and named paths (the path itself is checked by the server: sl_scene_path_parse) */
    SL_CHECK(parse("{\"type\":\"play_path\",\"path\":{\"fps\":2},\"loop\":true}") == SL_OK);
    SL_CHECK(msg.type == SL_MSG_PLAY_PATH && msg.loop == 1 && cJSON_IsObject(msg.path));
    SL_CHECK(parse("{\"type\":\"play_path\",\"path\":{}}") == SL_OK && msg.loop == 0);
    SL_CHECK(fails_with("{\"type\":\"play_path\",\"path\":{},\"loop\":1}", "bad_field", "loop"));
    SL_CHECK(fails_with("{\"type\":\"play_path\",\"path\":[]}", "bad_field", "path"));
    SL_CHECK(fails_with("{\"type\":\"play_path\",\"path\":{},\"speed\":2}", "bad_field", "speed"));
    SL_CHECK(parse("{\"type\":\"play_stop\"}") == SL_OK && msg.type == SL_MSG_PLAY_STOP);
    SL_CHECK(parse("{\"type\":\"path_seek\",\"path\":{},\"t\":2.5}") == SL_OK && msg.type == SL_MSG_PATH_SEEK &&
             msg.t == 2.5);
    SL_CHECK(fails_with("{\"type\":\"path_seek\",\"path\":{}}", "bad_field", "t"));
    SL_CHECK(fails_with("{\"type\":\"path_seek\",\"path\":{},\"t\":-0.5}", "bad_field", "t"));
    SL_CHECK(parse("{\"type\":\"save_path\",\"name\":\"a\",\"path\":{}}") == SL_OK && msg.type == SL_MSG_SAVE_PATH &&
             strcmp(msg.name, "a") == 0 && cJSON_IsObject(msg.path));
    SL_CHECK(fails_with("{\"type\":\"save_path\",\"name\":\"a\"}", "bad_field", "path"));
    SL_CHECK(fails_with("{\"type\":\"save_path\",\"name\":\"\",\"path\":{}}", "bad_field", "name"));
    SL_CHECK(parse("{\"type\":\"load_path\",\"name\":\"a\"}") == SL_OK && msg.type == SL_MSG_LOAD_PATH);
    SL_CHECK(fails_with("{\"type\":\"load_path\",\"name\":\"a\",\"path\":{}}", "bad_field", "path"));
    SL_CHECK(parse("{\"type\":\"list_paths\"}") == SL_OK && msg.type == SL_MSG_LIST_PATHS);
    char *pb = sl_msg_playback_text("stopped", 1.5, 3, 12, 25, 0, "camera");
    SL_CHECK(pb && strcmp(pb, "{\"type\":\"playback\",\"state\":\"stopped\",\"t\":1.5,\"duration\":3,\"frame\":12,"
                             "\"frames\":25,\"loop\":false,\"reason\":\"camera\"}") == 0);
    free(pb);

    /* camera */
    SL_CHECK(parse("{\"type\":\"camera\",\"seq\":4294967295,\"phase\":\"move\",\"camera\":{\"orbit\":{}}}") == SL_OK);
    SL_CHECK(msg.type == SL_MSG_CAMERA && msg.seq == 4294967295LL && msg.phase == SL_PHASE_MOVE && cJSON_IsObject(msg.camera));
    SL_CHECK(parse("{\"type\":\"camera\",\"seq\":0,\"camera\":{}}") == SL_OK && msg.phase == SL_PHASE_NONE);
    SL_CHECK(fails_with("{\"type\":\"camera\",\"seq\":-1,\"camera\":{}}", "bad_field", "seq"));
    SL_CHECK(fails_with("{\"type\":\"camera\",\"seq\":4294967296,\"camera\":{}}", "bad_field", "seq"));
    SL_CHECK(fails_with("{\"type\":\"camera\",\"seq\":1,\"phase\":\"drag\",\"camera\":{}}", "bad_field", "phase"));
    SL_CHECK(fails_with("{\"type\":\"camera\",\"seq\":1}", "bad_field", "camera"));
    SL_CHECK(fails_with("{\"type\":\"camera\",\"seq\":1,\"camera\":[]}", "bad_field", "camera"));

    /* set / scene */
    SL_CHECK(parse("{\"type\":\"set\",\"params\":{\"a\":1},\"background\":[0,0.5,1,1]}") == SL_OK);
    SL_CHECK(msg.type == SL_MSG_SET && cJSON_IsObject(msg.params) && cJSON_IsArray(msg.background) && !msg.stream);
    SL_CHECK(fails_with("{\"type\":\"set\"}", "bad_field", "params"));
    SL_CHECK(fails_with("{\"type\":\"set\",\"params\":3}", "bad_field", "params"));
    SL_CHECK(fails_with("{\"type\":\"set\",\"background\":[0,0,2,1]}", "bad_field", "background"));
    SL_CHECK(fails_with("{\"type\":\"set\",\"background\":[0,0,1]}", "bad_field", "background"));
    SL_CHECK(parse("{\"type\":\"scene\",\"dataset\":\"tornado\"}") == SL_OK);
    SL_CHECK(msg.type == SL_MSG_SCENE && strcmp(msg.dataset, "tornado") == 0 && !msg.technique[0]);
    SL_CHECK(fails_with("{\"type\":\"scene\"}", "bad_field", "dataset"));
    SL_CHECK(fails_with("{\"type\":\"scene\",\"technique\":1}", "bad_field", "technique"));

    /* the rest */
    SL_CHECK(parse("{\"type\":\"ack\",\"frame\":12}") == SL_OK && msg.type == SL_MSG_ACK && msg.frame_id == 12);
    SL_CHECK(fails_with("{\"type\":\"ack\"}", "bad_field", "frame"));
    SL_CHECK(parse("{\"type\":\"resize\",\"width\":64,\"height\":48}") == SL_OK && msg.width == 64 && msg.height == 48);
    SL_CHECK(fails_with("{\"type\":\"resize\",\"width\":64}", "bad_field", "height"));
    SL_CHECK(parse("{\"type\":\"save_view\",\"name\":\"front\"}") == SL_OK && strcmp(msg.name, "front") == 0);
    SL_CHECK(fails_with("{\"type\":\"load_view\",\"name\":\"\"}", "bad_field", "name"));
    SL_CHECK(parse("{\"type\":\"control\",\"action\":\"grant\",\"client\":3}") == SL_OK);
    SL_CHECK(msg.action == SL_CONTROL_GRANT && msg.client == 3);
    SL_CHECK(fails_with("{\"type\":\"control\",\"action\":\"grant\"}", "bad_field", "client"));
    SL_CHECK(fails_with("{\"type\":\"control\",\"action\":\"steal\"}", "bad_field", "action"));
    SL_CHECK(parse("{\"type\":\"snapshot\"}") == SL_OK && msg.type == SL_MSG_SNAPSHOT);
    SL_CHECK(parse("{\"type\":\"list_datasets\"}") == SL_OK && msg.type == SL_MSG_LIST_DATASETS);
    SL_CHECK(parse("{\"type\":\"ping\",\"seq\":9}") == SL_OK && msg.seq == 9);

    /* whole-message errors */
    SL_CHECK(fails_with("{\"type\":\"camera\",", "bad_json", ""));
    SL_CHECK(fails_with("[1,2]", "bad_json", ""));
    SL_CHECK(fails_with("{}", "bad_field", "type"));
    SL_CHECK(fails_with("{\"type\":\"teleport\"}", "unknown_type", "type"));
    SL_CHECK(fails_with("{\"type\":\"snapshot\",\"extra\":1}", "bad_field", "extra"));
    /* Length is honoured: the text after len is not read. */
    const char *two = "{\"type\":\"snapshot\"}garbage";
    sl_msg_deinit(&msg);
    SL_CHECK(sl_msg_parse(two, 19, &msg, code, field, &err) == SL_OK);
    sl_msg_deinit(&msg);
    SL_CHECK(sl_msg_parse(two, 10, &msg, code, field, &err) == SL_ERR_INVALID && strcmp(code, "bad_json") == 0);

    char *e = sl_msg_error_text("bad_param", "x must be in [0, 1]", "params.x");
    cJSON *ej = cJSON_Parse(e);
    SL_CHECK(ej && strcmp(cJSON_GetObjectItem(ej, "type")->valuestring, "error") == 0);
    SL_CHECK(ej && strcmp(cJSON_GetObjectItem(ej, "field")->valuestring, "params.x") == 0);
    SL_CHECK(ej && !cJSON_GetObjectItem(ej, "repeated"));
    cJSON_Delete(ej);
    free(e);
    /* merged errors: `repeated` counts the ones after the first */
    e = sl_msg_error_repeat_text("bad_param", "x must be in [0, 1]", "params.x", 49);
    ej = cJSON_Parse(e);
    const cJSON *rep = cJSON_GetObjectItem(ej, "repeated");
    SL_CHECK(ej && cJSON_IsNumber(rep) && rep->valueint == 49);
    SL_CHECK(ej && strcmp(cJSON_GetObjectItem(ej, "code")->valuestring, "bad_param") == 0);
    cJSON_Delete(ej);
    free(e);

    /* progress: null fraction when unknown, a number when known; done carries ok, frame and render ms */
    sl_msg_progress pm = {.stage = SL_PROGRESS_LOADING, .round = 3, .version = 7, .dataset = "furball_787k",
                          .technique = "tubes", .fraction = -1, .elapsed_ms = 12.34};
    char *pt = sl_msg_progress_text(&pm);
    cJSON *pj = cJSON_Parse(pt);
    SL_CHECK(pj && strcmp(cJSON_GetObjectItem(pj, "type")->valuestring, "progress") == 0);
    SL_CHECK(pj && strcmp(cJSON_GetObjectItem(pj, "stage")->valuestring, "loading") == 0);
    SL_CHECK(pj && cJSON_IsNull(cJSON_GetObjectItem(pj, "fraction")));
    SL_CHECK(pj && cJSON_GetObjectItem(pj, "round")->valuedouble == 3 && cJSON_GetObjectItem(pj, "version")->valuedouble == 7);
    SL_CHECK(pj && fabs(cJSON_GetObjectItem(pj, "elapsed_ms")->valuedouble - 12.3) < 1e-9);
    SL_CHECK(pj && !cJSON_GetObjectItem(pj, "ok") && !cJSON_GetObjectItem(pj, "frame"));
    cJSON_Delete(pj);
    free(pt);
    pm.stage = SL_PROGRESS_DONE;
    pm.fraction = 1;
    pm.ok = 1;
    pm.frame = 42;
    pm.load_ms = 1000;
    pm.prepare_ms = 250;
    pm.render_ms = 80;
    pt = sl_msg_progress_text(&pm);
    pj = cJSON_Parse(pt);
    SL_CHECK(pj && strcmp(cJSON_GetObjectItem(pj, "stage")->valuestring, "done") == 0);
    SL_CHECK(pj && cJSON_GetObjectItem(pj, "fraction")->valuedouble == 1);
    SL_CHECK(pj && cJSON_IsTrue(cJSON_GetObjectItem(pj, "ok")) && cJSON_GetObjectItem(pj, "frame")->valuedouble == 42);
    SL_CHECK(pj && cJSON_GetObjectItem(pj, "load_ms")->valuedouble == 1000 &&
             cJSON_GetObjectItem(pj, "prepare_ms")->valuedouble == 250 &&
             cJSON_GetObjectItem(pj, "render_ms")->valuedouble == 80);
    cJSON_Delete(pj);
    free(pt);
    SL_CHECK(strcmp(sl_progress_stage_name(SL_PROGRESS_FIRST_FRAME), "first_frame") == 0);

    /* stream settings: defaults, a patch, and all-or-nothing failures naming the key */
    sl_stream_settings ss = SL_STREAM_DEFAULTS;
    SL_CHECK(ss.interactive_scale == 1.0 && ss.interactive_adaptive == 1 && ss.interactive_budget_ms == 100);
    cJSON *sp = cJSON_Parse("{\"interactive_adaptive\":false,\"interactive_budget_ms\":250,\"interactive_scale\":0.5}");
    SL_CHECK(sl_msg_stream_apply(&ss, sp, field, &err) == SL_OK);
    SL_CHECK(!ss.interactive_adaptive && ss.interactive_budget_ms == 250 && ss.interactive_scale == 0.5);
    cJSON_Delete(sp);
    const char *bad_stream[][2] = {{"{\"interactive_budget_ms\":9}", "stream.interactive_budget_ms"},
                                   {"{\"interactive_budget_ms\":100.5}", "stream.interactive_budget_ms"},
                                   {"{\"interactive_adaptive\":\"yes\"}", "stream.interactive_adaptive"},
                                   {"{\"interactive_budget_ms\":50,\"interactive_adaptive\":0}", "stream.interactive_adaptive"}};
    for (size_t i = 0; i < sizeof bad_stream / sizeof bad_stream[0]; i++) {
        sl_stream_settings before = ss;
        sp = cJSON_Parse(bad_stream[i][0]);
        SL_CHECK(sl_msg_stream_apply(&ss, sp, field, &err) == SL_ERR_INVALID);
        SL_CHECK_MSG(strcmp(field, bad_stream[i][1]) == 0, "%s: field %s", bad_stream[i][0], field);
        SL_CHECK(memcmp(&before, &ss, sizeof ss) == 0);
        cJSON_Delete(sp);
    }
    cJSON *sj = sl_msg_stream_json(&ss);
    SL_CHECK(cJSON_IsFalse(cJSON_GetObjectItem(sj, "interactive_adaptive")));
    SL_CHECK(cJSON_GetObjectItem(sj, "interactive_budget_ms")->valueint == 250);
    cJSON_Delete(sj);

    /* welcome: the page's camera defaults and elevation limit come from core/sl_camera.h */
    char *wt = sl_msg_welcome_text(&(sl_msg_welcome){.session = "s", .token = "t", .client = 1});
    cJSON *wj = cJSON_Parse(wt);
    const cJSON *cd = cJSON_GetObjectItemCaseSensitive(wj, "camera_default");
    const cJSON *co = cJSON_GetObjectItemCaseSensitive(cd, "orbit");
    SL_CHECK(cJSON_IsObject(co) && cJSON_GetObjectItem(co, "azimuth")->valuedouble == sl_orbit_default.azimuth_deg &&
             cJSON_GetObjectItem(co, "elevation")->valuedouble == sl_orbit_default.elevation_deg &&
             cJSON_GetObjectItem(co, "distance")->valuedouble == sl_orbit_default.distance);
    SL_CHECK(cJSON_IsNumber(cJSON_GetObjectItem(cd, "fov_y")) &&
             cJSON_GetObjectItem(cd, "fov_y")->valuedouble == sl_orbit_default.fov_y_deg);
    const cJSON *me = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(wj, "limits"), "max_elevation");
    SL_CHECK(cJSON_IsNumber(me) && me->valuedouble == SL_ORBIT_MAX_ELEVATION);
    cJSON_Delete(wj);
    free(wt);

    /* camera check: the typed camera comes out, with defaults for what the client left out */
    cJSON *cj = cJSON_Parse("{\"orbit\":{\"azimuth\":75}}");
    sl_camera_spec spec = {0};
    SL_CHECK(sl_msg_camera_check(cj, NULL, &spec, &err) == SL_OK);
    SL_CHECK(spec.is_orbit && spec.orbit.azimuth_deg == 75.0 && spec.orbit.elevation_deg == 20.0 &&
             spec.orbit.distance == 2.5 && spec.orbit.fov_y_deg == 45.0);
    cJSON_Delete(cj);
    cj = cJSON_Parse("{\"orbit\":{\"distance\":2e6}}");
    sl_camera_spec kept = spec;
    SL_CHECK(sl_msg_camera_check(cj, NULL, &spec, &err) == SL_ERR_INVALID && memcmp(&kept, &spec, sizeof spec) == 0);
    cJSON_Delete(cj);
    sl_params no_params = {0};
    const float bg[4] = {0, 0, 0, 1};
    sl_stream_settings defaults = SL_STREAM_DEFAULTS;
    cJSON *stj = sl_msg_state_json(&(sl_msg_state){.dataset = "d", .technique = "t", .params = &no_params,
                                                    .camera = &spec, .background = bg, .stream = &defaults});
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(stj, "camera");
    SL_CHECK(cJSON_GetObjectItem(cJSON_GetObjectItem(sc, "orbit"), "azimuth")->valuedouble == 75.0 &&
             cJSON_GetObjectItem(cJSON_GetObjectItem(sc, "orbit"), "distance")->valuedouble == 2.5 &&
             cJSON_GetObjectItem(sc, "fov_y")->valuedouble == 45.0);
    cJSON_Delete(stj);

    /* frame header */
    sl_frame_header h = {.kind = SL_FRAME_JPEG, .flags = SL_FRAME_FLAG_INTERACTIVE, .frame_id = 0xdeadbeef,
                         .state_version = 77, .width = 1920, .height = 1080, .quality = 60, .subsampling = 1,
                         .render_ms = 12.25f, .encode_ms = 3.5f, .camera_seq = 4000000000u, .payload_bytes = 5};
    uint8_t buf[SL_FRAME_HEADER_SIZE + 5] = {0};
    sl_frame_header_write(&h, buf);
    SL_CHECK(memcmp(buf, "SLF1", 4) == 0);
    sl_frame_header r;
    SL_CHECK(sl_frame_header_read(buf, sizeof buf, &r, &err) == SL_OK);
    SL_CHECK(r.kind == h.kind && r.flags == h.flags && r.frame_id == h.frame_id && r.state_version == 77);
    SL_CHECK(r.width == 1920 && r.height == 1080 && r.quality == 60 && r.subsampling == 1);
    SL_CHECK(r.render_ms == 12.25f && r.encode_ms == 3.5f && r.camera_seq == 4000000000u && r.payload_bytes == 5);
    SL_CHECK(sl_frame_header_read(buf, sizeof buf - 1, &r, &err) == SL_ERR_FORMAT);
    SL_CHECK(sl_frame_header_read(buf, 39, &r, &err) == SL_ERR_FORMAT);
    buf[6] = 9;
    SL_CHECK(sl_frame_header_read(buf, sizeof buf, &r, &err) == SL_ERR_FORMAT);
    buf[6] = 0;
    buf[0] = 'X';
    SL_CHECK(sl_frame_header_read(buf, sizeof buf, &r, &err) == SL_ERR_FORMAT);
    buf[0] = 'S';
    buf[4] = 41;
    SL_CHECK(sl_frame_header_read(buf, sizeof buf, &r, &err) == SL_ERR_FORMAT);

    sl_msg_deinit(&msg);
    SL_TEST_END();
}
