/* encoder.c — reference-counted frame buffers and the JPEG/PNG encoders.
 *
 * A frame is encoded once per render and shared by every client of the
 * session: the buffer carries LWS_PRE bytes of headroom so lws_write can
 * send it without a copy, then the 40-byte frame header, then the image.
 * JPEG goes straight from GL's bottom-up readback through TurboJPEG's
 * TJFLAG_BOTTOMUP into the buffer (no flip copy, no second buffer).
 * Does not render or send. The encoder runs on the render thread; refcounts
 * are atomic because the service thread drops references.
 */
#include "sl_render.h"

#include <stdlib.h>
#include <string.h>

#include <libwebsockets.h>
#include <turbojpeg.h>

#include "core/sl_clock.h"
#include "image/sl_image.h"

struct sl_encoder {
    tjhandle tj;
};

sl_frame_buf *sl_frame_buf_create(size_t capacity)
{
    sl_frame_buf *f = malloc(sizeof *f + LWS_PRE + capacity);
    if (!f)
        return NULL;
    memset(f, 0, sizeof *f);
    atomic_init(&f->refs, 1);
    f->data = f->mem + LWS_PRE;
    f->capacity = capacity;
    return f;
}

void sl_frame_buf_ref(sl_frame_buf *f)
{
    atomic_fetch_add(&f->refs, 1);
}

void sl_frame_buf_unref(sl_frame_buf *f)
{
    if (f && atomic_fetch_sub(&f->refs, 1) == 1)
        free(f);
}

sl_status sl_encoder_create(sl_encoder **out, sl_err *err)
{
    *out = NULL;
    sl_encoder *e = calloc(1, sizeof *e);
    if (!e)
        return sl_err_set(err, SL_ERR_NOMEM, "encoder allocation failed");
    e->tj = tjInitCompress();
    if (!e->tj) {
        free(e);
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "TurboJPEG compressor init failed: %s", tjGetErrorStr());
    }
    *out = e;
    return SL_OK;
}

void sl_encoder_destroy(sl_encoder *e)
{
    if (!e)
        return;
    if (e->tj)
        tjDestroy(e->tj);
    free(e);
}

sl_status sl_encoder_jpeg(sl_encoder *e, const uint8_t *rgba_bottom_up, int width, int height, int quality,
                          int subsampling_420, sl_frame_buf **out, double *encode_ms, sl_err *err)
{
    *out = NULL;
    int subsamp = subsampling_420 ? TJSAMP_420 : TJSAMP_444;
    unsigned long bound = tjBufSize(width, height, subsamp);
    if (bound == (unsigned long)-1)
        return sl_err_set(err, SL_ERR_INVALID, "JPEG size %dx%d is not encodable", width, height);
    sl_frame_buf *f = sl_frame_buf_create(SL_FRAME_HEADER_SIZE + bound);
    if (!f)
        return sl_err_set(err, SL_ERR_NOMEM, "cannot allocate a %lu-byte frame", bound);
    double t0 = sl_clock_ms();
    unsigned char *dst = f->data + SL_FRAME_HEADER_SIZE;
    unsigned long size = bound;
    if (tjCompress2(e->tj, rgba_bottom_up, width, 0, height, TJPF_RGBA, &dst, &size, subsamp, quality,
                    TJFLAG_BOTTOMUP | TJFLAG_NOREALLOC | TJFLAG_FASTDCT) != 0) {
        sl_frame_buf_unref(f);
        return sl_err_set(err, SL_ERR_INVALID, "JPEG encode of %dx%d failed: %s", width, height,
                          tjGetErrorStr2(e->tj));
    }
    *encode_ms = sl_clock_ms() - t0;
    f->header.kind = SL_FRAME_JPEG;
    f->header.width = (uint16_t)width;
    f->header.height = (uint16_t)height;
    f->header.quality = (uint8_t)quality;
    f->header.subsampling = subsampling_420 ? 1 : 0;
    f->header.encode_ms = (float)*encode_ms;
    f->header.payload_bytes = (uint32_t)size;
    f->size = SL_FRAME_HEADER_SIZE + size;
    *out = f;
    return SL_OK;
}

sl_status sl_encoder_png(const uint8_t *rgba_top_down, int width, int height, sl_frame_buf **out,
                         double *encode_ms, sl_err *err)
{
    *out = NULL;
    double t0 = sl_clock_ms();
    uint8_t *png = NULL;
    size_t png_size = 0;
    sl_status st = sl_png_encode(rgba_top_down, width, height, &png, &png_size, err);
    if (st)
        return st;
    sl_frame_buf *f = sl_frame_buf_create(SL_FRAME_HEADER_SIZE + png_size);
    if (!f) {
        free(png);
        return sl_err_set(err, SL_ERR_NOMEM, "cannot allocate a %zu-byte snapshot", png_size);
    }
    memcpy(f->data + SL_FRAME_HEADER_SIZE, png, png_size);
    free(png);
    *encode_ms = sl_clock_ms() - t0;
    f->header.kind = SL_FRAME_PNG;
    f->header.width = (uint16_t)width;
    f->header.height = (uint16_t)height;
    f->header.quality = 100;
    f->header.encode_ms = (float)*encode_ms;
    f->header.payload_bytes = (uint32_t)png_size;
    f->size = SL_FRAME_HEADER_SIZE + png_size;
    *out = f;
    return SL_OK;
}
