/* png.c — PNG files and in-memory PNG through libpng (see sl_image.h).
 *
 * Writes RGBA8, 8 bits per channel, non-interlaced, default zlib level.
 * Reads every colour type and bit depth and converts to RGBA8 with libpng's
 * transforms (palette/grey/tRNS expansion, 16 -> 8 bit scaling, filler alpha).
 * Does not read or write colour-management chunks (gAMA, iCCP): pixels are
 * taken as stored. Any thread; no global state.
 *
 * Error handling: libpng reports errors through png_error -> longjmp. Every
 * resource (FILE, png structs, pixel buffer, output buffer) is owned by a
 * context struct that lives in the caller's frame and is only reached through
 * a pointer from the function that calls setjmp, so nothing read after the
 * longjmp is an indeterminate local; the caller frees the context on one path.
 * Hostile headers: width*height is checked against SL_IMAGE_MAX_PIXELS, and
 * when the input size is known the raw data size is checked against the
 * deflate ceiling (1032:1) before the pixel buffer is allocated.
 */
#include "sl_image.h"

#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* deflate cannot expand better than ~1032:1; allow a margin and a constant. */
#define SL_PNG_MAX_INFLATE_RATIO 1100u
#define SL_PNG_INFLATE_SLACK 65536u

typedef struct png_ctx {
    png_structp png;
    png_infop info;
    FILE *file;                 /* owned when non-NULL */
    const uint8_t *src;         /* decode from memory: borrowed input */
    size_t src_size, src_pos;
    uint8_t *buf;               /* encode: output buffer; decode: pixels */
    size_t size, cap;           /* encode: bytes used / allocated */
    uint64_t input_size;        /* decode: input bytes, 0 = unknown */
    const char *what;           /* the path or "(memory)" for messages */
    char message[256];          /* libpng's error text */
} png_ctx;

static void on_png_error(png_structp png, png_const_charp msg)
{
    png_ctx *ctx = png_get_error_ptr(png);
    snprintf(ctx->message, sizeof ctx->message, "%s", msg ? msg : "unknown libpng error");
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;          /* warnings (e.g. known-bad sRGB profiles) are not failures */
}

static sl_status check_size(int width, int height, const char *what, sl_err *err)
{
    if (width <= 0 || height <= 0)
        return sl_err_set(err, SL_ERR_INVALID, "%s: image size %dx%d must be positive", what, width, height);
    if ((uint64_t)width * (uint64_t)height > SL_IMAGE_MAX_PIXELS)
        return sl_err_set(err, SL_ERR_LIMIT, "%s: image size %dx%d exceeds the limit of %u pixels",
                          what, width, height, SL_IMAGE_MAX_PIXELS);
    return SL_OK;
}

/* ---- writing ---------------------------------------------------------- */

static void write_to_file(png_structp png, png_bytep data, size_t length)
{
    png_ctx *ctx = png_get_io_ptr(png);
    if (fwrite(data, 1, length, ctx->file) != length)
        png_error(png, "write failed (disk full or I/O error)");
}

static void write_to_memory(png_structp png, png_bytep data, size_t length)
{
    png_ctx *ctx = png_get_io_ptr(png);
    if (length > SIZE_MAX - ctx->size)
        png_error(png, "output larger than addressable memory");
    if (ctx->size + length > ctx->cap) {
        size_t cap = ctx->cap ? ctx->cap : 4096;
        while (cap < ctx->size + length)
            cap = cap > SIZE_MAX / 2 ? ctx->size + length : cap * 2;
        uint8_t *grown = realloc(ctx->buf, cap);
        if (!grown)
            png_error(png, "out of memory growing the output buffer");
        ctx->buf = grown;
        ctx->cap = cap;
    }
    memcpy(ctx->buf + ctx->size, data, length);
    ctx->size += length;
}

static void flush_file(png_structp png)
{
    png_ctx *ctx = png_get_io_ptr(png);
    if (fflush(ctx->file) != 0)
        png_error(png, "flush failed");
}

static void flush_nothing(png_structp png)
{
    (void)png;
}

/* Runs the encoder; on libpng error returns 0 with ctx->message set. */
static int run_encode(png_ctx *ctx, const uint8_t *rgba, int width, int height, int to_file)
{
    if (setjmp(png_jmpbuf(ctx->png)))
        return 0;
    png_set_write_fn(ctx->png, ctx, to_file ? write_to_file : write_to_memory,
                     to_file ? flush_file : flush_nothing);
    png_set_IHDR(ctx->png, ctx->info, (png_uint_32)width, (png_uint_32)height, 8,
                 PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(ctx->png, ctx->info);
    size_t stride = (size_t)width * 4;
    for (int y = 0; y < height; y++)
        png_write_row(ctx->png, (png_const_bytep)(rgba + (size_t)y * stride));
    png_write_end(ctx->png, NULL);
    return 1;
}

static sl_status encode(png_ctx *ctx, const uint8_t *rgba, int width, int height, int to_file, sl_err *err)
{
    ctx->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, ctx, on_png_error, on_png_warning);
    if (!ctx->png)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: cannot create the libpng writer", ctx->what);
    ctx->info = png_create_info_struct(ctx->png);
    if (!ctx->info)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: cannot create the libpng info struct", ctx->what);
    if (!run_encode(ctx, rgba, width, height, to_file))
        return sl_err_set(err, strstr(ctx->message, "emory") ? SL_ERR_NOMEM : SL_ERR_IO,
                          "%s: PNG encoding failed: %s", ctx->what, ctx->message);
    return SL_OK;
}

sl_status sl_png_write(const char *path, const uint8_t *rgba, int width, int height, sl_err *err)
{
    if (!path || !rgba)
        return sl_err_set(err, SL_ERR_INVALID, "sl_png_write: path and pixels must not be NULL");
    sl_status st = check_size(width, height, path, err);
    if (st != SL_OK)
        return st;
    png_ctx ctx = {.what = path};
    ctx.file = fopen(path, "wb");
    if (!ctx.file)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open for writing", path);
    st = encode(&ctx, rgba, width, height, 1, err);
    png_destroy_write_struct(&ctx.png, &ctx.info);
    if (fclose(ctx.file) != 0 && st == SL_OK)
        st = sl_err_set(err, SL_ERR_IO, "%s: close failed after writing", path);
    if (st != SL_OK)
        remove(path);
    return st;
}

sl_status sl_png_encode(const uint8_t *rgba, int width, int height, uint8_t **out, size_t *out_size, sl_err *err)
{
    if (!rgba || !out || !out_size)
        return sl_err_set(err, SL_ERR_INVALID, "sl_png_encode: pixels and outputs must not be NULL");
    *out = NULL;
    *out_size = 0;
    sl_status st = check_size(width, height, "sl_png_encode", err);
    if (st != SL_OK)
        return st;
    png_ctx ctx = {.what = "sl_png_encode"};
    st = encode(&ctx, rgba, width, height, 0, err);
    png_destroy_write_struct(&ctx.png, &ctx.info);
    if (st != SL_OK) {
        free(ctx.buf);
        return st;
    }
    *out = ctx.buf;
    *out_size = ctx.size;
    return SL_OK;
}

/* ---- reading ---------------------------------------------------------- */

static void read_from_file(png_structp png, png_bytep data, size_t length)
{
    png_ctx *ctx = png_get_io_ptr(png);
    if (fread(data, 1, length, ctx->file) != length)
        png_error(png, ferror(ctx->file) ? "read error" : "file is truncated (unexpected end of file)");
}

static void read_from_memory(png_structp png, png_bytep data, size_t length)
{
    png_ctx *ctx = png_get_io_ptr(png);
    if (length > ctx->src_size - ctx->src_pos)
        png_error(png, "data is truncated (unexpected end of input)");
    memcpy(data, ctx->src + ctx->src_pos, length);
    ctx->src_pos += length;
}

/* Runs the decoder into ctx->buf. Returns SL_OK, or the failure status with
 * the reason in ctx->message (libpng errors arrive here through longjmp). */
static sl_status run_decode(png_ctx *ctx, int *width, int *height)
{
    if (setjmp(png_jmpbuf(ctx->png)))
        return strstr(ctx->message, "emory") ? SL_ERR_NOMEM : SL_ERR_FORMAT;
    png_read_info(ctx->png, ctx->info);

    png_uint_32 w = 0, h = 0;
    int depth = 0, colour = 0, interlace = 0;
    png_get_IHDR(ctx->png, ctx->info, &w, &h, &depth, &colour, &interlace, NULL, NULL);
    if (w > 0x7fffffffu || h > 0x7fffffffu || (uint64_t)w * h > SL_IMAGE_MAX_PIXELS) {
        snprintf(ctx->message, sizeof ctx->message, "size %ux%u exceeds the limit of %u pixels",
                 (unsigned)w, (unsigned)h, SL_IMAGE_MAX_PIXELS);
        return SL_ERR_LIMIT;
    }
    if (ctx->input_size) {
        int channels = png_get_channels(ctx->png, ctx->info);
        uint64_t raw = ((uint64_t)w * (uint64_t)channels * (uint64_t)depth + 7) / 8 + 1;
        raw *= h;
        if (raw > ctx->input_size * SL_PNG_MAX_INFLATE_RATIO + SL_PNG_INFLATE_SLACK) {
            snprintf(ctx->message, sizeof ctx->message, "header claims %ux%u pixels (%llu raw bytes), "
                     "more than %llu file bytes can hold after decompression",
                     (unsigned)w, (unsigned)h, (unsigned long long)raw,
                     (unsigned long long)ctx->input_size);
            return SL_ERR_FORMAT;
        }
    }

    png_set_expand(ctx->png);                  /* palette -> RGB, grey < 8 bit -> 8, tRNS -> alpha */
    png_set_scale_16(ctx->png);                /* 16 -> 8 bit, rounded */
    if (colour == PNG_COLOR_TYPE_GRAY || colour == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(ctx->png);
    if (!(colour & PNG_COLOR_MASK_ALPHA) && !png_get_valid(ctx->png, ctx->info, PNG_INFO_tRNS))
        png_set_add_alpha(ctx->png, 0xff, PNG_FILLER_AFTER);
    int passes = png_set_interlace_handling(ctx->png);
    png_read_update_info(ctx->png, ctx->info);
    if (png_get_rowbytes(ctx->png, ctx->info) != (size_t)w * 4)
        png_error(ctx->png, "unexpected row size after conversion to RGBA8");

    ctx->buf = malloc((size_t)w * (size_t)h * 4);
    if (!ctx->buf)
        png_error(ctx->png, "out of memory for the pixel buffer");
    size_t stride = (size_t)w * 4;
    for (int pass = 0; pass < passes; pass++)
        for (png_uint_32 y = 0; y < h; y++)
            png_read_row(ctx->png, ctx->buf + (size_t)y * stride, NULL);
    png_read_end(ctx->png, NULL);
    *width = (int)w;
    *height = (int)h;
    return SL_OK;
}

/* Checks the signature, creates the reader and decodes into out. The input
 * (ctx->file or ctx->src) is set up by the caller, who also frees ctx. */
static sl_status decode(png_ctx *ctx, png_rw_ptr reader, sl_image *out, sl_err *err)
{
    uint8_t sig[8];
    ctx->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, ctx, on_png_error, on_png_warning);
    ctx->info = ctx->png ? png_create_info_struct(ctx->png) : NULL;
    if (!ctx->png || !ctx->info)
        return sl_err_set(err, SL_ERR_NOMEM, "%s: cannot create the libpng reader", ctx->what);
    png_set_read_fn(ctx->png, ctx, reader);
    int sig_ok = 0;
    if (ctx->file)
        sig_ok = fread(sig, 1, sizeof sig, ctx->file) == sizeof sig;
    else if (ctx->src_size >= sizeof sig) {
        memcpy(sig, ctx->src, sizeof sig);
        ctx->src_pos = sizeof sig;
        sig_ok = 1;
    }
    if (!sig_ok || png_sig_cmp(sig, 0, sizeof sig) != 0)
        return sl_err_set(err, SL_ERR_FORMAT, "%s: not a PNG file (bad signature)", ctx->what);
    png_set_sig_bytes(ctx->png, sizeof sig);
    int w = 0, h = 0;
    sl_status st = run_decode(ctx, &w, &h);
    if (st != SL_OK)
        return sl_err_set(err, st, "%s: cannot read PNG: %s", ctx->what, ctx->message);
    out->width = w;
    out->height = h;
    out->rgba = ctx->buf;
    ctx->buf = NULL;
    return SL_OK;
}

sl_status sl_png_read(const char *path, sl_image *out, sl_err *err)
{
    if (!path || !out)
        return sl_err_set(err, SL_ERR_INVALID, "sl_png_read: path and output must not be NULL");
    memset(out, 0, sizeof *out);
    png_ctx ctx = {.what = path};
    ctx.file = fopen(path, "rb");
    if (!ctx.file)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot open for reading", path);
    struct stat sb;
    if (fstat(fileno(ctx.file), &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0)
        ctx.input_size = (uint64_t)sb.st_size;
    sl_status st = decode(&ctx, read_from_file, out, err);
    png_destroy_read_struct(&ctx.png, &ctx.info, NULL);
    free(ctx.buf);
    fclose(ctx.file);
    return st;
}

sl_status sl_png_decode(const uint8_t *data, size_t size, sl_image *out, sl_err *err)
{
    if (!out || (!data && size))
        return sl_err_set(err, SL_ERR_INVALID, "sl_png_decode: output must not be NULL");
    memset(out, 0, sizeof *out);
    png_ctx ctx = {.what = "(memory)", .src = data, .src_size = size, .input_size = size};
    sl_status st = decode(&ctx, read_from_memory, out, err);
    png_destroy_read_struct(&ctx.png, &ctx.info, NULL);
    free(ctx.buf);
    return st;
}
