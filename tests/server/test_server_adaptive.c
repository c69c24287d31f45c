/* test_server_adaptive.c — the adaptive interactive scale against a running sightline-server.
 *
 * A slow scene is made with the server's test option --test-frame-delay-ms
 * (a sleep of DELAY x frame pixels / session pixels added to every frame's
 * render, so the cost scales with the pixel count as a fill-bound render
 * does; real slow techniques on llvmpipe under ASan would take minutes).
 * Checks: the stream settings' defaults and range errors; on the slow scene
 * a drag's interactive frames come back at 1/4 (1/8 allowed when the machine
 * is busy), never larger, from the first interactive frame on (the still
 * frame seeds the estimate), and the still frame after the drag is full
 * size; with interactive_adaptive off the same drag stays at the fixed
 * interactive_scale; a 300 ms budget gives 1/2; a cost that does not shrink
 * with the image (--test-frame-fixed-ms, as a vertex-bound technique) ends
 * back at full size once the smaller steps proved no faster, and the next
 * drag stays there; without a delay (a fast scene) interactive frames stay
 * at full size. Exit status 0 required.
 */
#include "sl_server_harness.h"
#include "sl_test.h"

#define W 320
#define H 240
#define FAST_W 160        /* the fast scene: a quarter of the pixels, so a busy machine stays under budget */
#define FAST_H 120
#define DELAY_MS 600      /* full-size cost on the slow server: 1/2 costs 150, 1/4 37.5, 1/8 9.4 */
#define FIXED_MS 300      /* the vertex-bound server: every frame costs 300 ms at any size */
#define DRAG_MS 1500
#define VERTEX_FRAMES 12  /* the vertex-bound drag: frames enough to try the smaller steps and come back */
#define T 30000

typedef struct drag_result {
    int frames;                   /* interactive frames received during the drag */
    int first_w, last_w, min_w, max_w; /* their widths */
    int heights_ok;               /* every height matches its width's scale */
    int still_w, still_h, still_interactive;
    int still_ok;
} drag_result;

/* Drags for drag_ms at 30 Hz (moves sent whether or not frames arrive, as a
 * mouse does) and on until min_frames interactive frames came (at most T), then
 * `end`, and waits for the still frame. */
static drag_result drag_for(tclient *c, uint32_t *seq, int sw, int sh, int drag_ms, int min_frames)
{
    drag_result r = {.min_w = 1 << 30, .heights_ok = 1};
    double t0 = sl_clock_ms(), next = t0;
    double az = 10;
    while ((sl_clock_ms() - t0 < drag_ms || r.frames < min_frames) && sl_clock_ms() - t0 < T) {
        if (sl_clock_ms() >= next) {
            tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"phase\":\"move\",\"camera\":{\"orbit\":"
                            "{\"azimuth\":%.2f,\"elevation\":20,\"distance\":2.5}}}", ++*seq, az += 3);
            next += 1000.0 / 30.0;
        }
        int wait = (int)(next - sl_clock_ms());
        if (tclient_next(c, wait < 1 ? 1 : wait, NULL) == 2 && c->last.h.kind == SL_FRAME_JPEG &&
            (c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE)) {
            int w = c->last.h.width, h = c->last.h.height;
            if (r.frames++ == 0)
                r.first_w = w;
            r.last_w = w;
            r.min_w = w < r.min_w ? w : r.min_w;
            r.max_w = w > r.max_w ? w : r.max_w;
            if (w <= 0 || abs(h - (int)lround((double)sh * w / sw)) > 1)
                r.heights_ok = 0;
        }
    }
    tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"phase\":\"end\",\"camera\":{\"orbit\":"
                    "{\"azimuth\":%.2f,\"elevation\":20,\"distance\":2.5}}}", ++*seq, az);
    r.still_ok = tclient_wait_frame(c, *seq, 1, T) == 0;
    r.still_w = c->last.h.width;
    r.still_h = c->last.h.height;
    r.still_interactive = (c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE) != 0;
    printf("drag: %d interactive frames, widths first %d min %d max %d; still %dx%d\n", r.frames, r.first_w,
           r.min_w, r.max_w, r.still_w, r.still_h);
    return r;
}

static drag_result drag(tclient *c, uint32_t *seq, int sw, int sh)
{
    return drag_for(c, seq, sw, sh, DRAG_MS, 3);
}

/* Sends a stream patch and waits for the still frame the change causes. */
static int set_stream(tclient *c, const char *json)
{
    if (tclient_send(c, "{\"type\":\"set\",\"stream\":%s}", json) != 0)
        return -1;
    cJSON *st = tclient_wait_type(c, "state", T);
    cJSON_Delete(st);
    return st && tclient_wait_frame(c, 0, 1, T) == 0 ? 0 : -1;
}

static int error_field_is(cJSON *e, const char *field)
{
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(e, "field");
    const cJSON *code = cJSON_GetObjectItemCaseSensitive(e, "code");
    return cJSON_IsString(f) && strcmp(f->valuestring, field) == 0 && cJSON_IsString(code) &&
           strcmp(code->valuestring, "bad_field") == 0;
}

static int connect_session(tclient *c, int port, int w, int h)
{
    if (tclient_connect(c, port, NULL) != 0 || tclient_hello(c, NULL, NULL, w, h) != 0)
        return -1;
    c->auto_ack = 1;
    return tclient_wait_frame(c, 0, 1, T);
}

static void slow_scene(void)
{
    harness hs;
    char delay[16];
    snprintf(delay, sizeof delay, "%d", DELAY_MS);
    /* Frames sleep in proportion to their pixels, and the adaptive scale sees exactly that
     * cost (--test-frame-time-ms), not the real render on top, so its choices are this
     * machine's whatever its speed. */
    const char *extra[] = {"--test-frame-delay-ms", delay, "--test-frame-time-ms", delay, NULL};
    SL_CHECK(harness_start(&hs, extra) == 0);
    tclient a;
    SL_CHECK(connect_session(&a, hs.port, W, H) == 0);
    SL_CHECK(a.last.h.width == W && a.last.h.height == H);
    SL_CHECK_MSG(a.last.h.render_ms >= DELAY_MS * 0.95, "still render %.0f ms with a %d ms delay",
                 a.last.h.render_ms, DELAY_MS);

    /* defaults: adaptive, upper bound 1, 100 ms budget */
    const cJSON *stream = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(a.welcome, "state"),
                                                           "stream");
    const cJSON *ad = cJSON_GetObjectItemCaseSensitive(stream, "interactive_adaptive");
    const cJSON *bu = cJSON_GetObjectItemCaseSensitive(stream, "interactive_budget_ms");
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(stream, "interactive_scale");
    SL_CHECK(cJSON_IsTrue(ad));
    SL_CHECK(cJSON_IsNumber(bu) && bu->valueint == 100);
    SL_CHECK(cJSON_IsNumber(sc) && sc->valuedouble == 1.0);
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"stream\":{\"interactive_budget_ms\":5}}") == 0);
    cJSON *e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_field_is(e, "stream.interactive_budget_ms"));
    cJSON_Delete(e);
    SL_CHECK(tclient_send(&a, "{\"type\":\"set\",\"stream\":{\"interactive_adaptive\":1}}") == 0);
    e = tclient_wait_type(&a, "error", T);
    SL_CHECK(error_field_is(e, "stream.interactive_adaptive"));
    cJSON_Delete(e);

    /* slow at full size (600 ms): 1/4 from the first interactive frame on */
    uint32_t seq = 0;
    drag_result r = drag(&a, &seq, W, H);
    SL_CHECK_MSG(r.frames >= 3, "%d interactive frames in %d ms", r.frames, DRAG_MS);
    SL_CHECK_MSG(r.first_w == W / 4, "first interactive frame %d wide, expected %d (1/4)", r.first_w, W / 4);
    SL_CHECK_MSG(r.max_w == W / 4 && r.min_w >= W / 8, "interactive widths %d..%d, expected %d (or %d when busy)",
                 r.min_w, r.max_w, W / 4, W / 8);
    SL_CHECK(r.heights_ok);
    SL_CHECK_MSG(r.still_ok && r.still_w == W && r.still_h == H && !r.still_interactive,
                 "still %dx%d interactive %d", r.still_w, r.still_h, r.still_interactive);

    /* a second drag starts from what the first one learned, not at full size */
    int learned = r.last_w;
    r = drag(&a, &seq, W, H);
    SL_CHECK_MSG(r.first_w <= learned && r.max_w <= W / 4 && r.min_w >= W / 8,
                 "second drag widths first %d (first drag ended at %d), %d..%d", r.first_w, learned, r.min_w, r.max_w);

    /* adaptive off: the fixed interactive_scale (1), however slow */
    SL_CHECK(set_stream(&a, "{\"interactive_adaptive\":false}") == 0);
    r = drag(&a, &seq, W, H);
    SL_CHECK_MSG(r.frames >= 1 && r.min_w == W && r.max_w == W, "fixed scale 1: widths %d..%d", r.min_w, r.max_w);
    SL_CHECK(r.still_ok && r.still_w == W);
    SL_CHECK(set_stream(&a, "{\"interactive_adaptive\":false,\"interactive_scale\":0.5}") == 0);
    r = drag(&a, &seq, W, H);
    SL_CHECK_MSG(r.frames >= 1 && r.min_w == W / 2 && r.max_w == W / 2, "fixed scale 0.5: widths %d..%d", r.min_w,
                 r.max_w);
    tclient_close(&a);

    /* a new session with a 300 ms budget: 1/2 (150 ms) fits, full size does not */
    tclient b;
    SL_CHECK(connect_session(&b, hs.port, W, H) == 0);
    SL_CHECK(set_stream(&b, "{\"interactive_budget_ms\":300}") == 0);
    seq = 0;
    r = drag(&b, &seq, W, H);
    SL_CHECK_MSG(r.first_w == W / 2 && r.max_w == W / 2 && r.min_w >= W / 4, "budget 300: widths first %d, %d..%d",
                 r.first_w, r.min_w, r.max_w);
    SL_CHECK(r.still_ok && r.still_w == W && r.still_h == H);
    tclient_close(&b);
    int status = harness_stop(&hs);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
}

/* A cost that does not shrink with the image: smaller steps are tried, found
 * no faster, and the drag settles back at full size instead of the floor. The
 * frames sleep FIXED_MS (so they arrive at that pace) and the adaptive scale
 * sees exactly FIXED_MS (--test-frame-time-fixed-ms: the real render and encode
 * time, which does shrink with the image and is long under ASan, is not what
 * it decides on); the drag lasts until VERTEX_FRAMES interactive frames came. */
static void vertex_bound_scene(void)
{
    harness hs;
    char fixed[16];
    snprintf(fixed, sizeof fixed, "%d", FIXED_MS);
    const char *extra[] = {"--test-frame-fixed-ms", fixed, "--test-frame-time-fixed-ms", fixed, NULL};
    SL_CHECK(harness_start(&hs, extra) == 0);
    tclient c;
    SL_CHECK(connect_session(&c, hs.port, W, H) == 0);
    uint32_t seq = 0;
    drag_result r = drag_for(&c, &seq, W, H, 0, VERTEX_FRAMES);
    SL_CHECK_MSG(r.frames >= VERTEX_FRAMES, "%d interactive frames", r.frames);
    SL_CHECK_MSG(r.min_w < W, "vertex-bound: smaller steps were never tried (widths %d..%d)", r.min_w, r.max_w);
    SL_CHECK_MSG(r.last_w == W, "vertex-bound: the drag ended at width %d, not back at full size %d", r.last_w, W);
    SL_CHECK(r.still_ok && r.still_w == W);
    r = drag(&c, &seq, W, H);
    SL_CHECK_MSG(r.frames >= 2 && r.min_w == W, "vertex-bound second drag: widths %d..%d, expected %d throughout",
                 r.min_w, r.max_w, W);
    tclient_close(&c);
    int status = harness_stop(&hs);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
}

/* A scene whose frames cost 20 ms at full size (injected: --test-frame-time-ms, so a slow
 * sanitizer build on a busy machine decides the same as a fast one): the drag stays at
 * full size. */
static void fast_scene(void)
{
    harness hs;
    const char *extra[] = {"--test-frame-time-ms", "20", NULL};
    SL_CHECK(harness_start(&hs, extra) == 0);
    tclient c;
    SL_CHECK(connect_session(&c, hs.port, FAST_W, FAST_H) == 0);
    uint32_t seq = 0;
    drag_result r = drag(&c, &seq, FAST_W, FAST_H);
    SL_CHECK_MSG(r.frames >= 3, "%d interactive frames", r.frames);
    SL_CHECK_MSG(r.min_w == FAST_W && r.max_w == FAST_W, "fast scene: interactive widths %d..%d, expected %d",
                 r.min_w, r.max_w, FAST_W);
    SL_CHECK(r.still_ok && r.still_w == FAST_W && !r.still_interactive);
    tclient_close(&c);
    int status = harness_stop(&hs);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
}

int main(void)
{
    slow_scene();
    vertex_bound_scene();
    fast_scene();
    SL_TEST_END();
}
