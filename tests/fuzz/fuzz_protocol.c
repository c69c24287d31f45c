/* fuzz_protocol.c — sl_msg_parse (client messages) and sl_frame_header_read on arbitrary bytes.
 *
 * Any input must give SL_OK or SL_ERR_INVALID/FORMAT with a code and field
 * that are NUL-terminated within their buffers, never a crash, leak or
 * over-read; a parsed message's borrowed pointers must lie in its own tree.
 * The proto library is not linked into fuzz targets, so its one source file
 * is compiled in here.
 */
#include "../../proto/sl_protocol.c"

#include <assert.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sl_msg msg;
    char code[32], field[SL_PROTO_ID_MAX];
    sl_err err;
    sl_status st = sl_msg_parse((const char *)data, size, &msg, code, field, &err);
    if (st == SL_OK) {
        assert(msg.type != SL_MSG_INVALID && msg.root != NULL);
        assert(strlen(msg.session) < sizeof msg.session && strlen(msg.name) < sizeof msg.name);
        if (msg.type == SL_MSG_HELLO || msg.type == SL_MSG_RESIZE)
            assert(msg.width >= 0 && msg.width <= SL_PROTO_MAX_SIZE && msg.height <= SL_PROTO_MAX_SIZE);
    } else {
        assert(st == SL_ERR_INVALID && msg.root == NULL);
        assert(strlen(code) < 32 && strlen(field) < SL_PROTO_ID_MAX && code[0]);
    }
    sl_msg_deinit(&msg);
    sl_frame_header h;
    st = sl_frame_header_read(data, size, &h, &err);
    if (st == SL_OK)
        assert((size_t)h.payload_bytes + SL_FRAME_HEADER_SIZE == size);
    return 0;
}
