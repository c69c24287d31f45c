/* test_image.c — PNG, PFM and JPEG files (renderer/image/png.c, pfm.c, jpeg.c).
 *
 * Round trips must be exact (PNG, PFM), including PFM row order (the file is
 * bottom-up, memory top-down). PNG files of other colour types are written
 * here with libpng directly and their RGBA8 conversion is checked against the
 * PNG specification's rules. JPEG at quality 95, 4:4:4 must decode with a mean
 * absolute error below 3 (0..255) on a smooth image; bottom_up must equal a
 * flipped top-down buffer byte for byte. Hostile inputs must fail with the
 * right status and leave the output zeroed. Temporary files go to a mkdtemp
 * folder under /tmp that is removed at the end. Single-threaded.
 */
#include <png.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "image/sl_image.h"
#include "sl_test.h"

static char tmpdir[64];

static const char *tmp_path(const char *name)
{
    static char buf[8][256];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 256, "%s/%s", tmpdir, name);
    return p;
}

static uint32_t rng = 12345u;
static uint32_t rand_u32(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

static int write_bytes(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    int ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok;
}

static uint8_t *read_bytes(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *buf = malloc(n > 0 ? (size_t)n : 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    *size = (size_t)n;
    return buf;
}

static int is_zeroed(const sl_image *img)
{
    return img->width == 0 && img->height == 0 && img->rgba == NULL;
}

static int depth_is_zeroed(const sl_depth_image *img)
{
    return img->width == 0 && img->height == 0 && img->values == NULL;
}

/* ---- PNG ---------------------------------------------------------------- */

static void test_png_round_trip(void)
{
    const int w = 37, h = 23;
    uint8_t *rgba = malloc((size_t)w * h * 4);
    for (int i = 0; i < w * h * 4; i++)
        rgba[i] = (uint8_t)rand_u32();
    sl_err err = {0};
    const char *path = tmp_path("round.png");
    SL_CHECK(sl_png_write(path, rgba, w, h, &err) == SL_OK);
    sl_image img = {0};
    SL_CHECK_MSG(sl_png_read(path, &img, &err) == SL_OK, "%s", err.message);
    SL_CHECK(img.width == w && img.height == h);
    SL_CHECK(img.rgba && memcmp(img.rgba, rgba, (size_t)w * h * 4) == 0);
    sl_image_deinit(&img);
    SL_CHECK(is_zeroed(&img));
    sl_image_deinit(&img);                      /* idempotent */

    /* The in-memory encoder produces the same bytes as the file writer. */
    uint8_t *mem = NULL;
    size_t mem_size = 0, file_size = 0;
    SL_CHECK(sl_png_encode(rgba, w, h, &mem, &mem_size, &err) == SL_OK);
    uint8_t *file = read_bytes(path, &file_size);
    SL_CHECK(mem && file && mem_size == file_size && memcmp(mem, file, mem_size) == 0);
    SL_CHECK(mem && sl_png_decode(mem, mem_size, &img, &err) == SL_OK);
    SL_CHECK(img.width == w && img.height == h && img.rgba && memcmp(img.rgba, rgba, (size_t)w * h * 4) == 0);
    sl_image_deinit(&img);
    free(mem);
    free(file);
    free(rgba);
}

typedef struct png_spec {
    int width, height, bit_depth, colour_type, interlace;
    const png_color *palette;
    int palette_size;
    const uint8_t *trns;
    int trns_size;
} png_spec;

/* Writes raw rows (already in the file's sample format) with libpng directly. */
static int write_png_raw(const char *path, const png_spec *s, uint8_t *const *rows)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        fclose(f);
        return 0;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)s->width, (png_uint_32)s->height, s->bit_depth, s->colour_type,
                 s->interlace, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (s->palette)
        png_set_PLTE(png, info, s->palette, s->palette_size);
    if (s->trns)
        png_set_tRNS(png, info, s->trns, s->trns_size, NULL);
    png_write_info(png, info);
    png_write_image(png, (png_bytepp)rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return fclose(f) == 0;
}

static void test_png_colour_types(void)
{
    enum { W = 6, H = 4 };
    sl_err err = {0};
    sl_image img = {0};
    uint8_t rowbuf[H][W * 8];
    uint8_t *rows[H];
    for (int y = 0; y < H; y++)
        rows[y] = rowbuf[y];

    /* 8-bit grey: g -> (g, g, g, 255). */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            rowbuf[y][x] = (uint8_t)(y * 60 + x * 7);
    png_spec grey = {W, H, 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, NULL, 0, NULL, 0};
    SL_CHECK(write_png_raw(tmp_path("grey.png"), &grey, rows));
    SL_CHECK_MSG(sl_png_read(tmp_path("grey.png"), &img, &err) == SL_OK, "%s", err.message);
    int ok = img.width == W && img.height == H;
    for (int y = 0; ok && y < H; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *p = img.rgba + (y * W + x) * 4;
            uint8_t g = (uint8_t)(y * 60 + x * 7);
            ok &= p[0] == g && p[1] == g && p[2] == g && p[3] == 255;
        }
    SL_CHECK_MSG(ok, "8-bit grey not expanded to (g, g, g, 255)");
    sl_image_deinit(&img);

    /* 4-bit grey: v (0..15) -> v * 17. */
    memset(rowbuf, 0, sizeof rowbuf);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int v = (y * W + x) % 16;
            rowbuf[y][x / 2] |= (uint8_t)(x % 2 ? v : v << 4);
        }
    png_spec grey4 = {W, H, 4, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, NULL, 0, NULL, 0};
    SL_CHECK(write_png_raw(tmp_path("grey4.png"), &grey4, rows));
    SL_CHECK_MSG(sl_png_read(tmp_path("grey4.png"), &img, &err) == SL_OK, "%s", err.message);
    ok = img.width == W && img.height == H;
    for (int y = 0; ok && y < H; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *p = img.rgba + (y * W + x) * 4;
            uint8_t g = (uint8_t)(((y * W + x) % 16) * 17);
            ok &= p[0] == g && p[1] == g && p[2] == g && p[3] == 255;
        }
    SL_CHECK_MSG(ok, "4-bit grey not scaled by 17");
    sl_image_deinit(&img);

    /* Palette with tRNS: index -> palette colour, alpha from tRNS (255 beyond it). */
    static const png_color pal[4] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {10, 20, 30}};
    static const uint8_t trns[2] = {0, 128};
    memset(rowbuf, 0, sizeof rowbuf);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            rowbuf[y][x] = (uint8_t)((x + y) % 4);
    png_spec palette = {W, H, 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE, pal, 4, trns, 2};
    SL_CHECK(write_png_raw(tmp_path("palette.png"), &palette, rows));
    SL_CHECK_MSG(sl_png_read(tmp_path("palette.png"), &img, &err) == SL_OK, "%s", err.message);
    ok = img.width == W && img.height == H;
    for (int y = 0; ok && y < H; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *p = img.rgba + (y * W + x) * 4;
            int i = (x + y) % 4;
            ok &= p[0] == pal[i].red && p[1] == pal[i].green && p[2] == pal[i].blue &&
                  p[3] == (i < 2 ? trns[i] : 255);
        }
    SL_CHECK_MSG(ok, "palette + tRNS not expanded to RGBA");
    sl_image_deinit(&img);

    /* 16-bit RGBA, big-endian samples v8 * 257 -> exactly v8; 0x1234 -> round(0x1234 / 257.0) = 18. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 4; c++) {
                unsigned v = (unsigned)((x * 40 + y * 9 + c * 50) % 256) * 257u;
                if (x == 0 && y == 0 && c == 0)
                    v = 0x1234;
                rowbuf[y][(x * 4 + c) * 2] = (uint8_t)(v >> 8);
                rowbuf[y][(x * 4 + c) * 2 + 1] = (uint8_t)v;
            }
    png_spec rgba16 = {W, H, 16, PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE, NULL, 0, NULL, 0};
    SL_CHECK(write_png_raw(tmp_path("rgba16.png"), &rgba16, rows));
    SL_CHECK_MSG(sl_png_read(tmp_path("rgba16.png"), &img, &err) == SL_OK, "%s", err.message);
    ok = img.width == W && img.height == H;
    for (int y = 0; ok && y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 4; c++) {
                int want = (x * 40 + y * 9 + c * 50) % 256;
                if (x == 0 && y == 0 && c == 0)
                    want = 18;
                ok &= img.rgba[(y * W + x) * 4 + c] == want;
            }
    SL_CHECK_MSG(ok, "16-bit RGBA not scaled to 8 bits with rounding");
    sl_image_deinit(&img);

    /* 8-bit RGB, Adam7-interlaced: alpha 255 added, all passes assembled. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++)
                rowbuf[y][x * 3 + c] = (uint8_t)(x * 30 + y * 50 + c * 11);
    png_spec rgb = {W, H, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_ADAM7, NULL, 0, NULL, 0};
    SL_CHECK(write_png_raw(tmp_path("rgb.png"), &rgb, rows));
    SL_CHECK_MSG(sl_png_read(tmp_path("rgb.png"), &img, &err) == SL_OK, "%s", err.message);
    ok = img.width == W && img.height == H;
    for (int y = 0; ok && y < H; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *p = img.rgba + (y * W + x) * 4;
            for (int c = 0; c < 3; c++)
                ok &= p[c] == (uint8_t)(x * 30 + y * 50 + c * 11);
            ok &= p[3] == 255;
        }
    SL_CHECK_MSG(ok, "interlaced RGB not read as RGBA with alpha 255");
    sl_image_deinit(&img);

    /* Grey + alpha 8-bit: (g, a) -> (g, g, g, a). */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            rowbuf[y][x * 2] = (uint8_t)(x * 40);
            rowbuf[y][x * 2 + 1] = (uint8_t)(y * 80);
        }
    png_spec ga = {W, H, 8, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_NONE, NULL, 0, NULL, 0};
    SL_CHECK(write_png_raw(tmp_path("ga.png"), &ga, rows));
    SL_CHECK_MSG(sl_png_read(tmp_path("ga.png"), &img, &err) == SL_OK, "%s", err.message);
    ok = img.width == W && img.height == H;
    for (int y = 0; ok && y < H; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *p = img.rgba + (y * W + x) * 4;
            ok &= p[0] == x * 40 && p[1] == x * 40 && p[2] == x * 40 && p[3] == y * 80;
        }
    SL_CHECK_MSG(ok, "grey+alpha not expanded");
    sl_image_deinit(&img);
}

static void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

/* A PNG holding signature, IHDR (w x h, 8-bit RGBA), an empty IDAT and IEND, valid CRCs. */
static size_t make_header_only_png(uint8_t *buf, uint32_t w, uint32_t h)
{
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    memcpy(buf, sig, 8);
    put_be32(buf + 8, 13);
    memcpy(buf + 12, "IHDR", 4);
    put_be32(buf + 16, w);
    put_be32(buf + 20, h);
    buf[24] = 8;                /* bit depth */
    buf[25] = 6;                /* RGBA */
    buf[26] = buf[27] = buf[28] = 0;
    put_be32(buf + 29, (uint32_t)crc32(0, buf + 12, 17));
    for (int i = 0; i < 2; i++) {
        uint8_t *c = buf + 33 + i * 12;
        put_be32(c, 0);
        memcpy(c + 4, i == 0 ? "IDAT" : "IEND", 4);
        put_be32(c + 8, (uint32_t)crc32(0, c + 4, 4));
    }
    return 57;
}

static void test_png_hostile(void)
{
    sl_err err = {0};
    sl_image img = {0};
    const int w = 40, h = 30;
    uint8_t *rgba = malloc((size_t)w * h * 4);
    for (int i = 0; i < w * h * 4; i++)
        rgba[i] = (uint8_t)rand_u32();
    uint8_t *png = NULL;
    size_t size = 0;
    SL_CHECK(sl_png_encode(rgba, w, h, &png, &size, &err) == SL_OK);
    free(rgba);

    /* Truncations at several points: header, mid-IDAT, before IEND. */
    const size_t cuts[] = {0, 4, 8, 20, 33, 50, size / 2, size - 13, size - 1};
    for (size_t i = 0; png && i < sizeof cuts / sizeof cuts[0]; i++) {
        SL_CHECK(write_bytes(tmp_path("trunc.png"), png, cuts[i]));
        memset(&img, 0x5a, sizeof img);
        sl_status st = sl_png_read(tmp_path("trunc.png"), &img, &err);
        SL_CHECK_MSG(st == SL_ERR_FORMAT, "cut at %zu: status %d (%s)", cuts[i], st, err.message);
        SL_CHECK(is_zeroed(&img));
        memset(&img, 0x5a, sizeof img);
        st = sl_png_decode(png, cuts[i], &img, &err);
        SL_CHECK_MSG(st == SL_ERR_FORMAT, "decode cut at %zu: status %d (%s)", cuts[i], st, err.message);
        SL_CHECK(is_zeroed(&img));
    }
    /* A flipped byte inside IDAT breaks the CRC or the zlib stream. */
    if (png && size > 60) {
        png[size / 2] ^= 0xff;
        SL_CHECK(write_bytes(tmp_path("corrupt.png"), png, size));
        SL_CHECK(sl_png_read(tmp_path("corrupt.png"), &img, &err) == SL_ERR_FORMAT);
        SL_CHECK(is_zeroed(&img));
    }
    free(png);

    /* A header claiming 16000 x 16000 in a 57-byte file: rejected before allocating. */
    uint8_t buf[64];
    size_t n = make_header_only_png(buf, 16000, 16000);
    SL_CHECK(write_bytes(tmp_path("liar.png"), buf, n));
    SL_CHECK_MSG(sl_png_read(tmp_path("liar.png"), &img, &err) == SL_ERR_FORMAT, "%s", err.message);
    SL_CHECK(strstr(err.message, "16000x16000") != NULL);
    SL_CHECK(sl_png_decode(buf, n, &img, &err) == SL_ERR_FORMAT && is_zeroed(&img));
    /* Beyond SL_IMAGE_MAX_PIXELS: a limit error. */
    n = make_header_only_png(buf, 20000, 20000);
    SL_CHECK(write_bytes(tmp_path("huge.png"), buf, n));
    SL_CHECK_MSG(sl_png_read(tmp_path("huge.png"), &img, &err) == SL_ERR_LIMIT, "%s", err.message);
    /* A tiny header-only PNG passes the header checks and fails on missing IDAT. */
    n = make_header_only_png(buf, 2, 2);
    SL_CHECK(write_bytes(tmp_path("noidat.png"), buf, n));
    SL_CHECK(sl_png_read(tmp_path("noidat.png"), &img, &err) == SL_ERR_FORMAT);
    SL_CHECK(is_zeroed(&img));

    SL_CHECK(write_bytes(tmp_path("text.png"), "hello, not a png", 16));
    SL_CHECK(sl_png_read(tmp_path("text.png"), &img, &err) == SL_ERR_FORMAT);
    SL_CHECK(sl_png_read(tmp_path("missing.png"), &img, &err) == SL_ERR_IO);
    SL_CHECK(sl_png_read(tmpdir, &img, &err) != SL_OK);            /* a directory */

    uint8_t px[4] = {0};
    SL_CHECK(sl_png_write(tmp_path("zero.png"), px, 0, 1, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_png_write(tmp_path("neg.png"), px, 1, -1, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_png_write(tmp_path("big.png"), px, 20000, 20000, &err) == SL_ERR_LIMIT);
    SL_CHECK(sl_png_write("/nonexistent-dir/x.png", px, 1, 1, &err) == SL_ERR_IO);
    uint8_t *out = (uint8_t *)1;
    SL_CHECK(sl_png_encode(px, -5, 1, &out, &size, &err) == SL_ERR_INVALID && out == NULL);
}

/* ---- PFM ---------------------------------------------------------------- */

static void test_pfm_round_trip(void)
{
    enum { W = 5, H = 3 };
    float v[W * H];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            v[y * W + x] = (float)(y * 1000 + x) + 0.25f;
    v[1] = 0.0f;                      /* background */
    v[2] = 1e-30f;                    /* denormal-ish magnitudes survive */
    v[3] = 3.0e38f;
    sl_err err = {0};
    const char *path = tmp_path("round.pfm");
    SL_CHECK(sl_pfm_write(path, v, W, H, &err) == SL_OK);

    /* The file: exact header, then the bottom row (y = H-1) first, little-endian. */
    size_t size = 0;
    uint8_t *file = read_bytes(path, &size);
    const char *header = "Pf\n5 3\n-1\n";
    size_t hl = strlen(header);
    SL_CHECK(file && size == hl + W * H * 4);
    SL_CHECK(file && memcmp(file, header, hl) == 0);
    if (file && size == hl + W * H * 4) {
        float bottom_left = (float)((H - 1) * 1000) + 0.25f, got;
        uint32_t u = (uint32_t)file[hl] | (uint32_t)file[hl + 1] << 8 | (uint32_t)file[hl + 2] << 16 |
                     (uint32_t)file[hl + 3] << 24;
        memcpy(&got, &u, sizeof got);
        SL_CHECK_MSG(got == bottom_left, "first stored value %g, want %g (bottom row first)", got, bottom_left);
    }
    free(file);

    sl_depth_image img = {0};
    SL_CHECK_MSG(sl_pfm_read(path, &img, &err) == SL_OK, "%s", err.message);
    SL_CHECK(img.width == W && img.height == H);
    SL_CHECK(img.values && memcmp(img.values, v, sizeof v) == 0);
    SL_CHECK(img.values && img.values[0] == 0.25f && img.values[4] == 4.25f);   /* top row is row 0 */
    sl_depth_image_deinit(&img);
    SL_CHECK(depth_is_zeroed(&img));
}

static void put_be_float(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_be32(p, u);
}

static void test_pfm_big_endian_colour(void)
{
    /* "PF", 2 x 2, scale +1 (big-endian); file rows bottom-up; keep channel 0. */
    const char *header = "PF\n2 2\n1.0\n";
    size_t hl = strlen(header);
    uint8_t buf[64];
    memcpy(buf, header, hl);
    const float file_rows[2][2][3] = {
        {{1.5f, 9.f, 9.f}, {2.5f, 9.f, 9.f}},     /* bottom row */
        {{3.5f, 9.f, 9.f}, {-4.5f, 9.f, 9.f}},    /* top row */
    };
    uint8_t *p = buf + hl;
    for (int r = 0; r < 2; r++)
        for (int x = 0; x < 2; x++)
            for (int c = 0; c < 3; c++, p += 4)
                put_be_float(p, file_rows[r][x][c]);
    size_t size = (size_t)(p - buf);

    sl_err err = {0};
    sl_depth_image img = {0};
    SL_CHECK_MSG(sl_pfm_parse(buf, size, &img, &err) == SL_OK, "%s", err.message);
    SL_CHECK(img.width == 2 && img.height == 2);
    SL_CHECK(img.values && img.values[0] == 3.5f && img.values[1] == -4.5f &&
             img.values[2] == 1.5f && img.values[3] == 2.5f);
    sl_depth_image_deinit(&img);

    SL_CHECK(write_bytes(tmp_path("be.pfm"), buf, size));
    SL_CHECK_MSG(sl_pfm_read(tmp_path("be.pfm"), &img, &err) == SL_OK, "%s", err.message);
    SL_CHECK(img.values && img.values[0] == 3.5f && img.values[3] == 2.5f);
    sl_depth_image_deinit(&img);

    /* Any whitespace between header tokens; CRLF is one byte short, so "\r\n" after the scale fails. */
    const char *spaced = "Pf 1\t1 -2.0\n";
    uint8_t one[32];
    memcpy(one, spaced, strlen(spaced));
    memcpy(one + strlen(spaced), "\x00\x00\x80\x3f", 4);            /* 1.0f little-endian */
    SL_CHECK_MSG(sl_pfm_parse(one, strlen(spaced) + 4, &img, &err) == SL_OK, "%s", err.message);
    SL_CHECK(img.values && img.values[0] == 1.0f);
    sl_depth_image_deinit(&img);
}

static sl_status parse_text(const char *header, size_t data_bytes, sl_depth_image *img, sl_err *err)
{
    size_t hl = strlen(header);
    uint8_t *buf = calloc(1, hl + data_bytes + 1);
    memcpy(buf, header, hl);
    memset(img, 0x5a, sizeof *img);
    sl_status st = sl_pfm_parse(buf, hl + data_bytes, img, err);
    free(buf);
    return st;
}

static void test_pfm_hostile(void)
{
    sl_err err = {0};
    sl_depth_image img = {0};
    struct {
        const char *header;
        size_t data;
        sl_status want;
        const char *why;
    } cases[] = {
        {"Pf\n2 2\n-1\n", 15, SL_ERR_FORMAT, "truncated by one byte"},
        {"Pf\n2 2\n-1\n", 17, SL_ERR_FORMAT, "one trailing byte"},
        {"Pf\n2 2\n-1\n", 0, SL_ERR_FORMAT, "header only"},
        {"PF\n2 2\n-1\n", 16, SL_ERR_FORMAT, "PF needs three channels"},
        {"Pf\n4294967296 4294967296\n-1\n", 16, SL_ERR_LIMIT, "dimensions beyond int"},
        {"Pf\n2147483647 2147483647\n-1\n", 16, SL_ERR_LIMIT, "width*height beyond the pixel limit"},
        {"Pf\n65536 65536\n-1\n", 16, SL_ERR_LIMIT, "width*height = 2^32 (32-bit overflow to 0)"},
        {"Pf\n99999999999999999999999999 1\n-1\n", 4, SL_ERR_LIMIT, "width overflows 64 bits"},
        {"Pf\n-2 2\n-1\n", 16, SL_ERR_FORMAT, "negative width"},
        {"Pf\n2 -2\n-1\n", 16, SL_ERR_FORMAT, "negative height"},
        {"Pf\n0 2\n-1\n", 0, SL_ERR_FORMAT, "zero width"},
        {"Pf\n2x 2\n-1\n", 16, SL_ERR_FORMAT, "width with junk"},
        {"Pf\n2 2\n0\n", 16, SL_ERR_FORMAT, "scale zero"},
        {"Pf\n2 2\nnan\n", 16, SL_ERR_FORMAT, "scale NaN"},
        {"Pf\n2 2\n1e999\n", 16, SL_ERR_FORMAT, "scale overflows"},
        {"Pf\n2 2\n-1", 0, SL_ERR_FORMAT, "no byte after the scale"},
        {"Pf\n2 2\n", 0, SL_ERR_FORMAT, "missing scale"},
        {"Pf\n# comment\n2 2\n-1\n", 16, SL_ERR_FORMAT, "comment"},
        {"Pf2 2\n-1\n", 16, SL_ERR_FORMAT, "no whitespace after magic"},
        {"P6\n2 2\n255\n", 12, SL_ERR_FORMAT, "PPM, not PFM"},
        {"P", 0, SL_ERR_FORMAT, "one byte"},
        {"", 0, SL_ERR_FORMAT, "empty"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        sl_status st = parse_text(cases[i].header, cases[i].data, &img, &err);
        SL_CHECK_MSG(st == cases[i].want, "%s: status %d, want %d (%s)", cases[i].why, st, cases[i].want,
                     st == SL_OK ? "" : err.message);
        SL_CHECK_MSG(depth_is_zeroed(&img), "%s: output not zeroed", cases[i].why);
        sl_depth_image_deinit(&img);
    }
    /* A very long header token cannot overrun anything. */
    char longtok[400];
    memset(longtok, '7', sizeof longtok);
    memcpy(longtok, "Pf\n", 3);
    longtok[sizeof longtok - 1] = '\0';
    SL_CHECK(parse_text(longtok, 0, &img, &err) == SL_ERR_FORMAT);

    /* Files: a truncated write, an empty file, a missing file. */
    float v[6] = {1, 2, 3, 4, 5, 6};
    SL_CHECK(sl_pfm_write(tmp_path("t.pfm"), v, 3, 2, &err) == SL_OK);
    size_t size = 0;
    uint8_t *file = read_bytes(tmp_path("t.pfm"), &size);
    SL_CHECK(file && write_bytes(tmp_path("t.pfm"), file, size - 3));
    free(file);
    SL_CHECK(sl_pfm_read(tmp_path("t.pfm"), &img, &err) == SL_ERR_FORMAT);
    SL_CHECK(strstr(err.message, "truncated") != NULL);
    SL_CHECK(depth_is_zeroed(&img));
    SL_CHECK(write_bytes(tmp_path("empty.pfm"), "", 0));
    SL_CHECK(sl_pfm_read(tmp_path("empty.pfm"), &img, &err) == SL_ERR_FORMAT);
    SL_CHECK(sl_pfm_read(tmp_path("missing.pfm"), &img, &err) == SL_ERR_IO);
    SL_CHECK(sl_pfm_write(tmp_path("bad.pfm"), v, 0, 2, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_pfm_write(tmp_path("bad.pfm"), v, 70000, 70000, &err) == SL_ERR_LIMIT);
}

/* ---- JPEG --------------------------------------------------------------- */

static double mean_rgb_error(const uint8_t *a, const uint8_t *b, int n)
{
    double sum = 0;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            sum += abs((int)a[i * 4 + c] - (int)b[i * 4 + c]);
    return sum / (3.0 * n);
}

static void test_jpeg(void)
{
    enum { W = 64, H = 48 };
    static uint8_t rgba[W * H * 4], flipped[W * H * 4];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            uint8_t *p = rgba + (y * W + x) * 4;
            p[0] = (uint8_t)(x * 4);
            p[1] = (uint8_t)(y * 5);
            p[2] = (uint8_t)(128 + 100 * sin(x * 0.2) * cos(y * 0.15));
            p[3] = 255;
        }
    for (int y = 0; y < H; y++)
        memcpy(flipped + (H - 1 - y) * W * 4, rgba + y * W * 4, W * 4);

    sl_err err = {0};
    uint8_t *jpg = NULL, *jpg_up = NULL;
    size_t size = 0, size_up = 0;
    SL_CHECK_MSG(sl_jpeg_encode(rgba, W, H, 0, 95, SL_JPEG_444, &jpg, &size, &err) == SL_OK, "%s", err.message);
    sl_image img = {0};
    SL_CHECK_MSG(jpg && sl_jpeg_decode(jpg, size, &img, &err) == SL_OK, "%s", err.message);
    SL_CHECK(img.width == W && img.height == H);
    if (img.rgba) {
        double e = mean_rgb_error(img.rgba, rgba, W * H);
        SL_CHECK_MSG(e < 3.0, "JPEG q95 4:4:4 mean error %.3f, want < 3", e);
        printf("jpeg q95 444: %zu bytes, mean abs error %.3f\n", size, e);
    }
    sl_image_deinit(&img);

    /* bottom_up on the flipped buffer gives the same JPEG byte for byte. */
    SL_CHECK(sl_jpeg_encode(flipped, W, H, 1, 95, SL_JPEG_444, &jpg_up, &size_up, &err) == SL_OK);
    SL_CHECK(jpg && jpg_up && size == size_up && memcmp(jpg, jpg_up, size) == 0);
    free(jpg_up);

    /* 4:2:0 is smaller and still close on this smooth image. */
    uint8_t *jpg420 = NULL;
    size_t size420 = 0;
    SL_CHECK(sl_jpeg_encode(rgba, W, H, 0, 95, SL_JPEG_420, &jpg420, &size420, &err) == SL_OK);
    SL_CHECK(jpg420 && size420 < size);
    SL_CHECK(jpg420 && sl_jpeg_decode(jpg420, size420, &img, &err) == SL_OK);
    if (img.rgba) {
        double e = mean_rgb_error(img.rgba, rgba, W * H);
        SL_CHECK_MSG(e < 4.0, "JPEG q95 4:2:0 mean error %.3f, want < 4", e);
        printf("jpeg q95 420: %zu bytes, mean abs error %.3f\n", size420, e);
    }
    sl_image_deinit(&img);
    free(jpg420);

    /* sl_jpeg_write writes the same bytes as the 4:4:4 encoder. */
    SL_CHECK(sl_jpeg_write(tmp_path("a.jpg"), rgba, W, H, 95, &err) == SL_OK);
    size_t fsize = 0;
    uint8_t *file = read_bytes(tmp_path("a.jpg"), &fsize);
    SL_CHECK(file && jpg && fsize == size && memcmp(file, jpg, size) == 0);
    free(file);

    /* Hostile and invalid. */
    uint8_t junk[64];
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = (uint8_t)rand_u32();
    SL_CHECK(sl_jpeg_decode(junk, sizeof junk, &img, &err) == SL_ERR_FORMAT && is_zeroed(&img));
    SL_CHECK(jpg && sl_jpeg_decode(jpg, 100, &img, &err) != SL_ERR_NOMEM);   /* truncated: error or partial */
    SL_CHECK(img.rgba == NULL || (img.width == W && img.height == H));
    sl_image_deinit(&img);
    SL_CHECK(jpg && sl_jpeg_decode(jpg, 0, &img, &err) == SL_ERR_FORMAT);
    uint8_t *out = NULL;
    SL_CHECK(sl_jpeg_encode(rgba, W, H, 0, 0, SL_JPEG_444, &out, &size, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_jpeg_encode(rgba, W, H, 0, 101, SL_JPEG_444, &out, &size, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_jpeg_encode(rgba, 0, H, 0, 90, SL_JPEG_444, &out, &size, &err) == SL_ERR_INVALID);
    SL_CHECK(out == NULL);
    free(jpg);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/sl_test_image_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        fprintf(stderr, "cannot create a temporary folder\n");
        return 1;
    }
    test_png_round_trip();
    test_png_colour_types();
    test_png_hostile();
    test_pfm_round_trip();
    test_pfm_big_endian_colour();
    test_pfm_hostile();
    test_jpeg();
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", tmpdir);
    SL_TEST_END();
}
