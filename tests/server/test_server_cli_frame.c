/* test_server_cli_frame.c — a server snapshot equals sightline-render on the same scene.
 *
 * For two techniques (tubes_mesh, tubes), one session on the harness's
 * "tiny" dataset switches to the technique with non-default params, an
 * orbit camera and a background (`scene`, `set`), then asks for a
 * `snapshot` (lossless PNG, full size). sightline-render renders the same
 * scene (the same generator call, technique, params, camera, size,
 * background; --samples 1, as the server renders without MSAA) to a PNG.
 * Compared over the covered pixels (sl_diff_images_covered with the
 * background colour, as sightline-diff --background): mean |difference|
 * <= 0.5 and at most 0.5% of the covered pixels off by more than 16 (of
 * 255), with at least 2% of the frame covered, both images the requested
 * size and the background where nothing is drawn. A negative control: the
 * CLI at an azimuth 8 degrees off must fail those limits, so the comparison
 * can fail. Server exit status 0 required. Loopback only; single thread.
 */
#include <math.h>

#include "image/sl_diff.h"
#include "image/sl_image.h"
#include "sl_server_harness.h"
#include "sl_test.h"

#define W 192
#define H 144
#define T 60000
#define MAX_MEAN 0.5
#define BAD_THRESHOLD 16.0
#define MAX_BAD_PCT 0.5
/* 0.2, 0.4, 0.6 are exact in 8 bits (51, 102, 153): the cleared pixels' bytes. */
#define BACKGROUND "[0.2,0.4,0.6,1]"
static const uint8_t background_rgb[3] = {51, 102, 153};

typedef struct scene_case {
    const char *technique;
    const char *params;   /* JSON object, the same text to the server and the CLI */
    double azimuth, elevation, distance, fov_y;
} scene_case;

static const scene_case cases[] = {
    {"tubes_mesh", "{\"radius\":0.012,\"colormap\":\"magma\",\"sides\":10,\"light_direction\":[0.2,0.8,0.6]}",
     70, 25, 2.2, 40},
    {"tubes", "{\"radius\":0.01,\"colormap\":\"plasma\",\"specular\":0.6,\"shininess\":64}", 200, -15, 2.4, 45},
};

static void camera_json(char *out, size_t size, const scene_case *c, double azimuth)
{
    snprintf(out, size, "{\"orbit\":{\"azimuth\":%.17g,\"elevation\":%.17g,\"distance\":%.17g},\"fov_y\":%.17g}",
             azimuth, c->elevation, c->distance, c->fov_y);
}

/* Renders the case with sightline-render at the given azimuth; 0 and the image, or -1. */
static int cli_render(const harness *h, const scene_case *c, double azimuth, const char *name, sl_image *out)
{
    char camera[256], scene[1024];
    camera_json(camera, sizeof camera, c, azimuth);
    snprintf(scene, sizeof scene, "{\"dataset\":%s,\"technique\":\"%s\",\"params\":%s,\"camera\":%s,\"width\":%d,"
             "\"height\":%d,\"background\":%s}\n", HARNESS_TINY, c->technique, c->params, camera, W, H, BACKGROUND);
    int rc = harness_cli_render(h, scene, name, out);
    SL_CHECK_MSG(rc == 0, "sightline-render (%s) rendered", name);
    return rc;
}

/* Waits for the PNG snapshot; 0 and the decoded image, or -1. Counts error messages. */
static int wait_snapshot(tclient *c, sl_image *out, int *errors)
{
    double deadline = sl_clock_ms() + T;
    while (sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(c, (int)(deadline - sl_clock_ms()) + 1, &j);
        if (r == 1 && strcmp(json_type(j), "error") == 0) {
            char *text = cJSON_PrintUnformatted(j);
            fprintf(stderr, "server error: %s\n", text ? text : "?");
            cJSON_free(text);
            (*errors)++;
        }
        cJSON_Delete(j);
        if (r == 2 && c->last.h.kind == SL_FRAME_PNG) {
            sl_err err = {0};
            if (sl_png_decode(c->last.payload, c->last.h.payload_bytes, out, &err) == SL_OK)
                return 0;
            fprintf(stderr, "snapshot does not decode: %s\n", err.message);
            return -1;
        }
        if (r == 0 || (r < 0 && c->closed))
            return -1;
    }
    return -1;
}

static int is_background(const sl_image *img, int x, int y)
{
    const uint8_t *p = img->rgba + ((size_t)y * (size_t)img->width + (size_t)x) * 4;
    return p[0] == background_rgb[0] && p[1] == background_rgb[1] && p[2] == background_rgb[2];
}

static int within_limits(const sl_diff_result *d)
{
    return d->mean_abs <= MAX_MEAN && d->bad_pct <= MAX_BAD_PCT;
}

static void run_case(const harness *h, tclient *c, const scene_case *sc, int negative_control)
{
    char camera[256];
    camera_json(camera, sizeof camera, sc, sc->azimuth);
    int errors = 0;
    sl_image snap = {0}, ref = {0}, off = {0};
    if (tclient_send(c, "{\"type\":\"scene\",\"technique\":\"%s\",\"params\":%s,\"camera\":%s}", sc->technique,
                     sc->params, camera) ||
        tclient_send(c, "{\"type\":\"set\",\"background\":%s}", BACKGROUND) ||
        tclient_send(c, "{\"type\":\"snapshot\"}")) {
        SL_CHECK_MSG(0, "%s: send failed: %s", sc->technique, c->err.message);
        return;
    }
    int got = wait_snapshot(c, &snap, &errors) == 0;
    SL_CHECK_MSG(got, "%s: a snapshot arrived", sc->technique);
    SL_CHECK_MSG(errors == 0, "%s: %d error messages", sc->technique, errors);
    int have_ref = cli_render(h, sc, sc->azimuth, sc->technique, &ref) == 0;
    if (got && have_ref) {
        SL_CHECK_MSG(snap.width == W && snap.height == H && ref.width == W && ref.height == H,
                     "%s: sizes %dx%d (server), %dx%d (CLI), want %dx%d", sc->technique, snap.width, snap.height,
                     ref.width, ref.height, W, H);
        SL_CHECK_MSG(is_background(&snap, 0, 0) && is_background(&ref, 0, 0), "%s: corner pixel is the background",
                     sc->technique);
        sl_diff_result d;
        sl_err err = {0};
        if (sl_diff_images_covered(&snap, &ref, BAD_THRESHOLD, background_rgb, &d, NULL, &err) == SL_OK) {
            printf("%s: covered %ld of %ld pixels; mean %.4f, max %.0f, %.3f%% over %.0f\n", sc->technique,
                   d.compared, d.pixels, d.mean_abs, d.max_abs, d.bad_pct, BAD_THRESHOLD);
            SL_CHECK_MSG(d.compared >= d.pixels / 50, "%s: only %ld of %ld pixels covered", sc->technique, d.compared,
                         d.pixels);
            SL_CHECK_MSG(within_limits(&d), "%s: server snapshot differs from sightline-render: mean %.4f (max %.1f), "
                         "%.3f%% of covered pixels over %.0f (max %.1f%%)", sc->technique, d.mean_abs, MAX_MEAN,
                         d.bad_pct, BAD_THRESHOLD, MAX_BAD_PCT);
        } else {
            SL_CHECK_MSG(0, "%s: diff: %s", sc->technique, err.message);
        }
        if (negative_control) {
            char name[80];
            snprintf(name, sizeof name, "%s_off", sc->technique);
            if (cli_render(h, sc, sc->azimuth + 8, name, &off) == 0 &&
                sl_diff_images_covered(&snap, &off, BAD_THRESHOLD, background_rgb, &d, NULL, &err) == SL_OK) {
                printf("%s at azimuth + 8: mean %.4f, %.3f%% over %.0f\n", sc->technique, d.mean_abs, d.bad_pct,
                       BAD_THRESHOLD);
                SL_CHECK_MSG(!within_limits(&d), "%s: a camera 8 degrees off passes the limits (mean %.4f, %.3f%%)",
                             sc->technique, d.mean_abs, d.bad_pct);
            } else {
                SL_CHECK_MSG(0, "%s: negative control did not render", sc->technique);
            }
        }
    }
    sl_image_deinit(&snap);
    sl_image_deinit(&ref);
    sl_image_deinit(&off);
}

int main(void)
{
    harness h;
    HARNESS_START_OR_END(h, NULL);
    tclient c;
    if (tclient_connect(&c, h.port, NULL) != 0 || tclient_hello(&c, NULL, NULL, W, H) != 0) {
        SL_CHECK(!"connected");
    } else {
        c.auto_ack = 1;
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
            run_case(&h, &c, &cases[i], i == 0);
    }
    tclient_close(&c);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
