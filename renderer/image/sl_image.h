/* sl_image.h — image files and buffers: PNG (libpng), PFM depth maps, JPEG (TurboJPEG).
 *
 * Colour images are RGBA8, rows top-down, tightly packed. Depth maps are
 * float, one channel, rows top-down in memory; PFM files store rows
 * bottom-up as the format requires (and this module flips). Readers check
 * sizes against SL_IMAGE_MAX_PIXELS before allocating. Any thread; no GL.
 */
#ifndef SL_IMAGE_H
#define SL_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/sl_status.h"

#define SL_IMAGE_MAX_PIXELS (16384u * 16384u)

typedef struct sl_image {
    int width, height;
    uint8_t *rgba;       /* owned, width*height*4 */
} sl_image;

typedef struct sl_depth_image {
    int width, height;
    float *values;       /* owned, width*height, row 0 at the top */
} sl_depth_image;

void sl_image_deinit(sl_image *img);        /* frees and zeroes; safe on a zeroed struct */
void sl_depth_image_deinit(sl_depth_image *img);

sl_status sl_png_write(const char *path, const uint8_t *rgba, int width, int height, sl_err *err);
/* Reads any PNG colour type / bit depth, converted to RGBA8. */
sl_status sl_png_read(const char *path, sl_image *out, sl_err *err);
/* The same from a buffer (data is borrowed; fuzzing and network input). */
sl_status sl_png_decode(const uint8_t *data, size_t size, sl_image *out, sl_err *err);
/* PNG into a malloc'd buffer (for snapshots over the wire). */
sl_status sl_png_encode(const uint8_t *rgba, int width, int height, uint8_t **out, size_t *out_size, sl_err *err);

/* Writes "Pf", scale -1 (little-endian), rows bottom-up. */
sl_status sl_pfm_write(const char *path, const float *values, int width, int height, sl_err *err);
/* Reads Pf or PF (first channel), either byte order. */
sl_status sl_pfm_read(const char *path, sl_depth_image *out, sl_err *err);
/* The same from a buffer (data is borrowed; fuzzing and network input). */
sl_status sl_pfm_parse(const uint8_t *data, size_t size, sl_depth_image *out, sl_err *err);

typedef enum sl_jpeg_subsampling { SL_JPEG_444 = 0, SL_JPEG_420 = 1 } sl_jpeg_subsampling;

/* Encodes RGBA8 to JPEG with TurboJPEG. bottom_up says the rows are stored
 * bottom-up (as glReadPixels returns them), so no flip copy is needed.
 * *out is malloc'd (free with free()). */
sl_status sl_jpeg_encode(const uint8_t *rgba, int width, int height, int bottom_up, int quality,
                         sl_jpeg_subsampling subsampling, uint8_t **out, size_t *out_size, sl_err *err);
sl_status sl_jpeg_write(const char *path, const uint8_t *rgba, int width, int height, int quality, sl_err *err);
/* Decodes a JPEG to RGBA8 top-down (tests and tools). */
sl_status sl_jpeg_decode(const uint8_t *data, size_t size, sl_image *out, sl_err *err);

#endif
