/* load_test_util.h — helpers shared by the loader unit tests: a growable
 * byte buffer to write test files in memory (with explicit byte order), and
 * checks every loader result must satisfy (status and *out agree, a
 * dataset's offsets and bounds are consistent, reconstruction of world
 * coordinates). Test-only; single thread.
 */
#ifndef SL_LOAD_TEST_UTIL_H
#define SL_LOAD_TEST_UTIL_H

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_load.h"
#include "sl_test.h"

typedef struct tbuf {
    uint8_t *data;
    size_t size, cap;
} tbuf;

static inline void tb_put(tbuf *b, const void *p, size_t n)
{
    if (b->size + n > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->size + n)
            cap *= 2;
        uint8_t *d = realloc(b->data, cap);
        if (!d) {
            fprintf(stderr, "test: out of memory\n");
            exit(2);
        }
        b->data = d;
        b->cap = cap;
    }
    if (n)
        memcpy(b->data + b->size, p, n);
    b->size += n;
}

static inline void tb_printf(tbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static inline void tb_printf(tbuf *b, const char *fmt, ...)
{
    char tmp[4096];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    tb_put(b, tmp, (size_t)n);
}

/* Writes an n-byte integer/float representation in the given byte order. */
static inline void tb_bytes(tbuf *b, const void *native, size_t n, int big_endian)
{
    uint8_t t[8];
    memcpy(t, native, n);
    const uint16_t probe = 1;
    int host_be = *(const uint8_t *)&probe == 0;
    if (host_be != big_endian)
        for (size_t i = 0; i < n / 2; i++) {
            uint8_t x = t[i];
            t[i] = t[n - 1 - i];
            t[n - 1 - i] = x;
        }
    tb_put(b, t, n);
}

static inline void tb_f32(tbuf *b, float v, int be) { tb_bytes(b, &v, 4, be); }
static inline void tb_f64(tbuf *b, double v, int be) { tb_bytes(b, &v, 8, be); }
static inline void tb_i32(tbuf *b, int32_t v, int be) { tb_bytes(b, &v, 4, be); }
static inline void tb_i16(tbuf *b, int16_t v, int be) { tb_bytes(b, &v, 2, be); }
static inline void tb_u16(tbuf *b, uint16_t v, int be) { tb_bytes(b, &v, 2, be); }

static inline void tb_free(tbuf *b)
{
    free(b->data);
    memset(b, 0, sizeof *b);
}

/* Overwrites 4 bytes at offset with an int32 in the given byte order. */
static inline void tb_set_i32(tbuf *b, size_t off, int32_t v, int be)
{
    tbuf t = {0};
    tb_i32(&t, v, be);
    memcpy(b->data + off, t.data, 4);
    tb_free(&t);
}

static inline void tb_set_i16(tbuf *b, size_t off, int16_t v, int be)
{
    tbuf t = {0};
    tb_i16(&t, v, be);
    memcpy(b->data + off, t.data, 2);
    tb_free(&t);
}

/* Runs a loader and checks the universal contract: status and *out agree,
 * an error has a message naming the input, and a line set is consistent. */
static inline sl_status run_loader(sl_loader_fn fn, const uint8_t *data, size_t size, const char *path,
                            sl_dataset **out, sl_err *err)
{
    *out = (sl_dataset *)(uintptr_t)1; /* must be overwritten */
    sl_err_clear(err);
    sl_status st = fn(data, size, path, out, err);
    if (st != SL_OK) {
        SL_CHECK_MSG(*out == NULL, "failed load left *out set");
        SL_CHECK_MSG(err->status == st && err->message[0] != '\0', "status %d without message", (int)st);
        if (path)
            SL_CHECK_MSG(strstr(err->message, path) != NULL, "message does not name the file: %s", err->message);
        return st;
    }
    SL_CHECK(*out != NULL);
    if (*out && (*out)->kind == SL_DATASET_LINES) {
        const sl_lines *l = &(*out)->lines;
        int ok = l->line_offsets[0] == 0 && l->line_offsets[l->line_count] == l->vertex_count;
        for (size_t k = 0; k < l->line_count; k++)
            ok = ok && l->line_offsets[k] <= l->line_offsets[k + 1];
        SL_CHECK_MSG(ok, "inconsistent line offsets");
    }
    return st;
}

/* World coordinate c of vertex v. */
static inline double world(const sl_dataset *ds, size_t v, int c)
{
    double o = c == 0 ? ds->origin.x : c == 1 ? ds->origin.y : ds->origin.z;
    return o + (double)ds->lines.positions[3 * v + c];
}

/* Brute-force range of n floats (finite only), compared with an attribute's. */
static inline void check_range(const sl_attribute *a, size_t n)
{
    double lo = 1e300, hi = -1e300;
    for (size_t i = 0; i < n; i++) {
        double x = a->values[i];
        if (x == x && x < 1e300 && x > -1e300) {
            if (x < lo) lo = x;
            if (x > hi) hi = x;
        }
    }
    if (lo > hi)
        lo = hi = 0.0;
    SL_CHECK_NEAR(a->min, lo, 0.0);
    SL_CHECK_NEAR(a->max, hi, 0.0);
}

#endif
