/* read_file.c — file reading and gunzip for every loader (sl_load.h,
 * load_common.h).
 *
 * sl_read_file reads a file into memory and, when it starts with the gzip
 * magic 1f 8b, inflates it. sl_load_stream reads the same content in pieces,
 * so that a loader can look at a header first and then ask for exactly the
 * bytes that header describes: nothing past them is read or inflated.
 * Does not parse any format and does not memory-map (every loader sees one
 * contiguous, owned buffer). Any thread; no GL; no global state.
 * Invariants: no buffer ever grows past what was asked for (limit + 1
 * bytes), so a gzip bomb or a lying size costs at most the limit; output
 * grows geometrically (x2), so a small stream allocates little; a stream
 * reads at most sl_load_gzip_input_bound(want) compressed bytes, so a file
 * of empty deflate blocks or a huge file behind a small header cannot keep
 * it reading. A gzip file may hold several members (concatenated gzip is
 * legal); bytes after the last member that do not start another member are
 * ignored (and not read), as gzip(1) does.
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

sl_status sl_load_read_tail(const char *path, size_t n, uint8_t **data, sl_err *err)
{
    *data = NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    sl_status st = SL_OK;
    uint8_t *buf = NULL;
    if (fstat(fileno(f), &sb) != 0) {
        st = sl_err_set(err, SL_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
        goto done;
    }
    if (!S_ISREG(sb.st_mode)) {
        st = sl_err_set(err, SL_ERR_IO, "%s: not a regular file, so it has no end to take the last %zu bytes from",
                        path, n);
        goto done;
    }
    if ((uint64_t)sb.st_size < (uint64_t)n) {
        st = sl_err_set(err, SL_ERR_FORMAT, "%s: file has %llu bytes, fewer than the %zu needed", path,
                        (unsigned long long)sb.st_size, n);
        goto done;
    }
    buf = malloc(n ? n : 1);
    if (!buf) {
        st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for %zu bytes", path, n);
        goto done;
    }
    if (fseeko(f, (off_t)((uint64_t)sb.st_size - n), SEEK_SET) != 0 || fread(buf, 1, n, f) != n) {
        st = sl_err_set(err, SL_ERR_IO, "%s: cannot read its last %zu bytes: %s", path, n,
                        ferror(f) ? strerror(errno) : "file shrank");
        goto done;
    }
    *data = buf;
    buf = NULL;
done:
    free(buf);
    fclose(f);
    return st;
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

/* ------------------------------------------------------------ streams */

#define STREAM_CHUNK (64u * 1024u)

struct sl_load_stream {
    FILE *f;
    char *path;          /* owned copy, for messages */
    int gz;              /* content is the inflated file */
    int regular;
    uint64_t file_size;  /* when regular */
    int ended;           /* the whole content is in buf */
    uint8_t *buf;        /* content so far; owned */
    size_t size, cap;
    /* gzip state */
    z_stream zs;
    int zs_ready;
    int between_members; /* a member ended; the next 2 input bytes decide */
    uint8_t *in;         /* STREAM_CHUNK bytes; in[in_pos, in_len) not yet inflated */
    size_t in_pos, in_len;
    uint64_t in_read;    /* compressed bytes read from the file so far */
    int in_eof;
};

uint64_t sl_load_gzip_input_bound(uint64_t out)
{
    /* Deflate stores incompressible data with 5 bytes per 64 KiB block and
     * gzip adds ~18 per member (bgzip: ~26 per 64 KiB member): 1/256 plus
     * 64 KiB of headers covers every real encoder with room to spare. */
    uint64_t extra = out / 256u + 65536u;
    return out > UINT64_MAX - extra ? UINT64_MAX : out + extra;
}

sl_status sl_load_stream_open(const char *path, sl_load_stream_mode mode, sl_load_stream **out, sl_err *err)
{
    *out = NULL;
    if (!path)
        return sl_err_set(err, SL_ERR_INVALID, "sl_load_stream_open: no path given");
    sl_load_stream *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", path);
    sl_status st = SL_OK;
    s->path = strdup(path);
    if (!s->path) {
        st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    s->f = fopen(path, "rb");
    if (!s->f) {
        st = sl_err_set(err, SL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
        goto fail;
    }
    struct stat sb;
    if (fstat(fileno(s->f), &sb) != 0) {
        st = sl_err_set(err, SL_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
        goto fail;
    }
    if (S_ISDIR(sb.st_mode)) {
        st = sl_err_set(err, SL_ERR_IO, "%s: is a directory, not a file", path);
        goto fail;
    }
    s->regular = S_ISREG(sb.st_mode);
    s->file_size = s->regular ? (uint64_t)sb.st_size : 0;
    if (mode != SL_STREAM_RAW) {
        s->in = malloc(STREAM_CHUNK);
        if (!s->in) {
            st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", path);
            goto fail;
        }
        s->in_len = fread(s->in, 1, 2, s->f);
        if (s->in_len < 2 && ferror(s->f)) {
            st = sl_err_set(err, SL_ERR_IO, "%s: read error: %s", path, strerror(errno));
            goto fail;
        }
        s->in_read = s->in_len;
        s->gz = s->in_len == 2 && s->in[0] == 0x1f && s->in[1] == 0x8b;
        if (mode == SL_STREAM_GZIP && !s->gz) {
            st = sl_err_set(err, SL_ERR_FORMAT, "%s: not a gzip file (no 1f 8b magic)", path);
            goto fail;
        }
        if (s->gz) {
            if (inflateInit2(&s->zs, 16 + MAX_WBITS) != Z_OK) {
                st = sl_err_set(err, SL_ERR_NOMEM, "%s: gzip: cannot initialise zlib", path);
                goto fail;
            }
            s->zs_ready = 1;
        } else {
            /* Not gzip: the two peeked bytes are content. */
            s->buf = malloc(STREAM_CHUNK);
            if (!s->buf) {
                st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", path);
                goto fail;
            }
            s->cap = STREAM_CHUNK;
            memcpy(s->buf, s->in, s->in_len);
            s->size = s->in_len;
            s->in_len = 0;
            s->ended = s->size < 2 && feof(s->f);
        }
    }
    *out = s;
    return SL_OK;
fail:
    sl_load_stream_close(s);
    return st;
}

void sl_load_stream_close(sl_load_stream *s)
{
    if (!s)
        return;
    if (s->zs_ready)
        inflateEnd(&s->zs);
    if (s->f)
        fclose(s->f);
    free(s->in);
    free(s->buf);
    free(s->path);
    free(s);
}

int sl_load_stream_gzipped(const sl_load_stream *s) { return s->gz; }

int sl_load_stream_regular(const sl_load_stream *s, uint64_t *file_size)
{
    if (file_size)
        *file_size = s->file_size;
    return s->regular;
}

/* Grows a full buf towards `want` bytes (x2 steps, never past want; a regular
 * uncompressed file never past its size + 1, enough to see its end). */
static sl_status stream_grow(sl_load_stream *s, size_t want, sl_err *err)
{
    if (s->size < s->cap || s->cap >= want)
        return SL_OK; /* room left, or as large as asked */
    size_t cap = s->cap == 0 ? STREAM_CHUNK : s->cap <= SIZE_MAX / 2 ? s->cap * 2 : SIZE_MAX;
    if (!s->gz && s->regular && s->file_size < (uint64_t)cap - 1 && s->file_size + 1 > (uint64_t)s->cap)
        cap = (size_t)s->file_size + 1;
    if (cap > want)
        cap = want;
    uint8_t *grown = realloc(s->buf, cap);
    if (!grown)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for %zu bytes", s->path, cap);
    s->buf = grown;
    s->cap = cap;
    return SL_OK;
}

/* Moves unread input to the front and reads more; in_eof at the end of the file. */
static sl_status stream_read_input(sl_load_stream *s, uint64_t want, sl_err *err)
{
    if (s->in_pos > 0) {
        memmove(s->in, s->in + s->in_pos, s->in_len - s->in_pos);
        s->in_len -= s->in_pos;
        s->in_pos = 0;
    }
    if (s->in_eof || s->in_len == STREAM_CHUNK)
        return SL_OK;
    if (s->in_read >= sl_load_gzip_input_bound(want))
        return sl_err_set(err, SL_ERR_LIMIT,
                          "%s: gzip data goes on past %llu compressed bytes, more than %llu inflated bytes can take "
                          "(%zu inflated so far)",
                          s->path, (unsigned long long)s->in_read, (unsigned long long)want, s->size);
    size_t got = fread(s->in + s->in_len, 1, STREAM_CHUNK - s->in_len, s->f);
    if (got == 0) {
        if (ferror(s->f))
            return sl_err_set(err, SL_ERR_IO, "%s: read error after %llu bytes: %s", s->path,
                              (unsigned long long)s->in_read, strerror(errno));
        s->in_eof = 1;
    }
    s->in_len += got;
    s->in_read += got;
    return SL_OK;
}

static sl_status stream_fill_gzip(sl_load_stream *s, size_t want, sl_err *err)
{
    while (s->size < want && !s->ended) {
        if (s->between_members) {
            if (s->in_len - s->in_pos < 2 && !s->in_eof) {
                sl_status st = stream_read_input(s, want, err);
                if (st != SL_OK)
                    return st;
                if (s->in_len - s->in_pos < 2 && !s->in_eof)
                    continue;
            }
            if (s->in_len - s->in_pos >= 2 && s->in[s->in_pos] == 0x1f && s->in[s->in_pos + 1] == 0x8b) {
                if (inflateReset(&s->zs) != Z_OK)
                    return sl_err_set(err, SL_ERR_FORMAT, "%s: gzip: cannot restart for the next member", s->path);
                s->between_members = 0;
                continue;
            }
            s->ended = 1; /* trailing bytes that start no member are ignored */
            break;
        }
        if (s->in_pos == s->in_len) {
            sl_status st = stream_read_input(s, want, err);
            if (st != SL_OK)
                return st;
        }
        sl_status st = stream_grow(s, want, err);
        if (st != SL_OK)
            return st;
        size_t room = (s->cap < want ? s->cap : want) - s->size; /* never past want */
        size_t out_chunk = room < UINT_MAX ? room : UINT_MAX;
        s->zs.next_in = s->in + s->in_pos;
        s->zs.avail_in = (uInt)(s->in_len - s->in_pos);
        s->zs.next_out = s->buf + s->size;
        s->zs.avail_out = (uInt)out_chunk;
        int ret = inflate(&s->zs, Z_NO_FLUSH);
        s->in_pos = s->in_len - s->zs.avail_in;
        s->size += out_chunk - s->zs.avail_out;
        if (ret == Z_STREAM_END) {
            s->between_members = 1;
            continue;
        }
        if (ret == Z_DATA_ERROR || ret == Z_NEED_DICT)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: gzip stream is corrupt near compressed byte %llu: %s", s->path,
                              (unsigned long long)(s->in_read - (s->in_len - s->in_pos)),
                              s->zs.msg ? s->zs.msg : "invalid data");
        if (ret == Z_MEM_ERROR)
            return sl_err_set(err, SL_ERR_NOMEM, "%s: gzip: zlib is out of memory", s->path);
        if (ret != Z_OK && ret != Z_BUF_ERROR)
            return sl_err_set(err, SL_ERR_FORMAT, "%s: gzip: zlib error %d", s->path, ret);
        if (s->in_eof && s->in_pos == s->in_len && s->zs.avail_out > 0)
            return sl_err_set(err, SL_ERR_FORMAT,
                              "%s: gzip stream is truncated: the file ends after %llu bytes (%zu inflated)", s->path,
                              (unsigned long long)s->in_read, s->size);
    }
    return SL_OK;
}

static sl_status stream_fill_raw(sl_load_stream *s, size_t want, sl_err *err)
{
    while (s->size < want && !s->ended) {
        sl_status st = stream_grow(s, want, err);
        if (st != SL_OK)
            return st;
        size_t got = fread(s->buf + s->size, 1, (s->cap < want ? s->cap : want) - s->size, s->f);
        s->size += got;
        if (got == 0) {
            if (ferror(s->f))
                return sl_err_set(err, SL_ERR_IO, "%s: read error after %zu bytes: %s", s->path, s->size,
                                  strerror(errno));
            s->ended = 1;
        }
    }
    return SL_OK;
}

sl_status sl_load_stream_fill(sl_load_stream *s, uint64_t want, const uint8_t **data, size_t *size, sl_err *err)
{
    size_t w = want < (uint64_t)SIZE_MAX ? (size_t)want : SIZE_MAX;
    sl_status st = s->gz ? stream_fill_gzip(s, w, err) : stream_fill_raw(s, w, err);
    *data = s->buf;
    *size = st == SL_OK ? s->size : 0;
    return st;
}

uint8_t *sl_load_stream_take(sl_load_stream *s, size_t *size)
{
    uint8_t *b = s->buf;
    *size = s->size;
    if (!b)
        b = malloc(1);
    else if (s->size + 1 < s->cap) {
        uint8_t *shrunk = realloc(b, s->size ? s->size : 1);
        if (shrunk)
            b = shrunk;
    }
    s->buf = NULL;
    s->size = s->cap = 0;
    return b;
}

sl_status sl_read_file(const char *path, uint64_t limit, uint8_t **data, size_t *size, sl_err *err)
{
    *data = NULL;
    *size = 0;
    if (!path)
        return sl_err_set(err, SL_ERR_INVALID, "sl_read_file: no path given");
    sl_load_stream *s = NULL;
    sl_status st = sl_load_stream_open(path, SL_STREAM_AUTO, &s, err);
    if (st != SL_OK)
        return st;
    if (!s->gz && s->regular && s->file_size > limit) {
        st = sl_err_set(err, SL_ERR_LIMIT, "%s: file of %llu bytes exceeds the limit of %llu bytes", path,
                        (unsigned long long)s->file_size, (unsigned long long)limit);
        goto done;
    }
    const uint8_t *p;
    size_t n;
    st = sl_load_stream_fill(s, limit < UINT64_MAX ? limit + 1 : limit, &p, &n, err);
    if (st != SL_OK)
        goto done;
    if ((uint64_t)n > limit) {
        st = sl_err_set(err, SL_ERR_LIMIT, s->gz ? "%s: gzip stream inflates past the limit of %llu bytes"
                                                 : "%s: file exceeds the limit of %llu bytes",
                        path, (unsigned long long)limit);
        goto done;
    }
    *data = sl_load_stream_take(s, size);
    if (!*data)
        st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory", path);
done:
    sl_load_stream_close(s);
    return st;
}
