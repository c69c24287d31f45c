/* sl_status.c — formatting of sl_err messages (see sl_status.h). */
#include "sl_status.h"

#include <stdio.h>
#include <string.h>

sl_status sl_err_set(sl_err *err, sl_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}

void sl_err_prefix(sl_err *err, const char *fmt, ...)
{
    if (!err)
        return;
    char prefix[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    /* Shift the old message right and write "prefix: " in front of it,
     * truncating the tail when the two do not fit together. The prefix
     * (< 256 bytes) always fits in the message (1024 bytes). */
    _Static_assert(sizeof prefix + 2 < SL_ERR_MSG_MAX, "prefix must fit");
    size_t cap = sizeof err->message;
    size_t plen = strlen(prefix);
    size_t head = plen + 2;
    size_t tail = strnlen(err->message, cap - 1);
    if (head + tail > cap - 1)
        tail = cap - 1 - head;
    memmove(err->message + head, err->message, tail);
    err->message[head + tail] = '\0';
    memcpy(err->message, prefix, plen);
    memcpy(err->message + plen, ": ", 2);
}

void sl_err_clear(sl_err *err)
{
    if (err) {
        err->status = SL_OK;
        err->message[0] = '\0';
    }
}

const char *sl_status_name(sl_status status)
{
    switch (status) {
    case SL_OK: return "ok";
    case SL_ERR_INVALID: return "invalid";
    case SL_ERR_IO: return "io";
    case SL_ERR_FORMAT: return "format";
    case SL_ERR_LIMIT: return "limit";
    case SL_ERR_NOMEM: return "nomem";
    case SL_ERR_GPU: return "gpu";
    case SL_ERR_UNSUPPORTED: return "unsupported";
    }
    return "unknown";
}
