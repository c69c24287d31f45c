/* egl_context.c — the headless OpenGL 4.5 core context (see sl_gpu.h).
 *
 * Order of choice: $SIGHTLINE_EGL_DEVICE (or desc->device) when set —
 * "software" forces Mesa surfaceless, "<index>" picks that EGL device; else
 * the first hardware device of EGL_EXT_device_enumeration (devices whose
 * extensions name EGL_MESA_device_software are skipped), else surfaceless.
 * The context has no surface (EGL_KHR_surfaceless_context): all rendering
 * goes to framebuffer objects. Runs on, and binds the context to, the
 * calling thread. No window system is touched.
 */
#include "sl_gpu.h"

#include <epoxy/egl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct sl_gpu {
    EGLDisplay display;
    EGLContext context;
    char renderer[256];
    int software;
};

/* An EGL display is shared by the whole process and eglInitialize on an
 * initialized display is a no-op, so sl_gpu never calls eglTerminate: the
 * display (and the driver it loaded) stays for the process lifetime. This
 * keeps a later sl_gpu_create from paying for the driver load again, and
 * avoids unloading Mesa, whose unload leaves allocations that no leak
 * checker can attribute (the module is gone). Contexts are destroyed. */

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

static EGLDisplay open_device_display(const char *choice, int *software, sl_err *err)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    int want_index = -1;
    if (choice && strcmp(choice, "software") != 0) {
        char *end;
        long v = strtol(choice, &end, 10);
        if (*end != '\0' || v < 0) {
            sl_err_set(err, SL_ERR_INVALID, "SIGHTLINE_EGL_DEVICE must be 'software' or a device index, got '%s'", choice);
            return EGL_NO_DISPLAY;
        }
        want_index = (int)v;
    }
    if (choice && strcmp(choice, "software") == 0)
        return EGL_NO_DISPLAY;
    if (!has_extension(client, "EGL_EXT_device_enumeration") || !has_extension(client, "EGL_EXT_platform_device")) {
        if (want_index >= 0)
            sl_err_set(err, SL_ERR_UNSUPPORTED, "EGL device %d requested but EGL_EXT_device_enumeration is missing", want_index);
        return EGL_NO_DISPLAY;
    }
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (!eglQueryDevicesEXT(16, devices, &count))
        count = 0;
    if (want_index >= count) {
        sl_err_set(err, SL_ERR_INVALID, "EGL device %d requested but only %d device(s) exist", want_index, count);
        return EGL_NO_DISPLAY;
    }
    for (EGLint i = 0; i < count; i++) {
        if (want_index >= 0 && i != want_index)
            continue;
        const char *ext = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
        int is_software = has_extension(ext, "EGL_MESA_device_software");
        if (is_software && want_index < 0)
            continue;
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
        if (d != EGL_NO_DISPLAY) {
            *software = is_software;
            return d;
        }
    }
    return EGL_NO_DISPLAY;
}

static EGLDisplay open_surfaceless_display(void)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_extension(client, "EGL_MESA_platform_surfaceless"))
        return EGL_NO_DISPLAY;
    return eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
}

static void GLAPIENTRY debug_callback(GLenum source, GLenum type, GLuint id, GLenum severity,
                                      GLsizei length, const GLchar *message, const void *user)
{
    (void)source; (void)id; (void)length; (void)user;
    if (type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH)
        fprintf(stderr, "GL: %s\n", message);
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
    sl_gpu *gpu = calloc(1, sizeof *gpu);
    if (!gpu)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    gpu->display = EGL_NO_DISPLAY;
    gpu->context = EGL_NO_CONTEXT;

    sl_err_clear(err);
    gpu->display = open_device_display(choice, &gpu->software, err);
    if (gpu->display == EGL_NO_DISPLAY && err && err->status != SL_OK)
        goto fail;
    if (gpu->display == EGL_NO_DISPLAY) {
        gpu->display = open_surfaceless_display();
        gpu->software = 1;
    }
    if (gpu->display == EGL_NO_DISPLAY) {
        sl_err_set(err, SL_ERR_GPU, "no EGL display: neither a GPU device (EGL_EXT_platform_device) nor Mesa surfaceless is available; install libegl-mesa0 and libgl1-mesa-dri");
        goto fail;
    }
    EGLint major = 0, minor = 0;
    EGLBoolean ok = eglInitialize(gpu->display, &major, &minor);
    if (!ok) {
        sl_err_set(err, SL_ERR_GPU, "eglInitialize failed (0x%x)", (unsigned)eglGetError());
        gpu->display = EGL_NO_DISPLAY;
        goto fail;
    }
    const char *dext = eglQueryString(gpu->display, EGL_EXTENSIONS);
    if (!has_extension(dext, "EGL_KHR_surfaceless_context")) {
        sl_err_set(err, SL_ERR_GPU, "the EGL display lacks EGL_KHR_surfaceless_context");
        goto fail;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        sl_err_set(err, SL_ERR_GPU, "this EGL cannot create desktop OpenGL contexts");
        goto fail;
    }
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_extension(dext, "EGL_KHR_no_config_context")) {
        const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(gpu->display, config_attribs, &config, 1, &n) || n < 1) {
            sl_err_set(err, SL_ERR_GPU, "no EGL config supports desktop OpenGL");
            goto fail;
        }
    }
    const EGLint context_attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_CONTEXT_OPENGL_DEBUG, desc->debug ? EGL_TRUE : EGL_FALSE,
        EGL_NONE};
    gpu->context = eglCreateContext(gpu->display, config, EGL_NO_CONTEXT, context_attribs);
    if (gpu->context == EGL_NO_CONTEXT) {
        sl_err_set(err, SL_ERR_GPU, "cannot create an OpenGL 4.5 core context (EGL error 0x%x)", (unsigned)eglGetError());
        goto fail;
    }
    if (!eglMakeCurrent(gpu->display, EGL_NO_SURFACE, EGL_NO_SURFACE, gpu->context)) {
        sl_err_set(err, SL_ERR_GPU, "eglMakeCurrent failed (0x%x)", (unsigned)eglGetError());
        goto fail;
    }
    if (epoxy_gl_version() < 45) {
        sl_err_set(err, SL_ERR_GPU, "OpenGL 4.5 is required, the context offers %d.%d",
                   epoxy_gl_version() / 10, epoxy_gl_version() % 10);
        goto fail;
    }
    snprintf(gpu->renderer, sizeof gpu->renderer, "%s", (const char *)glGetString(GL_RENDERER));
    if (desc->debug) {
        glEnable(GL_DEBUG_OUTPUT);
        glDebugMessageCallback(debug_callback, NULL);
    }
    if (!desc->quiet)
        fprintf(stderr, "sightline: OpenGL renderer: %s (%s)\n", gpu->renderer,
                gpu->software ? "software" : "hardware");
    *out = gpu;
    return SL_OK;
fail:
    sl_gpu_destroy(gpu);
    return err ? err->status : SL_ERR_GPU;
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
