/* sl_host_frame.h — a frame drawn on the CPU (colour and reversed-Z depth in host memory)
 * put into the bound GL target, so that everything else drawn into the same frame
 * (a volume whose rays end at the depth, overlays, focus + context) composes with it
 * as with a GL draw.
 *
 * The caller fills `rgba` (RGBA8) and `depth` (reversed-Z as sl_camera.h defines it,
 * 0 = nothing hit), both with GL's bottom-up rows, then calls sl_host_frame_draw: two
 * texture uploads and one full-screen triangle that writes colour and gl_FragDepth where
 * depth > 0, depth test GREATER against what the target holds, so nearer GL geometry drawn
 * before stays in front; with `premultiplied` the colour is blended over the target instead
 * (a transparent CPU frame over the background). Multisampled targets get the value in every sample. Buffers and
 * textures are (re)made when the size changes. Render thread only (GL).
 */
#ifndef SL_HOST_FRAME_H
#define SL_HOST_FRAME_H

#include <stddef.h>
#include <stdint.h>

#include <epoxy/gl.h>

#include "../core/sl_status.h"

typedef struct sl_host_frame {
    int width, height;
    uint8_t *rgba;          /* owned: width * height * 4, rows bottom-up */
    float *depth;           /* owned: width * height, rows bottom-up */
    int premultiplied;      /* 1: rgba is premultiplied colour blended over the target
                             * (ONE, ONE_MINUS_SRC_ALPHA), as a translucent GL draw; 0: replaces it */
    GLuint color_tex, depth_tex, program, vao;
} sl_host_frame;

/* Makes the host buffers (and on first use the program) for width x height; keeps
 * them when the size is the same. The buffers' contents are left as they are. */
sl_status sl_host_frame_resize(sl_host_frame *f, int width, int height, sl_err *err);

/* Uploads the buffers and draws them into the bound target (viewport = its size). */
sl_status sl_host_frame_draw(sl_host_frame *f, sl_err *err);

void sl_host_frame_deinit(sl_host_frame *f); /* zeroed is fine */
size_t sl_host_frame_gpu_bytes(const sl_host_frame *f);

#endif
