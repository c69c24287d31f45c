/* sl_protocol.c — parse client messages, serialize server messages, pack frame headers.
 *
 * Each message type has a table of allowed keys; anything else is a
 * "bad_field" naming the key, so a typo never silently does nothing. Only
 * syntax and ranges are checked here (see sl_protocol.h for what is not).
 * Any thread; no allocation beyond the cJSON tree the message owns.
 * Cameras are checked with the scene parser's own rules (sl_camera_json.h) plus
 * the protocol's range limits, never a second copy of those rules.
 */
#include "sl_protocol.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/sl_camera.h"
#include "sl_camera_json.h"
#include "sl_params_json.h"

typedef struct msg_spec {
    const char *name;
    sl_msg_type type;
    const char *keys[8];   /* allowed keys besides "type"; NULL-terminated */
} msg_spec;

static const msg_spec specs[] = {
    {"hello", SL_MSG_HELLO, {"version", "session", "token", "width", "height", NULL}},
    {"camera", SL_MSG_CAMERA, {"seq", "phase", "camera", NULL}},
    {"set", SL_MSG_SET, {"params", "stream", "background", NULL}},
    {"scene", SL_MSG_SCENE, {"dataset", "technique", "params", "camera", NULL}},
    {"list_datasets", SL_MSG_LIST_DATASETS, {NULL}},
    {"list_views", SL_MSG_LIST_VIEWS, {NULL}},
    {"save_view", SL_MSG_SAVE_VIEW, {"name", NULL}},
    {"load_view", SL_MSG_LOAD_VIEW, {"name", NULL}},
    {"resize", SL_MSG_RESIZE, {"width", "height", NULL}},
    {"ack", SL_MSG_ACK, {"frame", NULL}},
    {"snapshot", SL_MSG_SNAPSHOT, {NULL}},
    {"control", SL_MSG_CONTROL, {"action", "client", NULL}},
    {"ping", SL_MSG_PING, {"seq", NULL}},
    {"record", SL_MSG_RECORD, {"path", "format", "crf", NULL}},
    {"record_cancel", SL_MSG_RECORD_CANCEL, {NULL}},
    {"play_path", SL_MSG_PLAY_PATH, {"path", "loop", NULL}},
    {"play_stop", SL_MSG_PLAY_STOP, {NULL}},
    {"path_seek", SL_MSG_PATH_SEEK, {"path", "t", NULL}},
    {"save_path", SL_MSG_SAVE_PATH, {"name", "path", NULL}},
    {"list_paths", SL_MSG_LIST_PATHS, {NULL}},
    {"load_path", SL_MSG_LOAD_PATH, {"name", NULL}},
};

static sl_status fail(sl_msg *msg, char *code, char *field, const char *c, const char *f,
                      sl_err *err, const char *fmt, const char *arg)
{
    sl_msg_deinit(msg);
    snprintf(code, 32, "%s", c);
    snprintf(field, SL_PROTO_ID_MAX, "%s", f ? f : "");
    return sl_err_set(err, SL_ERR_INVALID, fmt, arg);
}

/* Copies string member `key` into out (size bytes). Returns 1 when present
 * and valid, 0 when absent, -1 when not a string or too long. */
static int get_string(const cJSON *root, const char *key, char *out, size_t size)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!it || cJSON_IsNull(it))
        return 0;
    if (!cJSON_IsString(it) || !it->valuestring || strlen(it->valuestring) >= size)
        return -1;
    memcpy(out, it->valuestring, strlen(it->valuestring) + 1);
    return 1;
}

int sl_node_id_valid(const char *s)
{
    size_t n = 0;
    for (; s[n]; n++)
        if (n >= SL_NODE_ID_MAX ||
            !((s[n] >= 'a' && s[n] <= 'z') || (s[n] >= 'A' && s[n] <= 'Z') || (s[n] >= '0' && s[n] <= '9') ||
              s[n] == '_' || s[n] == '-'))
            return 0;
    return n > 0;
}

int sl_session_id_valid(const char *s)
{
    const char *dot = strrchr(s, '.');
    if (!dot || (size_t)(dot - s) > SL_NODE_ID_MAX || strlen(dot + 1) != SL_SESSION_HEX)
        return 0;
    char node[SL_NODE_ID_MAX + 1];
    memcpy(node, s, (size_t)(dot - s));
    node[dot - s] = '\0';
    for (const char *p = dot + 1; *p; p++)
        if (!((*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'f')))
            return 0;
    return sl_node_id_valid(node);
}

/* Integer member in [lo, hi]: 1 present and valid, 0 absent, -1 bad. */
static int get_int(const cJSON *root, const char *key, double lo, double hi, long long *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!it)
        return 0;
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble) || it->valuedouble != floor(it->valuedouble)
        || it->valuedouble < lo || it->valuedouble > hi)
        return -1;
    *out = (long long)it->valuedouble;
    return 1;
}

static int key_allowed(const msg_spec *spec, const char *key)
{
    if (strcmp(key, "type") == 0)
        return 1;
    for (int i = 0; spec->keys[i]; i++)
        if (strcmp(spec->keys[i], key) == 0)
            return 1;
    return 0;
}

sl_status sl_msg_parse(const char *text, size_t len, sl_msg *msg, char *code, char *field, sl_err *err)
{
    memset(msg, 0, sizeof *msg);
    code[0] = field[0] = '\0';
    msg->root = cJSON_ParseWithLength(text, len);
    if (!msg->root)
        return fail(msg, code, field, "bad_json", NULL, err, "message is not valid JSON%s", "");
    const cJSON *root = msg->root;
    if (!cJSON_IsObject(root))
        return fail(msg, code, field, "bad_json", NULL, err, "message must be a JSON object%s", "");
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(root, "type");
    if (!cJSON_IsString(type))
        return fail(msg, code, field, "bad_field", "type", err, "message has no string \"type\"%s", "");
    const msg_spec *spec = NULL;
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; i++)
        if (strcmp(specs[i].name, type->valuestring) == 0)
            spec = &specs[i];
    if (!spec) {
        char name[48];
        snprintf(name, sizeof name, "%s", type->valuestring);
        return fail(msg, code, field, "unknown_type", "type", err, "unknown message type \"%s\"", name);
    }
    const cJSON *it;
    cJSON_ArrayForEach(it, root) {
        if (!it->string || !key_allowed(spec, it->string)) {
            char key[SL_PROTO_ID_MAX];
            snprintf(key, sizeof key, "%s", it->string ? it->string : "");
            return fail(msg, code, field, "bad_field", key, err, "unknown key \"%s\" for this message type", key);
        }
    }
    msg->type = spec->type;
    long long v = 0;
    int r;
    switch (spec->type) {
    case SL_MSG_HELLO:
        if (get_int(root, "version", 1, 1000, &v) != 1)
            return fail(msg, code, field, "bad_field", "version", err, "hello needs an integer \"version\"%s", "");
        msg->version = (int)v;
        msg->type = SL_MSG_HELLO;
        if (get_string(root, "session", msg->session, sizeof msg->session) < 0)
            return fail(msg, code, field, "bad_field", "session", err, "\"session\" must be a string of < %s bytes", "64");
        if (msg->session[0] && !sl_session_id_valid(msg->session))
            return fail(msg, code, field, "bad_field", "session", err,
                        "\"session\" must be NODE.HEX: a node id of 1-32 [A-Za-z0-9_-], '.', %s lowercase hex digits",
                        "16");
        if (get_string(root, "token", msg->token, sizeof msg->token) < 0)
            return fail(msg, code, field, "bad_field", "token", err, "\"token\" must be a string of < %s bytes", "64");
        /* fall through: width/height are shared with resize */
        /* FALLTHROUGH */
    case SL_MSG_RESIZE: {
        const char *keys[2] = {"width", "height"};
        int *dst[2] = {&msg->width, &msg->height};
        for (int k = 0; k < 2; k++) {
            r = get_int(root, keys[k], 1, SL_PROTO_MAX_SIZE, &v);
            if (r < 0 || (r == 0 && spec->type == SL_MSG_RESIZE))
                return fail(msg, code, field, "bad_field", keys[k], err,
                            "\"%s\" must be an integer in [1, 4096]", keys[k]);
            *dst[k] = r ? (int)v : 0;
        }
        break;
    }
    case SL_MSG_CAMERA: {
        if (get_int(root, "seq", 0, 4294967295.0, &v) != 1)
            return fail(msg, code, field, "bad_field", "seq", err, "camera needs an integer \"seq\" in [0, 2^32-1]%s", "");
        msg->seq = v;
        char phase[16] = "";
        r = get_string(root, "phase", phase, sizeof phase);
        if (r < 0)
            return fail(msg, code, field, "bad_field", "phase", err, "\"phase\" must be start, move or end%s", "");
        if (r == 0)
            msg->phase = SL_PHASE_NONE;
        else if (strcmp(phase, "start") == 0)
            msg->phase = SL_PHASE_START;
        else if (strcmp(phase, "move") == 0)
            msg->phase = SL_PHASE_MOVE;
        else if (strcmp(phase, "end") == 0)
            msg->phase = SL_PHASE_END;
        else
            return fail(msg, code, field, "bad_field", "phase", err, "\"phase\" must be start, move or end%s", "");
        msg->camera = cJSON_GetObjectItemCaseSensitive(root, "camera");
        if (!cJSON_IsObject(msg->camera))
            return fail(msg, code, field, "bad_field", "camera", err, "camera needs a \"camera\" object%s", "");
        break;
    }
    case SL_MSG_SET:
    case SL_MSG_SCENE:
        msg->params = cJSON_GetObjectItemCaseSensitive(root, "params");
        if (msg->params && !cJSON_IsObject(msg->params))
            return fail(msg, code, field, "bad_field", "params", err, "\"params\" must be an object%s", "");
        if (spec->type == SL_MSG_SET) {
            msg->stream = cJSON_GetObjectItemCaseSensitive(root, "stream");
            if (msg->stream && !cJSON_IsObject(msg->stream))
                return fail(msg, code, field, "bad_field", "stream", err, "\"stream\" must be an object%s", "");
            msg->background = cJSON_GetObjectItemCaseSensitive(root, "background");
            if (msg->background) {
                int ok = cJSON_IsArray(msg->background) && cJSON_GetArraySize(msg->background) == 4;
                const cJSON *c;
                cJSON_ArrayForEach(c, msg->background)
                    ok = ok && cJSON_IsNumber(c) && c->valuedouble >= 0.0 && c->valuedouble <= 1.0;
                if (!ok)
                    return fail(msg, code, field, "bad_field", "background", err,
                                "\"background\" must be [r, g, b, a] with each in [0, 1]%s", "");
            }
            if (!msg->params && !msg->stream && !msg->background)
                return fail(msg, code, field, "bad_field", "params", err, "set needs \"params\", \"stream\" or \"background\"%s", "");
        } else {
            if (get_string(root, "dataset", msg->dataset, sizeof msg->dataset) < 0)
                return fail(msg, code, field, "bad_field", "dataset", err, "\"dataset\" must be a catalog name%s", "");
            if (get_string(root, "technique", msg->technique, sizeof msg->technique) < 0)
                return fail(msg, code, field, "bad_field", "technique", err, "\"technique\" must be a technique name%s", "");
            msg->camera = cJSON_GetObjectItemCaseSensitive(root, "camera");
            if (msg->camera && !cJSON_IsObject(msg->camera))
                return fail(msg, code, field, "bad_field", "camera", err, "\"camera\" must be an object%s", "");
            if (!msg->dataset[0] && !msg->technique[0])
                return fail(msg, code, field, "bad_field", "dataset", err, "scene needs \"dataset\" or \"technique\"%s", "");
        }
        break;
    case SL_MSG_SAVE_VIEW:
    case SL_MSG_LOAD_VIEW:
    case SL_MSG_SAVE_PATH:
    case SL_MSG_LOAD_PATH:
        if (get_string(root, "name", msg->name, sizeof msg->name) != 1 || !msg->name[0])
            return fail(msg, code, field, "bad_field", "name", err, "\"name\" must be a non-empty string of < %s bytes", "64");
        if (msg->type == SL_MSG_SAVE_PATH) {
            msg->path = cJSON_GetObjectItemCaseSensitive(root, "path");
            if (!cJSON_IsObject(msg->path))
                return fail(msg, code, field, "bad_field", "path", err, "save_path needs a \"path\" object (scene.md, Paths)%s", "");
        }
        break;
    case SL_MSG_ACK:
        if (get_int(root, "frame", 0, 4294967295.0, &v) != 1)
            return fail(msg, code, field, "bad_field", "frame", err, "ack needs an integer \"frame\"%s", "");
        msg->frame_id = (uint32_t)v;
        break;
    case SL_MSG_CONTROL: {
        char action[16] = "";
        if (get_string(root, "action", action, sizeof action) != 1)
            return fail(msg, code, field, "bad_field", "action", err, "\"action\" must be request, grant or release%s", "");
        if (strcmp(action, "request") == 0)
            msg->action = SL_CONTROL_REQUEST;
        else if (strcmp(action, "grant") == 0)
            msg->action = SL_CONTROL_GRANT;
        else if (strcmp(action, "release") == 0)
            msg->action = SL_CONTROL_RELEASE;
        else
            return fail(msg, code, field, "bad_field", "action", err, "\"action\" must be request, grant or release%s", "");
        r = get_int(root, "client", 1, 2147483647.0, &v);
        if (r < 0 || (r == 0 && msg->action == SL_CONTROL_GRANT))
            return fail(msg, code, field, "bad_field", "client", err, "grant needs an integer \"client\" id%s", "");
        msg->client = r ? (int)v : 0;
        break;
    }
    case SL_MSG_RECORD:
        msg->path = cJSON_GetObjectItemCaseSensitive(root, "path");
        if (!cJSON_IsObject(msg->path))
            return fail(msg, code, field, "bad_field", "path", err, "record needs a \"path\" object (scene.md, Paths)%s", "");
        r = get_string(root, "format", msg->format, sizeof msg->format);
        if (r < 0 || (r == 1 && strcmp(msg->format, "mp4") != 0 && strcmp(msg->format, "webm") != 0))
            return fail(msg, code, field, "bad_field", "format", err, "\"format\" must be \"mp4\" or \"webm\"%s", "");
        if (r == 0)
            snprintf(msg->format, sizeof msg->format, "mp4");
        r = get_int(root, "crf", 0, 63, &v);
        if (r < 0)
            return fail(msg, code, field, "bad_field", "crf", err, "\"crf\" must be an integer in [0, 63]%s", "");
        msg->crf = r ? (int)v : -1;
        break;
    case SL_MSG_PLAY_PATH:
    case SL_MSG_PATH_SEEK: {
        const char *what = msg->type == SL_MSG_PLAY_PATH ? "play_path" : "path_seek";
        msg->path = cJSON_GetObjectItemCaseSensitive(root, "path");
        if (!cJSON_IsObject(msg->path))
            return fail(msg, code, field, "bad_field", "path", err, "%s needs a \"path\" object (scene.md, Paths)", what);
        const cJSON *loop = cJSON_GetObjectItemCaseSensitive(root, "loop");
        if (loop && !cJSON_IsBool(loop))
            return fail(msg, code, field, "bad_field", "loop", err, "\"loop\" must be true or false%s", "");
        msg->loop = cJSON_IsTrue(loop);
        if (msg->type == SL_MSG_PATH_SEEK) {
            const cJSON *t = cJSON_GetObjectItemCaseSensitive(root, "t");
            if (!cJSON_IsNumber(t) || !isfinite(t->valuedouble) || t->valuedouble < 0 || t->valuedouble > 1e6)
                return fail(msg, code, field, "bad_field", "t", err, "path_seek needs \"t\", seconds in [0, %s]", "1e6");
            msg->t = t->valuedouble;
        }
        break;
    }
    case SL_MSG_PING:
        if (get_int(root, "seq", 0, 9007199254740991.0, &v) < 0)
            return fail(msg, code, field, "bad_field", "seq", err, "\"seq\" must be an integer%s", "");
        msg->seq = v;
        break;
    default:
        break;
    }
    return SL_OK;
}

void sl_msg_deinit(sl_msg *msg)
{
    if (!msg)
        return;
    cJSON_Delete(msg->root);
    memset(msg, 0, sizeof *msg);
}

sl_status sl_msg_camera_check(const cJSON *camera, const double (*bounds)[3], sl_camera_spec *out, sl_err *err)
{
    sl_camera_spec spec;
    sl_status st = sl_camera_json_parse(camera, &spec, err);
    if (st != SL_OK)
        return st;
    sl_vec3 lo = bounds ? sl_v3(bounds[0][0], bounds[0][1], bounds[0][2]) : sl_v3(-1, -1, -1);
    sl_vec3 hi = bounds ? sl_v3(bounds[1][0], bounds[1][1], bounds[1][2]) : sl_v3(1, 1, 1);
    if (spec.is_orbit) {
        const sl_orbit *orbit = &spec.orbit;
        if (fabs(orbit->azimuth_deg) > SL_PROTO_CAMERA_MAX_AZIMUTH)
            return sl_err_set(err, SL_ERR_INVALID, "camera.orbit.azimuth must be in [-%g, %g] degrees, got %g",
                              SL_PROTO_CAMERA_MAX_AZIMUTH, SL_PROTO_CAMERA_MAX_AZIMUTH, orbit->azimuth_deg);
        if (orbit->distance > SL_PROTO_CAMERA_MAX_DISTANCE)
            return sl_err_set(err, SL_ERR_INVALID,
                              "camera.orbit.distance must be in (0, %g] bounding-sphere radii, got %g",
                              SL_PROTO_CAMERA_MAX_DISTANCE, orbit->distance);
    } else {
        const sl_camera *c = &spec.look_at;
        const double v[6] = {c->eye.x, c->eye.y, c->eye.z, c->target.x, c->target.y, c->target.z};
        for (int i = 0; i < 6; i++)
            if (fabs(v[i]) > SL_PROTO_CAMERA_MAX_COORD)
                return sl_err_set(err, SL_ERR_INVALID, "camera.%s components must be within +-%g, got %g",
                                  i < 3 ? "eye" : "target", SL_PROTO_CAMERA_MAX_COORD, v[i]);
    }
    sl_view view;
    memset(&view, 0, sizeof view);
    if ((st = sl_camera_spec_resolve(&spec, lo, hi, &view.camera, err)) != SL_OK)
        return st;
    view.width = view.height = 1;
    view.origin = sl_v3_scale(sl_v3_add(lo, hi), 0.5);
    if ((st = sl_view_init(&view, 0.5 * sl_v3_length(sl_v3_sub(hi, lo)), err)) != SL_OK)
        return st;
    if (out)
        *out = spec;
    return SL_OK;
}

const char *sl_msg_type_name(sl_msg_type type)
{
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; i++)
        if (specs[i].type == type)
            return specs[i].name;
    return "invalid";
}

const char *sl_camera_phase_name(sl_camera_phase phase)
{
    switch (phase) {
    case SL_PHASE_START: return "start";
    case SL_PHASE_MOVE: return "move";
    case SL_PHASE_END: return "end";
    default: return "none";
    }
}

static char *print_and_free(cJSON *o)
{
    char *t = o ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    return t;
}

cJSON *sl_msg_stream_json(const sl_stream_settings *s)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "interactive_scale", s->interactive_scale);
    cJSON_AddBoolToObject(o, "interactive_adaptive", s->interactive_adaptive);
    cJSON_AddNumberToObject(o, "interactive_budget_ms", s->interactive_budget_ms);
    cJSON_AddNumberToObject(o, "interactive_quality", s->interactive_quality);
    cJSON_AddStringToObject(o, "interactive_subsampling", s->interactive_420 ? "420" : "444");
    cJSON_AddNumberToObject(o, "still_quality", s->still_quality);
    cJSON_AddStringToObject(o, "still_subsampling", s->still_420 ? "420" : "444");
    cJSON_AddNumberToObject(o, "still_delay_ms", s->still_delay_ms);
    return o;
}

sl_status sl_msg_stream_apply(sl_stream_settings *out, const cJSON *patch, char *field, sl_err *err)
{
    sl_stream_settings s = *out;
    const cJSON *it;
    field[0] = '\0';
    cJSON_ArrayForEach(it, patch) {
        const char *k = it->string ? it->string : "";
        snprintf(field, SL_PROTO_ID_MAX, "stream.%.48s", k);
        if (strcmp(k, "interactive_subsampling") == 0 || strcmp(k, "still_subsampling") == 0) {
            int v = -1;
            if (cJSON_IsString(it) && strcmp(it->valuestring, "420") == 0)
                v = 1;
            else if (cJSON_IsString(it) && strcmp(it->valuestring, "444") == 0)
                v = 0;
            if (v < 0)
                return sl_err_set(err, SL_ERR_INVALID, "%s must be \"420\" or \"444\"", k);
            *(k[0] == 'i' ? &s.interactive_420 : &s.still_420) = v;
            continue;
        }
        if (strcmp(k, "interactive_adaptive") == 0) {
            if (!cJSON_IsBool(it))
                return sl_err_set(err, SL_ERR_INVALID, "%s must be true or false", k);
            s.interactive_adaptive = cJSON_IsTrue(it);
            continue;
        }
        double lo, hi;
        if (strcmp(k, "interactive_scale") == 0) { lo = 0.1; hi = 1.0; }
        else if (strcmp(k, "interactive_quality") == 0 || strcmp(k, "still_quality") == 0) { lo = 1; hi = 100; }
        else if (strcmp(k, "still_delay_ms") == 0) { lo = 0; hi = 10000; }
        else if (strcmp(k, "interactive_budget_ms") == 0) { lo = 10; hi = 2000; }
        else
            return sl_err_set(err, SL_ERR_INVALID, "unknown stream setting \"%.48s\"", k);
        if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble) || it->valuedouble < lo || it->valuedouble > hi ||
            (strcmp(k, "interactive_scale") != 0 && it->valuedouble != floor(it->valuedouble)))
            return sl_err_set(err, SL_ERR_INVALID, "%s must be a%s number in [%g, %g]", k,
                              strcmp(k, "interactive_scale") != 0 ? "n integer" : "", lo, hi);
        if (strcmp(k, "interactive_scale") == 0) s.interactive_scale = it->valuedouble;
        else if (strcmp(k, "interactive_quality") == 0) s.interactive_quality = (int)it->valuedouble;
        else if (strcmp(k, "still_quality") == 0) s.still_quality = (int)it->valuedouble;
        else if (strcmp(k, "interactive_budget_ms") == 0) s.interactive_budget_ms = (int)it->valuedouble;
        else s.still_delay_ms = (int)it->valuedouble;
    }
    field[0] = '\0';
    *out = s;
    return SL_OK;
}

cJSON *sl_msg_state_json(const sl_msg_state *st)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "version", st->version);
    cJSON_AddStringToObject(o, "dataset", st->dataset);
    cJSON_AddStringToObject(o, "technique", st->technique);
    cJSON_AddItemToObject(o, "params", sl_params_to_json(st->params));
    cJSON *cam = sl_camera_to_json(st->camera);
    cJSON_AddItemToObject(o, "camera", cam ? cam : cJSON_CreateNull());
    cJSON_AddNumberToObject(o, "camera_seq", st->camera_seq);
    cJSON_AddNumberToObject(o, "width", st->width);
    cJSON_AddNumberToObject(o, "height", st->height);
    cJSON_AddItemToObject(o, "background", cJSON_CreateFloatArray(st->background, 4));
    cJSON_AddItemToObject(o, "stream", sl_msg_stream_json(st->stream));
    cJSON_AddNumberToObject(o, "controller", st->controller);
    cJSON_AddItemToObject(o, "bounds", st->bounds ? cJSON_Duplicate(st->bounds, 1) : cJSON_CreateNull());
    return o;
}

char *sl_msg_state_text(uint32_t version, cJSON *patch)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) {
        cJSON_Delete(patch);
        return NULL;
    }
    cJSON_AddStringToObject(o, "type", "state");
    cJSON_AddNumberToObject(o, "version", version);
    cJSON_AddItemToObject(o, "patch", patch ? patch : cJSON_CreateObject());
    return print_and_free(o);
}

char *sl_msg_welcome_text(const sl_msg_welcome *w)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "welcome");
    cJSON_AddNumberToObject(o, "version", SL_PROTO_VERSION);
    cJSON_AddStringToObject(o, "session", w->session);
    cJSON_AddStringToObject(o, "token", w->token);
    cJSON_AddStringToObject(o, "node", w->node ? w->node : "");
    cJSON_AddNumberToObject(o, "client", w->client);
    cJSON_AddStringToObject(o, "role", w->is_controller ? "controller" : "viewer");
    cJSON_AddItemToObject(o, "state", w->state ? w->state : cJSON_CreateNull());
    cJSON_AddItemToObject(o, "techniques", w->techniques ? w->techniques : cJSON_CreateArray());
    cJSON_AddItemToObject(o, "datasets", w->datasets ? w->datasets : cJSON_CreateArray());
    sl_camera_spec def = sl_camera_spec_default();
    cJSON *cam = sl_camera_to_json(&def);
    cJSON_AddItemToObject(o, "camera_default", cam ? cam : cJSON_CreateNull());
    cJSON *lim = cJSON_AddObjectToObject(o, "limits");
    cJSON_AddNumberToObject(lim, "max_message", SL_PROTO_MAX_MESSAGE);
    cJSON_AddNumberToObject(lim, "max_message_before_hello", SL_PROTO_MAX_HELLO);
    cJSON_AddNumberToObject(lim, "max_size", SL_PROTO_MAX_SIZE);
    cJSON_AddNumberToObject(lim, "ack_window", SL_PROTO_ACK_WINDOW);
    cJSON_AddNumberToObject(lim, "max_elevation", SL_ORBIT_MAX_ELEVATION);
    cJSON_AddNumberToObject(lim, "max_clients", w->max_clients);
    cJSON_AddNumberToObject(lim, "grace_s", w->grace_s);
    return print_and_free(o);
}

char *sl_msg_list_text(const char *type, const char *key, cJSON *list)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", type);
    cJSON_AddItemToObject(o, key, list ? list : cJSON_CreateArray());
    return print_and_free(o);
}

char *sl_msg_view_saved_text(const char *name)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "view_saved");
    cJSON_AddStringToObject(o, "name", name);
    return print_and_free(o);
}

char *sl_msg_playback_text(const char *state, double t, double duration, int frame, int frames, int loop,
                           const char *reason)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "playback");
    cJSON_AddStringToObject(o, "state", state);
    cJSON_AddNumberToObject(o, "t", t);
    cJSON_AddNumberToObject(o, "duration", duration);
    cJSON_AddNumberToObject(o, "frame", frame);
    cJSON_AddNumberToObject(o, "frames", frames);
    cJSON_AddBoolToObject(o, "loop", loop);
    if (reason)
        cJSON_AddStringToObject(o, "reason", reason);
    return print_and_free(o);
}

char *sl_msg_named_text(const char *type, const char *name, cJSON *path)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", type);
    cJSON_AddStringToObject(o, "name", name);
    if (path)
        cJSON_AddItemToObject(o, "path", path);
    return print_and_free(o);
}

char *sl_msg_control_request_text(int client)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "control_request");
    cJSON_AddNumberToObject(o, "client", client);
    return print_and_free(o);
}

char *sl_msg_pong_text(long long seq)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "pong");
    cJSON_AddNumberToObject(o, "seq", (double)seq);
    return print_and_free(o);
}

const char *sl_progress_stage_name(sl_progress_stage stage)
{
    static const char *const names[] = {"loading", "preparing", "first_frame", "done"};
    return (unsigned)stage < sizeof names / sizeof names[0] ? names[stage] : "unknown";
}

char *sl_msg_progress_text(const sl_msg_progress *p)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "progress");
    cJSON_AddStringToObject(o, "stage", sl_progress_stage_name(p->stage));
    cJSON_AddNumberToObject(o, "round", p->round);
    cJSON_AddNumberToObject(o, "version", p->version);
    cJSON_AddStringToObject(o, "dataset", p->dataset ? p->dataset : "");
    cJSON_AddStringToObject(o, "technique", p->technique ? p->technique : "");
    if (p->fraction >= 0 && p->fraction <= 1)
        cJSON_AddNumberToObject(o, "fraction", p->fraction);
    else
        cJSON_AddNullToObject(o, "fraction");
    cJSON_AddNumberToObject(o, "elapsed_ms", round(p->elapsed_ms * 10) / 10);
    cJSON_AddNumberToObject(o, "load_ms", round(p->load_ms * 10) / 10);
    cJSON_AddNumberToObject(o, "prepare_ms", round(p->prepare_ms * 10) / 10);
    if (p->stage == SL_PROGRESS_DONE) {
        cJSON_AddBoolToObject(o, "ok", p->ok);
        cJSON_AddNumberToObject(o, "render_ms", round(p->render_ms * 10) / 10);
        cJSON_AddNumberToObject(o, "frame", p->frame);
        if (p->backend && p->backend[0])
            cJSON_AddStringToObject(o, "backend", p->backend);
        else
            cJSON_AddNullToObject(o, "backend");
    }
    return print_and_free(o);
}

char *sl_msg_error_text(const char *code, const char *message, const char *field)
{
    return sl_msg_error_repeat_text(code, message, field, 0);
}

char *sl_msg_error_repeat_text(const char *code, const char *message, const char *field, uint32_t repeated)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "type", "error");
    cJSON_AddStringToObject(o, "code", code ? code : "error");
    cJSON_AddStringToObject(o, "message", message ? message : "");
    cJSON_AddStringToObject(o, "field", field ? field : "");
    if (repeated > 0)
        cJSON_AddNumberToObject(o, "repeated", repeated);
    char *text = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    return text;
}

static void put_u16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); }
static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)(v >> 16); p[3] = (uint8_t)(v >> 24);
}
static uint16_t get_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static void put_f32(uint8_t *p, float f) { uint32_t u; memcpy(&u, &f, 4); put_u32(p, u); }
static float get_f32(const uint8_t *p) { uint32_t u = get_u32(p); float f; memcpy(&f, &u, 4); return f; }

void sl_frame_header_write(const sl_frame_header *h, uint8_t out[SL_FRAME_HEADER_SIZE])
{
    memset(out, 0, SL_FRAME_HEADER_SIZE);
    put_u32(out + 0, SL_FRAME_MAGIC);
    put_u16(out + 4, SL_FRAME_HEADER_SIZE);
    out[6] = h->kind;
    out[7] = h->flags;
    put_u32(out + 8, h->frame_id);
    put_u32(out + 12, h->state_version);
    put_u16(out + 16, h->width);
    put_u16(out + 18, h->height);
    out[20] = h->quality;
    out[21] = h->subsampling;
    put_f32(out + 24, h->render_ms);
    put_f32(out + 28, h->encode_ms);
    put_u32(out + 32, h->camera_seq);
    put_u32(out + 36, h->payload_bytes);
}

sl_status sl_frame_header_read(const uint8_t *data, size_t size, sl_frame_header *h, sl_err *err)
{
    memset(h, 0, sizeof *h);
    if (size < SL_FRAME_HEADER_SIZE)
        return sl_err_set(err, SL_ERR_FORMAT, "frame of %zu bytes is shorter than its %d-byte header",
                          size, SL_FRAME_HEADER_SIZE);
    if (get_u32(data) != SL_FRAME_MAGIC)
        return sl_err_set(err, SL_ERR_FORMAT, "frame header magic is not SLF1");
    if (get_u16(data + 4) != SL_FRAME_HEADER_SIZE)
        return sl_err_set(err, SL_ERR_FORMAT, "frame header size %u, expected %d", get_u16(data + 4),
                          SL_FRAME_HEADER_SIZE);
    h->kind = data[6];
    if (h->kind != SL_FRAME_JPEG && h->kind != SL_FRAME_PNG)
        return sl_err_set(err, SL_ERR_FORMAT, "frame kind %u is neither JPEG (0) nor PNG (1)", h->kind);
    h->flags = data[7];
    h->frame_id = get_u32(data + 8);
    h->state_version = get_u32(data + 12);
    h->width = get_u16(data + 16);
    h->height = get_u16(data + 18);
    h->quality = data[20];
    h->subsampling = data[21];
    h->render_ms = get_f32(data + 24);
    h->encode_ms = get_f32(data + 28);
    h->camera_seq = get_u32(data + 32);
    h->payload_bytes = get_u32(data + 36);
    if ((size_t)h->payload_bytes != size - SL_FRAME_HEADER_SIZE)
        return sl_err_set(err, SL_ERR_FORMAT, "frame header says %u payload bytes, message has %zu",
                          h->payload_bytes, size - SL_FRAME_HEADER_SIZE);
    return SL_OK;
}
