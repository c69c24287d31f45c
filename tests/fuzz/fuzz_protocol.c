/* fuzz_protocol.c — client text messages of one connection, before and after
 * hello (proto/sl_protocol.h), and sl_frame_header_read on the whole input.
 *
 * The input is a conversation: messages separated by '\n' (JSON needs none
 * inside a message). Each goes through what the server does with it
 * (server/net/ws.c, sessions/session.c): over SL_PROTO_MAX_HELLO bytes before hello, or
 * SL_PROTO_MAX_MESSAGE after, closes the connection; sl_msg_parse; before
 * hello a parse error or any other type closes it, a hello opens it; after
 * hello a second hello is refused, a camera goes through
 * sl_msg_camera_check, a set's stream through sl_msg_stream_apply and a
 * set's or scene's params through sl_params_apply_json of every technique
 * and of a private schema holding the types no technique uses yet (values,
 * transfer_2d).
 * Checks (abort(), so they hold in every build type): a parse gives SL_OK
 * with a type, a tree and NUL-terminated strings within their buffers, or
 * SL_ERR_INVALID with no tree, a code and a message; hello sizes within
 * SL_PROTO_MAX_SIZE; a failed stream or params patch changes nothing and
 * names its field; an applied list holds 0 to 4 values in range with zeros
 * after them, an applied 2D function passes its check with zero unused
 * widgets; a passed camera check passes again; a frame header that
 * reads matches the input's size. Single-threaded; test-only.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/sl_technique.h"
#include "sl_params_json.h"
#include "sl_protocol.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_parsed(sl_status st, const sl_msg *msg, const char *code, const char *field, const sl_err *err)
{
    if (st == SL_OK) {
        if (msg->type == SL_MSG_INVALID || msg->root == NULL)
            abort();
        if (strnlen(msg->session, sizeof msg->session) == sizeof msg->session ||
            strnlen(msg->token, sizeof msg->token) == sizeof msg->token ||
            strnlen(msg->name, sizeof msg->name) == sizeof msg->name ||
            strnlen(msg->dataset, sizeof msg->dataset) == sizeof msg->dataset ||
            strnlen(msg->technique, sizeof msg->technique) == sizeof msg->technique)
            abort();
        if ((msg->type == SL_MSG_HELLO || msg->type == SL_MSG_RESIZE) &&
            (msg->width < 0 || msg->width > SL_PROTO_MAX_SIZE || msg->height < 0 || msg->height > SL_PROTO_MAX_SIZE))
            abort();
        return;
    }
    if (st != SL_ERR_INVALID || msg->root != NULL || msg->type != SL_MSG_INVALID)
        abort();
    if (!code[0] || strnlen(code, 32) == 32 || strnlen(field, SL_PROTO_ID_MAX) == SL_PROTO_ID_MAX ||
        !err->message[0])
        abort();
}

static int stream_equal(const sl_stream_settings *a, const sl_stream_settings *b)
{
    return a->interactive_scale == b->interactive_scale && a->interactive_adaptive == b->interactive_adaptive &&
           a->interactive_budget_ms == b->interactive_budget_ms && a->interactive_quality == b->interactive_quality &&
           a->interactive_420 == b->interactive_420 && a->still_quality == b->still_quality &&
           a->still_420 == b->still_420 && a->still_delay_ms == b->still_delay_ms;
}

static void check_stream(const cJSON *patch)
{
    sl_stream_settings s = SL_STREAM_DEFAULTS, before = s;
    char field[SL_PROTO_ID_MAX];
    sl_err err = {0};
    if (sl_msg_stream_apply(&s, patch, field, &err) != SL_OK) {
        if (!stream_equal(&s, &before) || strncmp(field, "stream.", 7) != 0 || !err.message[0] ||
            strnlen(field, sizeof field) == sizeof field)
            abort();
        return;
    }
    if (field[0] || !(s.interactive_scale >= 0.1 && s.interactive_scale <= 1.0) || s.interactive_quality < 1 ||
        s.interactive_quality > 100 || s.still_quality < 1 || s.still_quality > 100 || s.still_delay_ms < 0 ||
        s.still_delay_ms > 10000 || s.interactive_budget_ms < 10 || s.interactive_budget_ms > 2000)
        abort();
}

/* The list and 2D types next to a number, for check_params. */
static const sl_param_def private_params[] = {
    {"isovalues", SL_PARAM_VALUES, -1, 2, {0}, NULL, "data", "a list", SL_INVALIDATE_PREPARED},
    {"curvature_tf", SL_PARAM_TRANSFER_2D, 0, 0, {SL_TF2D_PRESET_RIDGES_VALLEYS}, NULL, "1/voxel", "2D",
     SL_INVALIDATE_FRAME},
    {"spacing", SL_PARAM_FLOAT, 0.25, 16, {1.25}, NULL, "voxel", "a number", SL_INVALIDATE_PREPARED},
};
static const sl_technique private_technique = {
    .name = "private", .description = "fuzz-only", .params = private_params, .param_count = 3,
};

/* An applied list or 2D function keeps its invariants. */
static void check_new_types(const sl_params *p, int i)
{
    const sl_param_def *d = &p->schema[i];
    if (d->type == SL_PARAM_VALUES) {
        int n = p->value_count[i];
        if (n < 0 || n > SL_PARAM_VALUES_MAX)
            abort();
        for (int k = 0; k < SL_PARAM_VALUES_MAX; k++)
            if (k < n ? !(p->value[i][k] >= d->min && p->value[i][k] <= d->max) : p->value[i][k] != 0.0)
                abort();
    } else if (d->type == SL_PARAM_TRANSFER_2D) {
        sl_err err = {0};
        if (sl_transfer_function_2d_check(d->name, &p->tf2d, &err) != SL_OK)
            abort();
        for (int k = p->tf2d.count; k < SL_TF2D_MAX_WIDGETS; k++)
            for (int c = 0; c < 7; c++)
                if (p->tf2d.widget[k][c] != 0.0)
                    abort();
    }
}

static void check_params(const cJSON *patch)
{
    int n = 0;
    const sl_technique *const *list = sl_technique_list(&n);
    for (int t = 0; t <= n; t++) {
        const sl_technique *tech = t < n ? list[t] : &private_technique;
        sl_params p, before;
        sl_params_init(&p, tech->params, tech->param_count);
        before = p;
        sl_err err = {0};
        if (sl_params_apply_json(&p, patch, &err) != SL_OK) {
            if (p.schema != before.schema || p.count != before.count ||
                memcmp(p.value, before.value, sizeof p.value) != 0 ||
                memcmp(p.value_count, before.value_count, sizeof p.value_count) != 0 ||
                !sl_transfer_function_2d_equal(&p.tf2d, &before.tf2d) || !err.message[0])
                abort();
            continue;
        }
        for (int i = 0; i < p.count; i++) {
            const sl_param_def *d = &p.schema[i];
            check_new_types(&p, i);
            int k_count = d->type == SL_PARAM_VEC3 ? 3 : 1;
            for (int k = 0; k < k_count; k++) {
                double v = p.value[i][k];
                if (d->type == SL_PARAM_FLOAT && isnan(v)) { /* only "auto", only where the default is auto */
                    if (!sl_param_def_has_auto(d) || !sl_params_is_auto(&p, d->name))
                        abort();
                    continue;
                }
                if ((d->type == SL_PARAM_FLOAT || d->type == SL_PARAM_INT || d->type == SL_PARAM_VEC3 ||
                     d->type == SL_PARAM_ATTRIBUTE) && !(v >= d->min && v <= d->max))
                    abort();
                if (d->type == SL_PARAM_ATTRIBUTE && v != floor(v))
                    abort();
                if (d->type == SL_PARAM_BOOL && v != 0.0 && v != 1.0)
                    abort();
                if (d->type == SL_PARAM_ENUM) {
                    int choices = 0;
                    while (d->choices && d->choices[choices])
                        choices++;
                    if (!(v >= 0.0 && v < choices && v == (double)(int)v))
                        abort();
                }
            }
        }
    }
}

static void check_camera(const cJSON *camera)
{
    static const double bounds[2][3] = {{-3.0, 0.0, 1e3}, {5.0, 1e-3, 1e3 + 1.0}};
    sl_err err = {0};
    for (int b = 0; b < 2; b++) {
        const double (*box)[3] = b ? bounds : NULL;
        sl_camera_spec spec, again;
        sl_status st = sl_msg_camera_check(camera, box, &spec, &err);
        if (st != SL_OK && (st != SL_ERR_INVALID || !err.message[0]))
            abort();
        /* Accepted once, accepted again, to the same camera (compared field by field). */
        if (st == SL_OK && (sl_msg_camera_check(camera, box, &again, &err) != SL_OK || spec.is_orbit != again.is_orbit ||
                            memcmp(spec.is_orbit ? (const void *)&spec.orbit : (const void *)&spec.look_at,
                                   spec.is_orbit ? (const void *)&again.orbit : (const void *)&again.look_at,
                                   spec.is_orbit ? sizeof spec.orbit : sizeof spec.look_at) != 0))
            abort();
    }
}

/* One message of an open or opening connection; returns 0 when the server closes it. */
static int on_message(const char *text, size_t len, int *hello_done)
{
    if (len > (*hello_done ? SL_PROTO_MAX_MESSAGE : SL_PROTO_MAX_HELLO))
        return 0;
    sl_msg msg;
    char code[32], field[SL_PROTO_ID_MAX];
    sl_err err = {0};
    sl_status st = sl_msg_parse(text, len, &msg, code, field, &err);
    check_parsed(st, &msg, code, field, &err);
    int open = 1;
    if (st != SL_OK) {
        open = *hello_done;
    } else if (!*hello_done) {
        open = *hello_done = msg.type == SL_MSG_HELLO;
    } else if (msg.type == SL_MSG_CAMERA) {
        check_camera(msg.camera);
    } else if (msg.type == SL_MSG_SET) {
        if (msg.stream)
            check_stream(msg.stream);
        if (msg.params)
            check_params(msg.params);
    } else if (msg.type == SL_MSG_SCENE) {
        if (msg.params)
            check_params(msg.params);
        if (msg.camera)
            check_camera(msg.camera);
    }
    sl_msg_deinit(&msg);
    return open;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *text = (const char *)data;
    int hello_done = 0;
    size_t start = 0;
    while (start <= size) {
        const char *nl = start < size ? memchr(text + start, '\n', size - start) : NULL;
        size_t end = nl ? (size_t)(nl - text) : size;
        if (!on_message(text + start, end - start, &hello_done))
            break;
        start = end + 1;
    }
    sl_frame_header h;
    sl_err err = {0};
    if (sl_frame_header_read(data, size, &h, &err) == SL_OK &&
        (size_t)h.payload_bytes + SL_FRAME_HEADER_SIZE != size)
        abort();
    return 0;
}
