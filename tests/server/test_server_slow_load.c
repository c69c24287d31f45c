/* test_server_slow_load.c — one session's slow dataset load does not stop another's frames.
 *
 * The server runs with --test-load-delay-ms 2000 (every load sleeps first,
 * on a loader thread), so the load is slow in any build. Sessions A, B
 * (64x64) start on "tiny"; a thread drives B: a camera move after each
 * frame it receives, every arrival time recorded. A switches to
 * furball_787k with the `tubes` technique (787k segments; the cheapest
 * prepare at that size); once A's `loading` arrives, a new session C asks
 * for the same dataset with another prepare-level parameter (tangents
 * catmull_rom: its own prepared scene). Checks:
 *  - A's `progress`: loading, preparing, first_frame, done — each once, in
 *    that order, one round, naming furball_787k/tubes and the new version;
 *    fraction null or in [0, 1]; elapsed_ms not decreasing; load_ms at
 *    least the delay; done has ok and the id of A's next frame, which shows
 *    the new version; that frame's header render_ms is done's render_ms
 *    and excludes the load and the prepare (load + prepare + render fit in
 *    the round's elapsed_ms);
 *  - B while A's load ran (A's `loading` to A's `preparing`): at least 5
 *    frames, and no gap between them (or the window's ends) of half the
 *    load time or more — the render thread kept serving B;
 *  - C joins A's load while it is in flight: one more load in /metrics for
 *    both sessions (two more prepares: their parameters differ at the
 *    prepare level), and C's progress shows loading ... done too;
 *  - A asks for "abc" (a load) and, once its `loading` arrives, for "tiny"
 *    again (loaded: B shows it): the abc round ends with done, ok false, no
 *    error comes, and A's next still frame shows the tiny state.
 * Prints B's longest gap in the load window and during A's prepare and
 * first frame (the part that still runs on the render thread, not bounded
 * here: that is the technique's prepare and render cost).
 */
#include <pthread.h>
#include <stdatomic.h>

#include "sl_server_harness.h"
#include "sl_test.h"

#define W 64
#define H 64
#define DELAY_MS 2000
#define T 120000
#define MAX_ARRIVALS 8192

typedef struct driver {
    int port;
    atomic_int stop;
    pthread_mutex_t lock;
    pthread_cond_t changed;
    int ok, done;                   /* [lock] */
    int n;                          /* [lock] frames recorded */
    double arrival[MAX_ARRIVALS];   /* read by main after the join */
} driver;

static void driver_set(driver *d, int ok, int done, double arrival)
{
    pthread_mutex_lock(&d->lock);
    d->ok = ok;
    d->done = done;
    if (arrival > 0 && d->n < MAX_ARRIVALS)
        d->arrival[d->n++] = arrival;
    pthread_cond_broadcast(&d->changed);
    pthread_mutex_unlock(&d->lock);
}

/* Waits until B has `frames` frames or ended; returns B's frame count. */
static int driver_wait_frames(driver *d, int frames, int timeout_ms)
{
    struct timespec ts = sl_clock_deadline(timeout_ms);
    pthread_mutex_lock(&d->lock);
    while (d->n < frames && !d->done && pthread_cond_timedwait(&d->changed, &d->lock, &ts) == 0)
        ;
    int n = d->n;
    pthread_mutex_unlock(&d->lock);
    return n;
}

static void *drive_b(void *arg)
{
    driver *d = arg;
    tclient b;
    int ok = tclient_connect(&b, d->port, NULL) == 0 && tclient_hello(&b, NULL, NULL, W, H) == 0;
    b.auto_ack = 1;
    ok = ok && tclient_wait_frame(&b, 0, 1, T) == 0;
    for (uint32_t seq = 1; ok && !atomic_load(&d->stop); seq++) {
        ok = tclient_send(&b, "{\"type\":\"camera\",\"seq\":%u,\"phase\":\"move\",\"camera\":{\"orbit\":{"
                              "\"azimuth\":%u,\"elevation\":10,\"distance\":2.5}}}", seq, seq % 360) == 0 &&
             tclient_wait_frame(&b, seq, 0, T) == 0;
        driver_set(d, ok, 0, ok ? b.last.arrival_ms : 0);
    }
    pthread_mutex_lock(&d->lock);
    int n = d->n;
    pthread_mutex_unlock(&d->lock);
    driver_set(d, ok && n > 0, 1, 0);
    tclient_close(&b);
    return NULL;
}

/* Longest stretch of [t0, t1] without one of B's frames. */
static double longest_gap(const driver *d, double t0, double t1, int *frames)
{
    double prev = t0, gap = 0;
    *frames = 0;
    for (int i = 0; i < d->n; i++) {
        if (d->arrival[i] < t0 || d->arrival[i] > t1)
            continue;
        (*frames)++;
        if (d->arrival[i] - prev > gap)
            gap = d->arrival[i] - prev;
        prev = d->arrival[i];
    }
    return t1 - prev > gap ? t1 - prev : gap;
}

typedef struct progress_log {
    int count;
    char stage[8][16];
    double at_ms[8];      /* arrival */
    cJSON *msg[8];
} progress_log;

/* Records a progress message (j consumed); other messages are dropped. */
static void log_progress(progress_log *p, cJSON *j)
{
    if (strcmp(json_type(j), "progress") != 0 || p->count >= 8) {
        cJSON_Delete(j);
        return;
    }
    const char *stage = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "stage"));
    snprintf(p->stage[p->count], sizeof p->stage[0], "%s", stage ? stage : "");
    p->at_ms[p->count] = sl_clock_ms();
    p->msg[p->count++] = j;
}

static double num(const cJSON *j, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(j, key);
    return cJSON_IsNumber(v) ? v->valuedouble : -1;
}

static int find_stage(const progress_log *p, const char *stage)
{
    for (int i = 0; i < p->count; i++)
        if (strcmp(p->stage[i], stage) == 0)
            return i;
    return -1;
}

int main(void)
{
    harness h;
    const char *extra[] = {"--test-load-delay-ms", "2000", NULL};
    HARNESS_START_OR_END(h, extra);
    tclient a, c;
    SL_CHECK(tclient_connect(&a, h.port, NULL) == 0 && tclient_hello(&a, NULL, NULL, W, H) == 0);
    a.auto_ack = 1;
    SL_CHECK(tclient_wait_frame(&a, 0, 1, T) == 0);
    driver *d = calloc(1, sizeof *d);
    d->port = h.port;
    pthread_mutex_init(&d->lock, NULL);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, SL_CLOCK_ID);
    pthread_cond_init(&d->changed, &ca);
    pthread_condattr_destroy(&ca);
    pthread_t th;
    pthread_create(&th, NULL, drive_b, d);
    int before = driver_wait_frames(d, 5, T);
    SL_CHECK_MSG(before >= 5, "B is not getting frames before A's switch (%d)", before);

    double loads0 = harness_metric(h.port, "sightline_dataset_loads_total");
    double prepares0 = harness_metric(h.port, "sightline_prepare_ms_count");
    uint32_t version = (uint32_t)num(cJSON_GetObjectItemCaseSensitive(a.welcome, "state"), "version");
    double t_switch = sl_clock_ms();
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"furball_787k\",\"technique\":\"tubes\"}") == 0);
    progress_log pa = {0}, pc = {0};
    int a_frame = 0, c_frame = 0, c_started = 0;
    uint32_t a_frame_id = 0, a_frame_version = 0;
    float a_render_ms = 0;
    double deadline = sl_clock_ms() + T;
    while ((!a_frame || !c_frame) && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&a, c_started ? 20 : 200, &j);
        if (r == 1)
            log_progress(&pa, j);
        if (r == 2 && !a_frame && a.last.h.state_version > version && !(a.last.h.flags & SL_FRAME_FLAG_INTERACTIVE)) {
            a_frame = 1;
            a_frame_id = a.last.h.frame_id;
            a_frame_version = a.last.h.state_version;
            a_render_ms = a.last.h.render_ms;
        }
        if (r == 0)
            break;
        if (!c_started && find_stage(&pa, "loading") >= 0) {
            c_started = 1;
            SL_CHECK(tclient_connect(&c, h.port, NULL) == 0 && tclient_hello(&c, NULL, NULL, W, H) == 0);
            c.auto_ack = 1;
            SL_CHECK(tclient_send(&c, "{\"type\":\"scene\",\"dataset\":\"furball_787k\",\"technique\":\"tubes\","
                                      "\"params\":{\"tangents\":\"catmull_rom\"}}") == 0);
        }
        if (c_started && !c_frame) {
            cJSON *k = NULL;
            int rc = tclient_next(&c, 20, &k);
            if (rc == 1)
                log_progress(&pc, k);
            if (rc == 2 && c.last.h.state_version >= 2 && !(c.last.h.flags & SL_FRAME_FLAG_INTERACTIVE))
                c_frame = 1;
        }
    }
    double t_end = sl_clock_ms();
    atomic_store(&d->stop, 1);
    pthread_join(th, NULL);
    SL_CHECK_MSG(d->ok, "B stopped getting frames");
    SL_CHECK_MSG(a_frame && c_frame, "A's frame %d, C's frame %d", a_frame, c_frame);

    /* A's progress: every stage once, in order, one round. */
    const char *order[] = {"loading", "preparing", "first_frame", "done"};
    SL_CHECK_MSG(pa.count == 4, "A got %d progress messages", pa.count);
    for (int i = 0; i < pa.count && i < 4; i++) {
        const cJSON *m = pa.msg[i];
        SL_CHECK_MSG(strcmp(pa.stage[i], order[i]) == 0, "A's progress %d is %s, expected %s", i, pa.stage[i],
                     order[i]);
        SL_CHECK(num(m, "round") == num(pa.msg[0], "round"));
        SL_CHECK(num(m, "version") > version);
        SL_CHECK(strcmp(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(m, "dataset")), "furball_787k") == 0);
        SL_CHECK(strcmp(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(m, "technique")), "tubes") == 0);
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(m, "fraction");
        SL_CHECK(cJSON_IsNull(f) || (cJSON_IsNumber(f) && f->valuedouble >= 0 && f->valuedouble <= 1));
        if (i > 0)
            SL_CHECK(num(m, "elapsed_ms") >= num(pa.msg[i - 1], "elapsed_ms"));
    }
    int il = find_stage(&pa, "loading"), ip = find_stage(&pa, "preparing"), id = find_stage(&pa, "done");
    double load_ms = id >= 0 ? num(pa.msg[id], "load_ms") : -1;
    double prepare_ms = id >= 0 ? num(pa.msg[id], "prepare_ms") : -1;
    if (id >= 0) {
        SL_CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(pa.msg[id], "ok")));
        SL_CHECK_MSG(num(pa.msg[id], "frame") == a_frame_id, "done names frame %g, A's frame is %u",
                     num(pa.msg[id], "frame"), a_frame_id);
        SL_CHECK(num(pa.msg[id], "version") == a_frame_version);
        SL_CHECK_MSG(load_ms >= DELAY_MS, "load_ms %.0f with a %d ms load delay", load_ms, DELAY_MS);
        /* Load, prepare and render follow one another inside the round: were the load or the prepare part
         * of the frame's render ms, the three would add up to more than the round took. */
        double elapsed = num(pa.msg[id], "elapsed_ms");
        SL_CHECK_MSG(fabs(num(pa.msg[id], "render_ms") - a_render_ms) < 0.1, "done render_ms %g, frame's %g",
                     num(pa.msg[id], "render_ms"), a_render_ms);
        SL_CHECK_MSG(a_render_ms + load_ms + prepare_ms <= elapsed + 1.0,
                     "frame render_ms %.0f + load %.0f + prepare %.0f > the round's %.0f ms", a_render_ms, load_ms,
                     prepare_ms, elapsed);
    }

    /* B kept receiving frames while A's dataset loaded. */
    if (il >= 0 && ip > il) {
        int frames = 0, frames_prep = 0;
        double gap = longest_gap(d, pa.at_ms[il], pa.at_ms[ip], &frames);
        double gap_prep = longest_gap(d, pa.at_ms[ip], id >= 0 ? pa.at_ms[id] : t_end, &frames_prep);
        printf("A: load %.0f ms (incl. %d ms test delay), prepare %.0f ms, first frame render %.0f ms, "
               "scene to frame %.0f ms\n", load_ms, DELAY_MS, prepare_ms, a_render_ms, t_end - t_switch);
        printf("B during A's load: %d frames, longest gap %.0f ms; during A's prepare + first frame: %d frames, "
               "longest gap %.0f ms\n", frames, gap, frames_prep, gap_prep);
        SL_CHECK_MSG(frames >= 5, "B got %d frames during A's %.0f ms load", frames, load_ms);
        SL_CHECK_MSG(gap < load_ms / 2, "B's longest gap %.0f ms during A's %.0f ms load", gap, load_ms);
    }

    /* C joined A's load. */
    double loads1 = harness_metric(h.port, "sightline_dataset_loads_total");
    double prepares1 = harness_metric(h.port, "sightline_prepare_ms_count");
    printf("loads %g -> %g, prepares %g -> %g; C's progress:", loads0, loads1, prepares0, prepares1);
    for (int i = 0; i < pc.count; i++)
        printf(" %s", pc.stage[i]);
    printf("\n");
    SL_CHECK_MSG(loads1 - loads0 == 1, "two sessions on furball_787k: %g loads", loads1 - loads0);
    /* C's first frame, if any, was on tiny, whose prepared scene B shares. */
    SL_CHECK_MSG(prepares1 - prepares0 == 2, "prepares %g -> %g", prepares0, prepares1);
    SL_CHECK_MSG(pc.count == 4 && find_stage(&pc, "loading") == 0 && find_stage(&pc, "done") == 3,
                 "C's progress: %d messages", pc.count);

    /* A load that is no longer wanted ends its round without a frame. */
    progress_log ps = {0};
    int errors = 0, sent_tiny = 0;
    uint32_t v_tiny = 0;
    SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"abc\"}") == 0);
    deadline = sl_clock_ms() + T;
    while (ps.count < 2 && sl_clock_ms() < deadline) {
        cJSON *j = NULL;
        int r = tclient_next(&a, 1000, &j);
        if (r == 0)
            break;
        if (r != 1)
            continue;
        errors += strcmp(json_type(j), "error") == 0;
        const cJSON *patch = cJSON_GetObjectItemCaseSensitive(j, "patch");
        const char *dsname = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(patch, "dataset"));
        if (dsname && strcmp(dsname, "tiny") == 0)
            v_tiny = (uint32_t)num(j, "version");
        log_progress(&ps, j);
        if (ps.count == 1 && strcmp(ps.stage[0], "loading") == 0 && !sent_tiny) {
            SL_CHECK(tclient_send(&a, "{\"type\":\"scene\",\"dataset\":\"tiny\"}") == 0);
            sent_tiny = 1;
        }
    }
    SL_CHECK_MSG(ps.count >= 2 && strcmp(ps.stage[0], "loading") == 0 && strcmp(ps.stage[1], "done") == 0 &&
                 !cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(ps.msg[1], "ok")) &&
                 strcmp(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(ps.msg[1], "dataset")), "abc") == 0,
                 "abc superseded by tiny: %d progress messages (%s, %s)", ps.count, ps.count > 0 ? ps.stage[0] : "",
                 ps.count > 1 ? ps.stage[1] : "");
    if (!v_tiny) {
        cJSON *j = tclient_wait_type(&a, "state", T);
        v_tiny = j ? (uint32_t)num(j, "version") : 0;
        cJSON_Delete(j);
    }
    SL_CHECK(v_tiny > 0 && tclient_wait_version(&a, v_tiny, T) == 0);
    SL_CHECK_MSG(errors == 0, "A got %d errors while switching away from a load", errors);
    for (int i = 0; i < ps.count; i++)
        cJSON_Delete(ps.msg[i]);

    for (int i = 0; i < pa.count; i++)
        cJSON_Delete(pa.msg[i]);
    for (int i = 0; i < pc.count; i++)
        cJSON_Delete(pc.msg[i]);
    pthread_cond_destroy(&d->changed);
    pthread_mutex_destroy(&d->lock);
    free(d);
    tclient_close(&a);
    if (c_started)
        tclient_close(&c);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
