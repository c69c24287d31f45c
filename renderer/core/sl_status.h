/* sl_status.h — the error convention shared by every Sightline module.
 *
 * Fallible functions return an sl_status and, on failure, fill a caller-owned
 * sl_err with one sentence: what failed, which input, which limit. Nothing in
 * the library calls exit() or abort() on bad input; assert() is kept for
 * programmer errors only. Thread-safe: an sl_err belongs to its caller.
 */
#ifndef SL_STATUS_H
#define SL_STATUS_H

#include <stdarg.h>

typedef enum sl_status {
    SL_OK = 0,
    SL_ERR_INVALID,     /* bad argument or malformed input (JSON, parameter, file) */
    SL_ERR_IO,          /* a file could not be opened, read or written */
    SL_ERR_FORMAT,      /* a file is truncated, corrupt or of an unsupported variant */
    SL_ERR_LIMIT,       /* a size limit would be exceeded (allocation, count, message) */
    SL_ERR_NOMEM,       /* an allocation failed */
    SL_ERR_GPU,         /* EGL/GL failure: no display, no context, compile/link error */
    SL_ERR_UNSUPPORTED  /* valid request that this build or device cannot serve */
} sl_status;

#define SL_ERR_MSG_MAX 1024

typedef struct sl_err {
    sl_status status;
    char message[SL_ERR_MSG_MAX];
} sl_err;

/* Records status and a printf-style message in err (err may be NULL);
 * returns status so callers can write `return sl_err_set(err, ...)`. */
sl_status sl_err_set(sl_err *err, sl_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Prefixes the message already in err with "prefix: ". */
void sl_err_prefix(sl_err *err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

void sl_err_clear(sl_err *err);

/* A short stable name for a status ("invalid", "io", ...), used in JSON errors. */
const char *sl_status_name(sl_status status);

#endif
