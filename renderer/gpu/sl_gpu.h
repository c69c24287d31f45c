/* sl_gpu.h — headless OpenGL 4.5 core: EGL context, embedded shaders, targets, timers.
 *
 * sl_gpu_create tries each hardware GPU of EGL_EXT_platform_device (software
 * devices skipped), then Mesa's surfaceless platform (llvmpipe), and keeps
 * the first that gives an OpenGL 4.5 core context;
 * SIGHTLINE_EGL_DEVICE=<index> picks that device with no fallback, and
 * SIGHTLINE_EGL_DEVICE=software a CPU rasterizer (Mesa's software EGL
 * device, else surfaceless, as long as the renderer is llvmpipe/softpipe). The context is current
 * on the creating thread and every function here, and every technique's
 * prepare/render/release, must run on that thread (the render thread).
 * Shaders are .glsl files under renderer/ embedded at build time and named
 * by their path below renderer/ ("tubes_mesh/tubes_mesh.frag.glsl"); a line
 * `#include "gpu/glsl/lighting.glsl"` pastes another embedded file, and a
 * compile error names the file and line. Missing EGL, context or GL feature
 * is an SL_ERR_GPU with a sentence saying which; never a crash.
 */
#ifndef SL_GPU_H
#define SL_GPU_H

#include <stddef.h>
#include <stdint.h>

#include <epoxy/gl.h>

#include "../core/sl_status.h"

typedef struct sl_gpu sl_gpu;

typedef struct sl_gpu_desc {
    const char *device;  /* NULL: $SIGHTLINE_EGL_DEVICE, else auto; "software" or "<index>" */
    int debug;           /* install a KHR_debug callback that prints GL errors */
    int quiet;           /* do not print the renderer string (nor the candidates skipped) */
    int software_devices;/* auto: also try EGL devices that are software renderers, before surfaceless */
    unsigned test_fail_mask; /* tests only: candidate i (in trial order) fails as if its
                                context could not be made when bit i is set; 0 in programs */
} sl_gpu_desc;

/* Fails with SL_ERR_INVALID for a malformed device choice, SL_ERR_GPU when
 * no candidate gives a 4.5 core context (the message names every candidate
 * tried and why it failed, or says there is no EGL display at all). */
sl_status sl_gpu_create(const sl_gpu_desc *desc, sl_gpu **out, sl_err *err);
void sl_gpu_destroy(sl_gpu *gpu);
const char *sl_gpu_renderer(const sl_gpu *gpu);  /* GL_RENDERER string */
/* 1 when GL_RENDERER names a CPU rasterizer (llvmpipe, softpipe, swrast) or
 * the EGL device says EGL_MESA_device_software. */
int sl_gpu_is_software(const sl_gpu *gpu);
const char *sl_gpu_display_name(const sl_gpu *gpu); /* "EGL device N" or "Mesa surfaceless" */

/* Embedded files (generated at build time). */
typedef struct sl_embedded_file {
    const char *path;      /* below renderer/ */
    const char *text;
    size_t size;
} sl_embedded_file;
const sl_embedded_file *sl_embedded_find(const char *path);
const sl_embedded_file *sl_embedded_list(int *count);

/* One shader stage's source after #include expansion: "#version 450 core",
 * the defines, then every pasted file behind a `#line 1 N` marker, where N
 * indexes paths (paths[0] is the stage file). Includes come from the
 * embedded files; the stage file itself may be any text (a checker can hand
 * in a file read from disk). */
#define SL_SHADER_MAX_FILES 32
typedef struct sl_shader_source {
    char *text;
    const char *paths[SL_SHADER_MAX_FILES];
    int file_count;
} sl_shader_source;
sl_status sl_shader_expand(const sl_embedded_file *file, const char *defines, sl_shader_source *out, sl_err *err);
void sl_shader_source_free(sl_shader_source *src); /* zeroed is fine */
/* Compiles an expanded source as `stage`; on failure err holds the info log
 * with "N:L" rewritten to "path:L". */
sl_status sl_shader_compile(GLenum stage, const sl_shader_source *src, GLuint *shader, sl_err *err);

/* Builds a program from embedded shader files; any of the stage names may
 * be NULL (compute alone, or vertex+fragment, optionally geometry).
 * `defines` (may be NULL) is pasted after #version, e.g. "#define N 8\n".
 * Returns 0 and fills err (with the info log, mapped to file:line) on failure. */
typedef struct sl_program_desc {
    const char *vertex, *geometry, *fragment, *compute;
    const char *defines;
    const char *label;
} sl_program_desc;
sl_status sl_gl_program_create(const sl_program_desc *desc, GLuint *program, sl_err *err);

/* After deleting buffers that the last draw used: one throw-away draw so the
 * driver drops its references to them and their memory is freed (unbind.c;
 * Mesa keeps the last draw's vertex and index buffers bound otherwise).
 * Costs a shader compile; never fails (a link failure only skips the draw). */
void sl_gpu_drop_references(void);

/* An offscreen target: RGBA8 colour + 32F depth (reversed-Z, see sl_camera.h),
 * optional MSAA resolved into single-sample textures by sl_target_resolve. */
typedef struct sl_target {
    int width, height, samples;
    GLuint fbo, color, depth;             /* render attachments (multisampled when samples > 1) */
    GLuint resolve_fbo, resolve_color, resolve_depth; /* single-sample; == fbo/color/depth when samples <= 1 */
} sl_target;

/* Whether this GPU can hold a width x height target with `samples` MSAA
 * samples (0 or 1 = none); the context must be current. SL_ERR_UNSUPPORTED
 * names the GPU's limit (size: texture, renderbuffer and framebuffer limits;
 * samples: GL_MAX_SAMPLES and the colour/depth texture sample limits);
 * SL_ERR_INVALID for a size below 1. sl_target_init checks the same. */
sl_status sl_target_check(int width, int height, int samples, sl_err *err);
sl_status sl_target_init(sl_target *t, int width, int height, int samples, sl_err *err);
void sl_target_deinit(sl_target *t);
/* Binds the target, sets viewport, clip control 0..1 and clears colour to
 * background and depth to 0 (reversed-Z: nothing hit). */
void sl_target_begin(sl_target *t, const float background[4]);
/* Resolves MSAA (no-op without) so readbacks see the final frame. */
void sl_target_resolve(sl_target *t);
/* Reads RGBA8; top_down = 1 flips to row 0 at the top, 0 keeps GL's bottom-up rows. */
void sl_target_read_rgba(sl_target *t, uint8_t *rgba, int top_down);
/* Reads the depth buffer (reversed-Z values), rows top-down. */
void sl_target_read_depth(sl_target *t, float *depth);

/* The GL errors raised since the last check, all drained: SL_OK, or SL_ERR_GPU
 * naming `what` and the first error (GL_OUT_OF_MEMORY: "out of GPU memory").
 * Techniques call it after a prepare's allocations (gl_errors.c). */
sl_status sl_gl_check_errors(const char *what, sl_err *err);
/* Tests only: the next sl_gl_check_errors reports `error` (as if GL had). */
void sl_gl_inject_error(GLenum error);

/* Compute dispatch along x in chunks (dispatch.c). sl_gpu_max_groups is the
 * driver's GL_MAX_COMPUTE_WORK_GROUP_COUNT[0] (65535 on llvmpipe, the GL
 * minimum; a 1-D dispatch above it fails with GL_INVALID_VALUE and does
 * nothing). sl_gpu_dispatch_chunked runs `groups` groups of the current
 * program in dispatches of at most max_groups (0 or above the limit = the
 * limit); before each it sets the uniform at group_base_location (the
 * chunk's first group, which the shader adds to gl_WorkGroupID.x; -1 when
 * the shader has none). Both need the current program's context. */
unsigned sl_gpu_max_groups(void);
void sl_gpu_dispatch_chunked(GLint group_base_location, size_t groups, unsigned max_groups);

/* GPU timer (GL_TIME_ELAPSED query). */
typedef struct sl_gpu_timer { GLuint query; int running; } sl_gpu_timer;
void sl_gpu_timer_init(sl_gpu_timer *t);
void sl_gpu_timer_deinit(sl_gpu_timer *t);
void sl_gpu_timer_begin(sl_gpu_timer *t);
/* Ends the query and waits for it; returns milliseconds. */
double sl_gpu_timer_end_ms(sl_gpu_timer *t);

/* The uniform block `sl_camera_block` of gpu/glsl/camera.glsl: creates the
 * buffer on first use (*buffer == 0), fills it from view and binds it to
 * uniform binding 0. Delete the buffer with glDeleteBuffers. */
struct sl_view;
void sl_camera_ubo_update(GLuint *buffer, const struct sl_view *view);

#endif
