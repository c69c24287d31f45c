/* sl_protocol.c — parse client messages, build error messages, pack frame headers.
 *
 * Each message type has a table of allowed keys; anything else is a
 * "bad_field" naming the key, so a typo never silently does nothing. Only
 * syntax and ranges are checked here (see sl_protocol.h for what is not).
 * Any thread; no allocation beyond the cJSON tree the message owns.
 */
#include "sl_protocol.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

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
        if (get_string(root, "name", msg->name, sizeof msg->name) != 1 || !msg->name[0])
            return fail(msg, code, field, "bad_field", "name", err, "\"name\" must be a non-empty string of < %s bytes", "64");
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

char *sl_msg_error_text(const char *code, const char *message, const char *field)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "type", "error");
    cJSON_AddStringToObject(o, "code", code ? code : "error");
    cJSON_AddStringToObject(o, "message", message ? message : "");
    cJSON_AddStringToObject(o, "field", field ? field : "");
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
