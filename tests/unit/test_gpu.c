/* test_gpu.c — choosing the EGL display and context (renderer/gpu/egl_context.c), on llvmpipe.
 *
 * The candidate loop is driven with sl_gpu_desc.test_fail_mask (a candidate
 * fails as if its context could not be made) and .software_devices (Mesa's
 * software EGL device becomes a candidate before surfaceless, so there are
 * two to fall back between on a machine without a GPU): a failed first
 * candidate falls back to the next, an explicit device choice never falls
 * back, and when all fail the error names each candidate and its reason.
 * Malformed SIGHTLINE_EGL_DEVICE values are refused naming the variable;
 * "software" is judged from the renderer string. The process-level failures
 * (no EGL vendor, no 4.5 context) are in tests/render/gpu.cmake, since they
 * need the environment of a fresh process. Single-threaded.
 */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu/sl_gpu.h"
#include "sl_test.h"

static int names_cpu_rasterizer(const char *renderer)
{
    char lower[256];
    size_t k = 0;
    for (; renderer[k] && k + 1 < sizeof lower; k++)
        lower[k] = (char)tolower((unsigned char)renderer[k]);
    lower[k] = '\0';
    return strstr(lower, "llvmpipe") || strstr(lower, "softpipe") || strstr(lower, "swrast");
}

/* Creates with desc; returns the status, fills name/renderer (when made) and err. */
static sl_status try_create(sl_gpu_desc desc, char *name, size_t name_size, int *software, sl_err *err)
{
    desc.quiet = 1;
    sl_gpu *gpu = NULL;
    memset(err, 0, sizeof *err);
    sl_status st = sl_gpu_create(&desc, &gpu, err);
    if (st == SL_OK) {
        snprintf(name, name_size, "%s", sl_gpu_display_name(gpu));
        *software = sl_gpu_is_software(gpu);
        /* The context is current and usable. */
        GLint major = 0;
        glGetIntegerv(GL_MAJOR_VERSION, &major);
        SL_CHECK_MSG(major >= 4, "GL major version %d", major);
        sl_gpu_destroy(gpu);
    } else {
        SL_CHECK_MSG(gpu == NULL, "a failed create must leave *out NULL");
        name[0] = '\0';
    }
    return st;
}

static void test_default(void)
{
    sl_err err;
    sl_gpu *gpu = NULL;
    sl_status st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err);
    SL_CHECK_MSG(st == SL_OK, "default context: %s", err.message);
    if (st != SL_OK)
        return;
    const char *r = sl_gpu_renderer(gpu);
    SL_CHECK(r && r[0]);
    printf("renderer: %s via %s (%s)\n", r, sl_gpu_display_name(gpu), sl_gpu_is_software(gpu) ? "software" : "hardware");
    /* Software is what the renderer string says (llvmpipe here), whatever the platform. */
    if (names_cpu_rasterizer(r))
        SL_CHECK_MSG(sl_gpu_is_software(gpu), "'%s' must count as software", r);
    sl_gpu_destroy(gpu);
    /* A second context after the first is gone (the display stays initialized). */
    st = sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err);
    SL_CHECK_MSG(st == SL_OK, "second context: %s", err.message);
    sl_gpu_destroy(gpu);
    sl_gpu_destroy(NULL);
}

static void test_fallback(void)
{
    char name[64];
    int software = -1;
    sl_err err;

    /* Software forced: llvmpipe, labelled software from its renderer string. */
    sl_status st = try_create((sl_gpu_desc){.device = "software"}, name, sizeof name, &software, &err);
    SL_CHECK_MSG(st == SL_OK, "software: %s", err.message);
    SL_CHECK(software == 1);
    int software_device = st == SL_OK && strncmp(name, "EGL device ", 11) == 0;
    printf("software: %s\n", name);

    /* With software devices as candidates, device platform first. Skip the
     * two-candidate checks only if this EGL has no device (then there is
     * nothing to fall back from; CI's Mesa has one). */
    st = try_create((sl_gpu_desc){.software_devices = 1}, name, sizeof name, &software, &err);
    SL_CHECK_MSG(st == SL_OK, "software_devices: %s", err.message);
    int have_device = st == SL_OK && strncmp(name, "EGL device ", 11) == 0;
    SL_CHECK_MSG(have_device, "software_devices: expected an EGL device first, got '%s'", name);
    if (!have_device)
        return;
    SL_CHECK(software == 1);

    /* The first candidate fails: the next one (surfaceless) is used. */
    st = try_create((sl_gpu_desc){.software_devices = 1, .test_fail_mask = 1u}, name, sizeof name, &software, &err);
    SL_CHECK_MSG(st == SL_OK, "fallback: %s", err.message);
    SL_CHECK_MSG(strcmp(name, "Mesa surfaceless") == 0, "fallback: display '%s'", name);
    SL_CHECK(software == 1);

    /* Every candidate fails: SL_ERR_GPU naming each, in order, with its reason. */
    st = try_create((sl_gpu_desc){.software_devices = 1, .test_fail_mask = ~0u}, name, sizeof name, &software, &err);
    SL_CHECK(st == SL_ERR_GPU);
    const char *dev = strstr(err.message, "EGL device 0: failure injected");
    const char *sfl = strstr(err.message, "Mesa surfaceless: failure injected");
    SL_CHECK_MSG(strstr(err.message, "no usable OpenGL 4.5 core context") && dev && sfl && dev < sfl, "all fail: %s",
                 err.message);

    /* An explicit choice never falls back. */
    st = try_create((sl_gpu_desc){.device = "0", .test_fail_mask = 1u}, name, sizeof name, &software, &err);
    SL_CHECK(st == SL_ERR_GPU);
    SL_CHECK_MSG(strstr(err.message, "EGL device 0: failure injected") && !strstr(err.message, "surfaceless"),
                 "device 0: %s", err.message);
    /* "software": Mesa's software device first, then surfaceless (kept only on a CPU rasterizer). */
    SL_CHECK_MSG(software_device, "software: expected Mesa's software EGL device first, got '%s'", name);
    st = try_create((sl_gpu_desc){.device = "software", .test_fail_mask = 1u}, name, sizeof name, &software, &err);
    SL_CHECK_MSG(st == SL_OK && strcmp(name, "Mesa surfaceless") == 0 && software == 1, "software, device failed: %s",
                 st ? err.message : name);
    st = try_create((sl_gpu_desc){.device = "software", .test_fail_mask = ~0u}, name, sizeof name, &software, &err);
    SL_CHECK(st == SL_ERR_GPU);
    dev = strstr(err.message, "EGL device 0: failure injected");
    sfl = strstr(err.message, "Mesa surfaceless: failure injected");
    SL_CHECK_MSG(dev && sfl && dev < sfl, "software, all fail: %s", err.message);
    /* Device 0 chosen explicitly works (a software device may be chosen by index). */
    st = try_create((sl_gpu_desc){.device = "0"}, name, sizeof name, &software, &err);
    SL_CHECK_MSG(st == SL_OK && strcmp(name, "EGL device 0") == 0, "device 0: %s", st ? err.message : name);
}

static void test_bad_choices(void)
{
    char name[64];
    int software;
    sl_err err;
    const char *bad[] = {"abc", "-1", "1x", "+1", " 1", "0x1", "1.5", "Software", "99999999999999999999"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        sl_status st = try_create((sl_gpu_desc){.device = bad[k]}, name, sizeof name, &software, &err);
        SL_CHECK_MSG(st == SL_ERR_INVALID, "device '%s': status %d", bad[k], (int)st);
        SL_CHECK_MSG(strstr(err.message, "SIGHTLINE_EGL_DEVICE must be 'software' or a device index") &&
                         strstr(err.message, bad[k]),
                     "device '%s': %s", bad[k], err.message);
    }
    /* A well-formed index beyond the devices: says how many there are. */
    sl_status st = try_create((sl_gpu_desc){.device = "99"}, name, sizeof name, &software, &err);
    SL_CHECK(st == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "EGL device 99 requested but only ") != NULL, "99: %s", err.message);
    /* The empty string means automatic, like an unset variable. */
    st = try_create((sl_gpu_desc){.device = ""}, name, sizeof name, &software, &err);
    SL_CHECK_MSG(st == SL_OK, "empty choice: %s", err.message);
}

static void test_target_limits(void)
{
    sl_err err;
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        SL_CHECK_MSG(0, "%s", err.message);
        return;
    }
    GLint max_samples = 0, max_size = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    SL_CHECK(sl_target_check(64, 64, 0, &err) == SL_OK);
    SL_CHECK(sl_target_check(64, 64, 1, &err) == SL_OK);
    SL_CHECK_MSG(sl_target_check(64, 64, max_samples, &err) == SL_OK, "%d samples: %s", max_samples, err.message);
    /* Above the GPU's limits: UNSUPPORTED (a GPU limit, exit 3 in sightline-render), naming it. */
    SL_CHECK(sl_target_check(64, 64, max_samples + 1, &err) == SL_ERR_UNSUPPORTED);
    char want[64];
    snprintf(want, sizeof want, "offers at most %d", max_samples);
    SL_CHECK_MSG(strstr(err.message, want) != NULL, "%s", err.message);
    SL_CHECK(sl_target_check(max_size + 1, 8, 0, &err) == SL_ERR_UNSUPPORTED);
    SL_CHECK(sl_target_check(0, 8, 0, &err) == SL_ERR_INVALID);
    sl_target t;
    SL_CHECK(sl_target_init(&t, 16, 16, max_samples + 1, &err) == SL_ERR_UNSUPPORTED);
    SL_CHECK(sl_target_init(&t, 16, 16, max_samples, &err) == SL_OK);
    sl_target_deinit(&t);
    sl_gpu_destroy(gpu);
}

int main(void)
{
    /* The tests pass devices explicitly; an inherited override must not steer the automatic cases. */
    unsetenv("SIGHTLINE_EGL_DEVICE");
    test_default();
    test_fallback();
    test_bad_choices();
    test_target_limits();
    SL_TEST_END();
}
