/* jpeg.c — JPEG encode/decode through TurboJPEG (libturbojpeg 2.1 API; see sl_image.h).
 *
 * Encodes RGBA8 (alpha dropped) with 4:4:4 or 4:2:0 chroma; bottom_up rows
 * (glReadPixels order) are handled by TJFLAG_BOTTOMUP, so no flip copy.
 * The output buffer is malloc'd at tjBufSize() and filled with TJFLAG_NOREALLOC,
 * so callers free it with free(), never tjFree(). Decodes to RGBA8 top-down;
 * non-fatal libjpeg warnings (e.g. premature end of data) still return the
 * image, with the missing part filled by the library.
 * Does not handle CMYK output, ICC profiles or EXIF orientation.
 * Any thread: each call creates and destroys its own TurboJPEG handle.
 * Hostile input: the header's size is checked against SL_IMAGE_MAX_PIXELS
 * before allocating, and progressive scans are limited where the library can.
 */
#include "sl_image.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <turbojpeg.h>

static sl_status check_size(int width, int height, const char *what, sl_err *err)
{
    if (width <= 0 || height <= 0)
        return sl_err_set(err, SL_ERR_INVALID, "%s: image size %dx%d must be positive", what, width, height);
    if ((uint64_t)width * (uint64_t)height > SL_IMAGE_MAX_PIXELS)
        return sl_err_set(err, SL_ERR_LIMIT, "%s: image size %dx%d exceeds the limit of %u pixels",
                          what, width, height, SL_IMAGE_MAX_PIXELS);
    return SL_OK;
}

sl_status sl_jpeg_encode(const uint8_t *rgba, int width, int height, int bottom_up, int quality,
                         sl_jpeg_subsampling subsampling, uint8_t **out, size_t *out_size, sl_err *err)
{
    if (!rgba || !out || !out_size)
        return sl_err_set(err, SL_ERR_INVALID, "sl_jpeg_encode: pixels and outputs must not be NULL");
    *out = NULL;
    *out_size = 0;
    sl_status st = check_size(width, height, "sl_jpeg_encode", err);
    if (st != SL_OK)
        return st;
    if (quality < 1 || quality > 100)
        return sl_err_set(err, SL_ERR_INVALID, "sl_jpeg_encode: quality %d outside 1..100", quality);
    if (subsampling != SL_JPEG_444 && subsampling != SL_JPEG_420)
        return sl_err_set(err, SL_ERR_INVALID, "sl_jpeg_encode: unknown subsampling %d", (int)subsampling);
    int tjsamp = subsampling == SL_JPEG_444 ? TJSAMP_444 : TJSAMP_420;

    unsigned long cap = tjBufSize(width, height, tjsamp);
    if (cap == (unsigned long)-1)
        return sl_err_set(err, SL_ERR_LIMIT, "sl_jpeg_encode: %dx%d is too large for TurboJPEG", width, height);
    unsigned char *buf = malloc(cap);
    if (!buf)
        return sl_err_set(err, SL_ERR_NOMEM, "sl_jpeg_encode: out of memory for %lu output bytes", cap);
    tjhandle tj = tjInitCompress();
    if (!tj) {
        free(buf);
        return sl_err_set(err, SL_ERR_NOMEM, "sl_jpeg_encode: tjInitCompress failed: %s", tjGetErrorStr2(NULL));
    }
    unsigned long size = cap;
    int flags = TJFLAG_NOREALLOC | (bottom_up ? TJFLAG_BOTTOMUP : 0);
    if (tjCompress2(tj, rgba, width, 0, height, TJPF_RGBA, &buf, &size, tjsamp, quality, flags) != 0) {
        st = sl_err_set(err, SL_ERR_INVALID, "sl_jpeg_encode: tjCompress2 failed: %s", tjGetErrorStr2(tj));
        tjDestroy(tj);
        free(buf);
        return st;
    }
    tjDestroy(tj);
    unsigned char *shrunk = realloc(buf, size ? size : 1);
    *out = shrunk ? shrunk : buf;
    *out_size = size;
    return SL_OK;
}

sl_status sl_jpeg_write(const char *path, const uint8_t *rgba, int width, int height, int quality, sl_err *err)
{
    if (!path)
        return sl_err_set(err, SL_ERR_INVALID, "sl_jpeg_write: path must not be NULL");
    uint8_t *data = NULL;
    size_t size = 0;
    sl_status st = sl_jpeg_encode(rgba, width, height, 0, quality, SL_JPEG_444, &data, &size, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "%s", path);
        return st;
    }
    FILE *f = fopen(path, "wb");
    if (!f) {
        free(data);
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open for writing", path);
    }
    int ok = fwrite(data, 1, size, f) == size;
    free(data);
    if (fclose(f) != 0)
        ok = 0;
    if (!ok) {
        remove(path);
        return sl_err_set(err, SL_ERR_IO, "%s: write failed (disk full or I/O error)", path);
    }
    return SL_OK;
}

sl_status sl_jpeg_decode(const uint8_t *data, size_t size, sl_image *out, sl_err *err)
{
    if (!data || !out)
        return sl_err_set(err, SL_ERR_INVALID, "sl_jpeg_decode: data and output must not be NULL");
    memset(out, 0, sizeof *out);
    if (size == 0 || size > ULONG_MAX)
        return sl_err_set(err, SL_ERR_FORMAT, "sl_jpeg_decode: input of %zu bytes is not a JPEG", size);
    tjhandle tj = tjInitDecompress();
    if (!tj)
        return sl_err_set(err, SL_ERR_NOMEM, "sl_jpeg_decode: tjInitDecompress failed: %s", tjGetErrorStr2(NULL));
    sl_status st = SL_OK;
    uint8_t *pixels = NULL;
    int width = 0, height = 0, subsamp = 0, colorspace = 0;
    if (tjDecompressHeader3(tj, data, (unsigned long)size, &width, &height, &subsamp, &colorspace) != 0) {
        st = sl_err_set(err, SL_ERR_FORMAT, "sl_jpeg_decode: bad JPEG header: %s", tjGetErrorStr2(tj));
        goto done;
    }
    st = check_size(width, height, "sl_jpeg_decode", err);
    if (st != SL_OK)
        goto done;
    pixels = malloc((size_t)width * (size_t)height * 4);
    if (!pixels) {
        st = sl_err_set(err, SL_ERR_NOMEM, "sl_jpeg_decode: out of memory for %dx%d pixels", width, height);
        goto done;
    }
    int flags = 0;
#ifdef TJFLAG_LIMITSCANS
    flags |= TJFLAG_LIMITSCANS;
#endif
    if (tjDecompress2(tj, data, (unsigned long)size, pixels, width, 0, height, TJPF_RGBA, flags) != 0 &&
        tjGetErrorCode(tj) == TJERR_FATAL) {
        st = sl_err_set(err, SL_ERR_FORMAT, "sl_jpeg_decode: %s", tjGetErrorStr2(tj));
        goto done;
    }
    out->width = width;
    out->height = height;
    out->rgba = pixels;
    pixels = NULL;
done:
    free(pixels);
    tjDestroy(tj);
    return st;
}
