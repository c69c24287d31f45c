/* pfm.c — PFM (portable float map) depth images (see sl_image.h).
 *
 * Writes "Pf\n<w> <h>\n-1\n" then little-endian float32 rows bottom-up, as
 * the format requires; in memory rows are top-down, so writer and reader flip.
 * Reads "Pf" (grey) and "PF" (RGB, first channel kept). The sign of the scale
 * gives the byte order (negative = little-endian); its magnitude is ignored
 * (values are returned as stored). No comments in the header, exactly one
 * whitespace byte after the scale, and the data must fill the rest of the
 * input exactly. Any thread; no global state.
 * Hostile input: every header token is bounded, sizes are parsed with
 * overflow checks, width*height*channels*4 is compared with the bytes present
 * before anything is allocated, so a lying header costs nothing.
 */
#include "sl_image.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define SL_PFM_TOKEN_MAX 64     /* longest header token accepted */
#define SL_PFM_HEADER_MAX 256   /* longest header accepted */

typedef struct pfm_cursor {
    const uint8_t *data;
    size_t size, pos;
} pfm_cursor;

static int is_space(uint8_t c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n';
}

/* Copies the next whitespace-delimited token into tok (NUL-terminated).
 * Returns 0 at end of input or when the token is longer than the buffer. */
static int next_token(pfm_cursor *c, char tok[SL_PFM_TOKEN_MAX])
{
    while (c->pos < c->size && is_space(c->data[c->pos]))
        c->pos++;
    size_t n = 0;
    while (c->pos < c->size && !is_space(c->data[c->pos])) {
        if (n + 1 >= SL_PFM_TOKEN_MAX)
            return 0;
        tok[n++] = (char)c->data[c->pos++];
    }
    tok[n] = '\0';
    return n > 0;
}

static sl_status parse_dimension(const char *tok, const char *name, int *out, const char *what, sl_err *err)
{
    if (tok[0] == '-')
        return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM %s is negative (%s)", what, name, tok);
    uint64_t v = 0;
    for (const char *p = tok; *p; p++) {
        if (*p < '0' || *p > '9')
            return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM %s is not a decimal number (\"%s\")", what, name, tok);
        v = v * 10 + (uint64_t)(*p - '0');
        if (v > INT_MAX)
            return sl_err_set(err, SL_ERR_LIMIT, "%s: PFM %s %s exceeds %d", what, name, tok, INT_MAX);
    }
    if (v == 0)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM %s is zero", what, name);
    *out = (int)v;
    return SL_OK;
}

static float load_float(const uint8_t *p, int little_endian)
{
    uint32_t u = little_endian
        ? (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24
        : (uint32_t)p[3] | (uint32_t)p[2] << 8 | (uint32_t)p[1] << 16 | (uint32_t)p[0] << 24;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static sl_status parse(const uint8_t *data, size_t size, sl_depth_image *out, const char *what, sl_err *err)
{
    pfm_cursor c = {.data = data, .size = size < SL_PFM_HEADER_MAX ? size : SL_PFM_HEADER_MAX};
    if (size < 2 || data[0] != 'P' || (data[1] != 'f' && data[1] != 'F'))
        return sl_err_set(err, SL_ERR_FORMAT, "%s: not a PFM file (expected \"Pf\" or \"PF\" magic)", what);
    int channels = data[1] == 'F' ? 3 : 1;
    c.pos = 2;
    if (c.pos >= c.size || !is_space(data[c.pos]))
        return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM magic must be followed by whitespace", what);

    char wtok[SL_PFM_TOKEN_MAX], htok[SL_PFM_TOKEN_MAX], stok[SL_PFM_TOKEN_MAX];
    if (!next_token(&c, wtok) || !next_token(&c, htok) || !next_token(&c, stok))
        return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM header is truncated or malformed "
                          "(need width, height and scale within %d bytes)", what, SL_PFM_HEADER_MAX);
    int width = 0, height = 0;
    sl_status st = parse_dimension(wtok, "width", &width, what, err);
    if (st == SL_OK)
        st = parse_dimension(htok, "height", &height, what, err);
    if (st != SL_OK)
        return st;
    char *end = NULL;
    errno = 0;
    double scale = strtod(stok, &end);
    if (end == stok || *end != '\0' || errno == ERANGE || !isfinite(scale) || scale == 0.0)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM scale \"%s\" must be a finite non-zero number", what, stok);
    if (c.pos >= c.size || !is_space(data[c.pos]))
        return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM header must end with one whitespace byte after the scale", what);
    size_t header = c.pos + 1;

    uint64_t pixels = (uint64_t)width * (uint64_t)height;
    if (pixels > SL_IMAGE_MAX_PIXELS)
        return sl_err_set(err, SL_ERR_LIMIT, "%s: PFM size %dx%d exceeds the limit of %u pixels",
                          what, width, height, SL_IMAGE_MAX_PIXELS);
    uint64_t need = pixels * (uint64_t)channels * 4u;
    uint64_t have = (uint64_t)(size - header);
    if (have != need)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: PFM %dx%d with %d channel(s) needs %llu data bytes, file has %llu%s",
                          what, width, height, channels, (unsigned long long)need, (unsigned long long)have,
                          have < need ? " (truncated)" : " (trailing bytes)");

    float *values = malloc((size_t)pixels * sizeof *values);
    if (!values)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for a %dx%d depth image", what, width, height);
    int little = scale < 0.0;
    const uint8_t *src = data + header;
    size_t stride = (size_t)width * (size_t)channels * 4;
    for (int row = 0; row < height; row++) {             /* file row 0 is the bottom */
        const uint8_t *s = src + (size_t)row * stride;
        float *d = values + (size_t)(height - 1 - row) * (size_t)width;
        for (int x = 0; x < width; x++)
            d[x] = load_float(s + (size_t)x * (size_t)channels * 4, little);
    }
    out->width = width;
    out->height = height;
    out->values = values;
    return SL_OK;
}

sl_status sl_pfm_parse(const uint8_t *data, size_t size, sl_depth_image *out, sl_err *err)
{
    if (!out || (!data && size))
        return sl_err_set(err, SL_ERR_INVALID, "sl_pfm_parse: output must not be NULL");
    memset(out, 0, sizeof *out);
    return parse(data, size, out, "(memory)", err);
}

sl_status sl_pfm_read(const char *path, sl_depth_image *out, sl_err *err)
{
    if (!path || !out)
        return sl_err_set(err, SL_ERR_INVALID, "sl_pfm_read: path and output must not be NULL");
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open for reading", path);
    sl_status st = SL_OK;
    uint8_t *buf = NULL;
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode)) {
        st = sl_err_set(err, SL_ERR_IO, "%s: not a regular file", path);
        goto done;
    }
    uint64_t max_size = SL_PFM_HEADER_MAX + (uint64_t)SL_IMAGE_MAX_PIXELS * 3u * 4u;
    if ((uint64_t)sb.st_size > max_size || (uint64_t)sb.st_size > SIZE_MAX) {
        st = sl_err_set(err, SL_ERR_LIMIT, "%s: file of %lld bytes exceeds the PFM limit of %llu bytes",
                        path, (long long)sb.st_size, (unsigned long long)max_size);
        goto done;
    }
    size_t size = (size_t)sb.st_size;
    buf = malloc(size ? size : 1);
    if (!buf) {
        st = sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory reading %zu bytes", path, size);
        goto done;
    }
    if (fread(buf, 1, size, f) != size) {
        st = sl_err_set(err, SL_ERR_IO, "%s: read failed", path);
        goto done;
    }
    st = parse(buf, size, out, path, err);
done:
    free(buf);
    fclose(f);
    return st;
}

sl_status sl_pfm_write(const char *path, const float *values, int width, int height, sl_err *err)
{
    if (!path || !values)
        return sl_err_set(err, SL_ERR_INVALID, "sl_pfm_write: path and values must not be NULL");
    if (width <= 0 || height <= 0)
        return sl_err_set(err, SL_ERR_INVALID, "%s: PFM size %dx%d must be positive", path, width, height);
    if ((uint64_t)width * (uint64_t)height > SL_IMAGE_MAX_PIXELS)
        return sl_err_set(err, SL_ERR_LIMIT, "%s: PFM size %dx%d exceeds the limit of %u pixels",
                          path, width, height, SL_IMAGE_MAX_PIXELS);
    uint8_t *row = malloc((size_t)width * 4);
    if (!row)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: out of memory for a row buffer", path);
    FILE *f = fopen(path, "wb");
    if (!f) {
        free(row);
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open for writing", path);
    }
    int ok = fprintf(f, "Pf\n%d %d\n-1\n", width, height) > 0;
    for (int y = height - 1; ok && y >= 0; y--) {         /* bottom row first */
        const float *src = values + (size_t)y * (size_t)width;
        for (int x = 0; x < width; x++) {
            uint32_t u;
            memcpy(&u, &src[x], sizeof u);
            uint8_t *d = row + (size_t)x * 4;
            d[0] = (uint8_t)u;
            d[1] = (uint8_t)(u >> 8);
            d[2] = (uint8_t)(u >> 16);
            d[3] = (uint8_t)(u >> 24);
        }
        ok = fwrite(row, 4, (size_t)width, f) == (size_t)width;
    }
    free(row);
    if (fclose(f) != 0)
        ok = 0;
    if (!ok) {
        remove(path);
        return sl_err_set(err, SL_ERR_IO, "%s: write failed (disk full or I/O error)", path);
    }
    return SL_OK;
}
