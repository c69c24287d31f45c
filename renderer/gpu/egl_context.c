/* egl_context.c — the headless OpenGL 4.5 core context (see sl_gpu.h).
 *
 * Candidates, tried in order until one gives a current 4.5 core context:
 * $SIGHTLINE_EGL_DEVICE (or desc->device) when set — "<index>" is that EGL
 * device alone (never falls back); "software" is Mesa's software EGL devices
 * (EGL_MESA_device_software), then Mesa surfaceless, keeping only a context
 * whose renderer is a CPU rasterizer (surfaceless may pick a GPU's render
 * node); else every hardware device of EGL_EXT_device_enumeration (software
 * devices skipped unless desc->software_devices), then Mesa surfaceless. A candidate that yields a
 * display but fails eglInitialize, the context or the version check is
 * recorded and the next one is tried; when all fail the error names each
 * with its reason. "Software" is judged from the GL_RENDERER string
 * (llvmpipe, softpipe, swrast) or the device's EGL_MESA_device_software, not
 * from the platform: Mesa surfaceless can drive a real GPU.
 * The context has no surface (EGL_KHR_surfaceless_context): all rendering
 * goes to framebuffer objects. Runs on, and binds the context to, the
 * calling thread. No window system is touched.
 */
#include "sl_gpu.h"

#include <epoxy/egl.h>
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_DEVICES 16
#define MAX_CANDIDATES (MAX_DEVICES + 1)

struct sl_gpu {
    EGLDisplay display;
    EGLContext context;
    char renderer[256];
    char display_name[64];
    int software;
};

/* One display to try. */
typedef struct candidate {
    EGLDisplay display;
    char name[64];          /* "EGL device 1", "Mesa surfaceless" */
    int software_device;    /* the device names EGL_MESA_device_software */
} candidate;

/* An EGL display is shared by the whole process and eglInitialize on an
 * initialized display is a no-op, so sl_gpu never calls eglTerminate: the
 * display (and the driver it loaded) stays for the process lifetime. This
 * keeps a later sl_gpu_create from paying for the driver load again, and
 * avoids unloading Mesa, whose unload leaves allocations that no leak
 * checker can attribute (the module is gone). Contexts are destroyed. A
 * candidate that failed after eglInitialize therefore also stays
 * initialized; it holds no context. */

static int has_extension(const char *list, const char *name)
{
    if (!list)
        return 0;
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return 1;
    return 0;
}

/* Mesa's CPU rasterizers name themselves in GL_RENDERER (any case). */
static int renderer_is_software(const char *renderer)
{
    static const char *const names[] = {"llvmpipe", "softpipe", "swrast"};
    char lower[256];
    size_t k = 0;
    for (; renderer[k] && k + 1 < sizeof lower; k++)
        lower[k] = (char)tolower((unsigned char)renderer[k]);
    lower[k] = '\0';
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strstr(lower, names[i]))
            return 1;
    return 0;
}

/* Parses the device choice: -1 = automatic, -2 = "software", else an index.
 * Rejects anything else naming the variable and what it accepts. */
static sl_status parse_choice(const char *choice, int *index, sl_err *err)
{
    *index = -1;
    if (!choice)
        return SL_OK;
    if (strcmp(choice, "software") == 0) {
        *index = -2;
        return SL_OK;
    }
    char *end = NULL;
    errno = 0;
    long v = strtol(choice, &end, 10);
    if (end == choice || *end != '\0' || errno == ERANGE || v < 0 || v > 1000000 || choice[0] == '-' ||
        choice[0] == '+' || choice[0] == ' ')
        return sl_err_set(err, SL_ERR_INVALID,
                          "SIGHTLINE_EGL_DEVICE must be 'software' or a device index (0, 1, ...), got '%.64s'", choice);
    *index = (int)v;
    return SL_OK;
}

static void add_surfaceless(candidate *c, int *n)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_extension(client, "EGL_MESA_platform_surfaceless"))
        return;
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (d == EGL_NO_DISPLAY)
        return;
    c[*n] = (candidate){.display = d};
    snprintf(c[*n].name, sizeof c[*n].name, "Mesa surfaceless");
    (*n)++;
}

/* Fills the candidates in trial order. An explicit choice that names no
 * usable display is an error here; an empty automatic list is left to the
 * caller ("no EGL display"). */
static sl_status list_candidates(int index, int software_devices, candidate *c, int *n, sl_err *err)
{
    *n = 0;
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    int enumerate = has_extension(client, "EGL_EXT_device_enumeration") && has_extension(client, "EGL_EXT_platform_device");
    if (!enumerate && index >= 0)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "EGL device %d requested but EGL_EXT_device_enumeration is missing", index);
    EGLDeviceEXT devices[MAX_DEVICES];
    EGLint count = 0;
    if (enumerate && !eglQueryDevicesEXT(MAX_DEVICES, devices, &count))
        count = 0;
    if (index >= count)
        return sl_err_set(err, SL_ERR_INVALID, "EGL device %d requested but only %d device(s) exist", index, (int)count);
    for (EGLint i = 0; i < count; i++) {
        if (index >= 0 && i != index)
            continue;
        const char *ext = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
        int is_software = has_extension(ext, "EGL_MESA_device_software");
        if (index == -2 ? !is_software : is_software && index == -1 && !software_devices)
            continue;
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
        if (d == EGL_NO_DISPLAY) {
            if (index >= 0)
                return sl_err_set(err, SL_ERR_GPU, "EGL device %d gives no display (EGL error 0x%x)", index,
                                  (unsigned)eglGetError());
            continue;
        }
        c[*n] = (candidate){.display = d, .software_device = is_software};
        snprintf(c[*n].name, sizeof c[*n].name, "EGL device %d", (int)i);
        (*n)++;
    }
    if (index < 0)
        add_surfaceless(c, n);
    if (index == -2 && *n == 0)
        return sl_err_set(err, SL_ERR_GPU, "SIGHTLINE_EGL_DEVICE=software, but neither a software EGL device nor "
                                           "Mesa surfaceless is available; install libegl-mesa0 and libgl1-mesa-dri");
    return SL_OK;
}

static void GLAPIENTRY debug_callback(GLenum source, GLenum type, GLuint id, GLenum severity,
                                      GLsizei length, const GLchar *message, const void *user)
{
    (void)source; (void)id; (void)length; (void)user;
    if (type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH)
        fprintf(stderr, "GL: %s\n", message);
}

/* Makes a current 4.5 core context on c->display. Returns 1 and fills gpu's
 * display, context and renderer; or returns 0 with the reason in why,
 * having destroyed whatever context it made. */
static int try_candidate(sl_gpu *gpu, const candidate *c, int debug, char *why, size_t why_size)
{
    EGLint major = 0, minor = 0;
    if (!eglInitialize(c->display, &major, &minor)) {
        snprintf(why, why_size, "eglInitialize failed (EGL error 0x%x)", (unsigned)eglGetError());
        return 0;
    }
    const char *dext = eglQueryString(c->display, EGL_EXTENSIONS);
    if (!has_extension(dext, "EGL_KHR_surfaceless_context")) {
        snprintf(why, why_size, "the EGL display lacks EGL_KHR_surfaceless_context");
        return 0;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        snprintf(why, why_size, "this EGL cannot create desktop OpenGL contexts");
        return 0;
    }
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_extension(dext, "EGL_KHR_no_config_context")) {
        const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(c->display, config_attribs, &config, 1, &n) || n < 1) {
            snprintf(why, why_size, "no EGL config supports desktop OpenGL");
            return 0;
        }
    }
    const EGLint context_attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_CONTEXT_OPENGL_DEBUG, debug ? EGL_TRUE : EGL_FALSE,
        EGL_NONE};
    EGLContext ctx = eglCreateContext(c->display, config, EGL_NO_CONTEXT, context_attribs);
    if (ctx == EGL_NO_CONTEXT) {
        snprintf(why, why_size, "cannot create an OpenGL 4.5 core context (EGL error 0x%x)", (unsigned)eglGetError());
        return 0;
    }
    if (!eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        snprintf(why, why_size, "eglMakeCurrent failed (EGL error 0x%x)", (unsigned)eglGetError());
        eglDestroyContext(c->display, ctx);
        return 0;
    }
    if (epoxy_gl_version() < 45) {
        snprintf(why, why_size, "OpenGL 4.5 is required, the context offers %d.%d", epoxy_gl_version() / 10,
                 epoxy_gl_version() % 10);
        eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(c->display, ctx);
        return 0;
    }
    gpu->display = c->display;
    gpu->context = ctx;
    const char *r = (const char *)glGetString(GL_RENDERER);
    snprintf(gpu->renderer, sizeof gpu->renderer, "%s", r ? r : "unknown");
    snprintf(gpu->display_name, sizeof gpu->display_name, "%s", c->name);
    return 1;
}

/* Appends "; " (when not first) and text to buf, truncating at its size. */
static void append(char *buf, size_t size, const char *text)
{
    size_t used = strlen(buf);
    if (used + 1 < size)
        snprintf(buf + used, size - used, "%s%s", used ? "; " : "", text);
}

sl_status sl_gpu_create(const sl_gpu_desc *desc, sl_gpu **out, sl_err *err)
{
    static const sl_gpu_desc defaults = {0};
    if (!desc)
        desc = &defaults;
    *out = NULL;
    const char *choice = desc->device ? desc->device : getenv("SIGHTLINE_EGL_DEVICE");
    if (choice && !*choice)
        choice = NULL;
    int index;
    sl_status st = parse_choice(choice, &index, err);
    if (st != SL_OK)
        return st;
    candidate cands[MAX_CANDIDATES];
    int n = 0;
    if ((st = list_candidates(index, desc->software_devices, cands, &n, err)) != SL_OK)
        return st;
    if (n == 0)
        return sl_err_set(err, SL_ERR_GPU, "no EGL display: neither a GPU device (EGL_EXT_platform_device) nor Mesa "
                                           "surfaceless is available; install libegl-mesa0 and libgl1-mesa-dri");
    sl_gpu *gpu = calloc(1, sizeof *gpu);
    if (!gpu)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    gpu->display = EGL_NO_DISPLAY;
    gpu->context = EGL_NO_CONTEXT;

    char failures[SL_ERR_MSG_MAX] = "";
    int chosen = -1;
    for (int i = 0; i < n && chosen < 0; i++) {
        char why[256], line[384];
        int ok;
        if (i < 32 && (desc->test_fail_mask >> i) & 1u) {
            snprintf(why, sizeof why, "failure injected by sl_gpu_desc.test_fail_mask");
            ok = 0;
        } else {
            ok = try_candidate(gpu, &cands[i], desc->debug, why, sizeof why);
        }
        if (ok && index == -2 && !renderer_is_software(gpu->renderer)) {
            snprintf(why, sizeof why, "renders on '%.128s', not a software rasterizer", gpu->renderer);
            eglMakeCurrent(gpu->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(gpu->display, gpu->context);
            gpu->display = EGL_NO_DISPLAY;
            gpu->context = EGL_NO_CONTEXT;
            ok = 0;
        }
        if (ok) {
            chosen = i;
            break;
        }
        snprintf(line, sizeof line, "%s: %s", cands[i].name, why);
        append(failures, sizeof failures, line);
    }
    if (chosen < 0) {
        free(gpu);
        return sl_err_set(err, SL_ERR_GPU, "no usable OpenGL 4.5 core context: %s", failures);
    }
    gpu->software = renderer_is_software(gpu->renderer) || cands[chosen].software_device;
    if (desc->debug) {
        glEnable(GL_DEBUG_OUTPUT);
        glDebugMessageCallback(debug_callback, NULL);
    }
    if (!desc->quiet) {
        if (failures[0])
            fprintf(stderr, "sightline: skipped: %s\n", failures);
        fprintf(stderr, "sightline: OpenGL renderer: %s (%s)\n", gpu->renderer,
                gpu->software ? "software" : "hardware");
    }
    *out = gpu;
    return SL_OK;
}

void sl_gpu_destroy(sl_gpu *gpu)
{
    if (!gpu)
        return;
    if (gpu->display != EGL_NO_DISPLAY) {
        eglMakeCurrent(gpu->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (gpu->context != EGL_NO_CONTEXT)
            eglDestroyContext(gpu->display, gpu->context);
        eglReleaseThread();
    }
    free(gpu);
}

const char *sl_gpu_renderer(const sl_gpu *gpu) { return gpu->renderer; }
int sl_gpu_is_software(const sl_gpu *gpu) { return gpu->software; }
const char *sl_gpu_display_name(const sl_gpu *gpu) { return gpu->display_name; }
