/* read_file.c — whole-file reading and gunzip for every loader (sl_load.h).
 *
 * sl_read_file reads a file into memory and, when it starts with the gzip
 * magic 1f 8b, inflates it. Does not parse any format and does not
 * memory-map (every loader sees one contiguous, owned buffer). Any thread;
 * no GL; no global state. Invariants: no buffer ever grows past limit + 1
 * bytes, so a gzip bomb or a lying size costs at most the limit; output
 * grows geometrically (x2), so a small stream allocates little. A gzip file
 * may hold several members (concatenated gzip is legal); bytes after the
 * last member that do not start another member are ignored, as gzip(1) does.
 */
#include "load_common.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <zlib.h>

sl_status sl_load_read_raw(const char *path, uint64_t limit, uint8_t **data, size_t *size, sl_err *err)
{
    *data = NULL;
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) != 0) {
        int e = errno;
        fclose(f);
        return sl_err_set(err, SL_ERR_IO, "%s: cannot stat: %s", path, strerror(e));
    }
    if (S_ISDIR(st.st_mode)) {
        fclose(f);
        return sl_err_set(err, SL_ERR_IO, "%s: is a directory, not a file", path);
    }
    if (S_ISREG(st.st_mode) && (uint64_t)st.st_size > limit) {
        fclose(f);
        return sl_err_set(err, SL_ERR_LIMIT, "%s: file of %llu bytes exceeds the limit of %llu bytes", path,
                          (unsigned long long)st.st_size, (unsigned long long)limit);
    }
    size_t cap_max = limit < (uint64_t)SIZE_MAX ? (size_t)limit + 1 : SIZE_MAX;
    size_t cap = S_ISREG(st.st_mode) ? (size_t)st.st_size + 1 : 65536;
    if (cap > cap_max)
        cap = cap_max;
    uint8_t *buf = malloc(cap ? cap : 1);
    size_t n = 0;
    sl_status st_out = SL_OK;
    if (!buf) {
        st_out = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for %zu bytes", path, cap);
        goto fail;
    }
    for (;;) {
        if (n == cap) {
            if (cap >= cap_max)
                break;
            size_t grown_cap = cap > cap_max / 2 ? cap_max : cap * 2;
            uint8_t *grown = realloc(buf, grown_cap);
            if (!grown) {
                st_out = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for %zu bytes", path, grown_cap);
                goto fail;
            }
            buf = grown;
            cap = grown_cap;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) {
            if (ferror(f)) {
                st_out = sl_err_set(err, SL_ERR_IO, "%s: read error after %zu bytes: %s", path, n, strerror(errno));
                goto fail;
            }
            break;
        }
    }
    if ((uint64_t)n > limit) {
        st_out = sl_err_set(err, SL_ERR_LIMIT, "%s: file exceeds the limit of %llu bytes", path,
                            (unsigned long long)limit);
        goto fail;
    }
    fclose(f);
    *data = buf;
    *size = n;
    return SL_OK;
fail:
    free(buf);
    fclose(f);
    return st_out;
}

sl_status sl_gunzip(const uint8_t *data, size_t size, uint64_t limit, uint8_t **out, size_t *out_size, sl_err *err)
{
    *out = NULL;
    *out_size = 0;
    if (size < 18 || data[0] != 0x1f || data[1] != 0x8b)
        return sl_err_set(err, SL_ERR_FORMAT, "gzip stream of %zu bytes has no gzip header (1f 8b) or is too short",
                          size);
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK)
        return sl_err_set(err, SL_ERR_NOMEM, "gzip: cannot initialise zlib");
    size_t cap_max = limit < (uint64_t)SIZE_MAX ? (size_t)limit + 1 : SIZE_MAX;
    size_t cap = size < SIZE_MAX / 4 ? size * 4 : SIZE_MAX;
    if (cap < 4096)
        cap = 4096;
    if (cap > cap_max)
        cap = cap_max;
    uint8_t *buf = malloc(cap ? cap : 1);
    size_t n = 0, in_pos = 0;
    sl_status st = SL_OK;
    if (!buf) {
        st = sl_err_set(err, SL_ERR_NOMEM, "gzip: out of memory for %zu bytes", cap);
        goto done;
    }
    for (;;) {
        if (n == cap) {
            if (cap >= cap_max) {
                st = sl_err_set(err, SL_ERR_LIMIT, "gzip stream inflates past the limit of %llu bytes",
                                (unsigned long long)limit);
                goto done;
            }
            size_t grown_cap = cap > cap_max / 2 ? cap_max : cap * 2;
            uint8_t *grown = realloc(buf, grown_cap);
            if (!grown) {
                st = sl_err_set(err, SL_ERR_NOMEM, "gzip: out of memory for %zu bytes", grown_cap);
                goto done;
            }
            buf = grown;
            cap = grown_cap;
        }
        size_t in_chunk = size - in_pos < UINT_MAX ? size - in_pos : UINT_MAX;
        size_t out_chunk = cap - n < UINT_MAX ? cap - n : UINT_MAX;
        zs.next_in = (Bytef *)(uintptr_t)(data + in_pos);
        zs.avail_in = (uInt)in_chunk;
        zs.next_out = buf + n;
        zs.avail_out = (uInt)out_chunk;
        int ret = inflate(&zs, Z_NO_FLUSH);
        in_pos += in_chunk - zs.avail_in;
        n += out_chunk - zs.avail_out;
        if ((uint64_t)n > limit) {
            st = sl_err_set(err, SL_ERR_LIMIT, "gzip stream inflates past the limit of %llu bytes",
                            (unsigned long long)limit);
            goto done;
        }
        if (ret == Z_STREAM_END) {
            /* Another member follows only when its magic does. */
            if (size - in_pos >= 2 && data[in_pos] == 0x1f && data[in_pos + 1] == 0x8b) {
                if (inflateReset(&zs) != Z_OK) {
                    st = sl_err_set(err, SL_ERR_FORMAT, "gzip: cannot restart for the member at byte %zu", in_pos);
                    goto done;
                }
                continue;
            }
            break;
        }
        if (ret == Z_DATA_ERROR || ret == Z_NEED_DICT) {
            st = sl_err_set(err, SL_ERR_FORMAT, "gzip stream is corrupt near input byte %zu: %s", in_pos,
                            zs.msg ? zs.msg : "invalid data");
            goto done;
        }
        if (ret == Z_MEM_ERROR) {
            st = sl_err_set(err, SL_ERR_NOMEM, "gzip: zlib is out of memory");
            goto done;
        }
        if (ret != Z_OK && ret != Z_BUF_ERROR) {
            st = sl_err_set(err, SL_ERR_FORMAT, "gzip: zlib error %d near input byte %zu", ret, in_pos);
            goto done;
        }
        if (in_pos == size && zs.avail_out > 0) {
            st = sl_err_set(err, SL_ERR_FORMAT, "gzip stream is truncated: input ends after %zu bytes (%zu inflated)",
                            size, n);
            goto done;
        }
    }
    if (n + 1 < cap) {
        uint8_t *shrunk = realloc(buf, n ? n : 1);
        if (shrunk)
            buf = shrunk;
    }
    *out = buf;
    *out_size = n;
    buf = NULL;
done:
    inflateEnd(&zs);
    free(buf);
    return st;
}

sl_status sl_read_file(const char *path, uint64_t limit, uint8_t **data, size_t *size, sl_err *err)
{
    *data = NULL;
    *size = 0;
    if (!path)
        return sl_err_set(err, SL_ERR_INVALID, "sl_read_file: no path given");
    uint8_t *raw = NULL;
    size_t raw_size = 0;
    sl_status st = sl_load_read_raw(path, limit, &raw, &raw_size, err);
    if (st != SL_OK)
        return st;
    if (raw_size >= 2 && raw[0] == 0x1f && raw[1] == 0x8b) {
        st = sl_gunzip(raw, raw_size, limit, data, size, err);
        free(raw);
        if (st != SL_OK)
            sl_err_prefix(err, "%s", path);
        return st;
    }
    *data = raw;
    *size = raw_size;
    return SL_OK;
}
