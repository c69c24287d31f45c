/* test_server_load.c — bounded load: 16 clients x 200 camera messages on loopback.
 *
 * Each client (one thread, its own session, 128x96) sends 200 camera
 * messages, up to 250 a second (a fast drag) — phase move, the last one end —
 * in two rounds of 100, draining and acking frames as they come. Meanwhile
 * the main thread times GET /healthz. Checks: every client ends with a
 * still frame showing its newest camera (seq 200) — newest wins, nothing is
 * lost at the end; the server coalesced (rendered fewer frames than camera
 * messages arrived); each client's final still shows its own camera: its
 * last azimuth is 360 + 7 x its index, and the decoded frame must be nearer
 * to sightline-render's frame of that camera than to any other client's
 * (drawn_diff: mean difference over the pixels either image draws), within
 * MAX_OWN_DIFF (JPEG q92 against a lossless render) and at most a third of
 * the nearest other's, so a frame rendered or sent for another session
 * fails; /healthz kept
 * answering within 3 s under load; the
 * server's resident memory after round 2 is not more than round 1's plus
 * 25% + 32 MiB (no growth per message: state is newest-wins, frames are
 * replaced, queues are bounded); the server exits cleanly.
 * Phase 2 puts 16 clients in ONE session: the controller sends the 200
 * camera messages, 15 viewers watch (all drain and ack). Every client must
 * end with the same newest still frame (seq 200, one frame id for all),
 * none may be closed, and the server must have sent each rendered frame to
 * all of them from one encode (frames received <= 16 x frames rendered),
 * and the controller's final frame is sightline-render's for its camera.
 */
#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <pthread.h>
#include <sys/socket.h>

#include "sl_server_harness.h"
#include "sl_test.h"

#define CLIENTS 16
#define MESSAGES 200
#define W 128
#define H 96
#define MAX_OWN_DIFF 20.0 /* drawn_diff, 0..255: JPEG q92 4:4:4 noise on thin tubes is ~10; 7 degrees off is ~70 */
#define DRAWN 24         /* a pixel is drawn when a channel is this far from the background */

typedef struct worker {
    int port;
    int index;
    pthread_barrier_t *barrier;
    int ok_connect, ok_final;
    int frames;
    uint32_t final_seq;
    int final_interactive;
    sl_image final_image;   /* the final still, decoded (owned) */
    char error[256];
} worker;

/* The azimuth of a load client's camera message i (the last one, i = MESSAGES: 360 + 7 x index). */
static double load_azimuth(int index, int i)
{
    return 360.0 * i / MESSAGES + 7.0 * index;
}

/* Mean over the pixels drawn in a or ref (a channel more than DRAWN from
 * ref's corner pixel, the background) of the largest channel difference;
 * -1 when the sizes differ or nothing is drawn. JPEG noise stays below
 * DRAWN, so the empty part of the frame neither counts nor dilutes. */
static double drawn_diff(const sl_image *a, const sl_image *ref)
{
    if (!a->rgba || !ref->rgba || a->width != ref->width || a->height != ref->height)
        return -1;
    const uint8_t *bg = ref->rgba;
    double sum = 0;
    long n = 0;
    for (size_t p = 0; p < (size_t)a->width * (size_t)a->height; p++) {
        const uint8_t *x = a->rgba + 4 * p, *y = ref->rgba + 4 * p;
        int drawn = 0, diff = 0;
        for (int c = 0; c < 3; c++) {
            drawn |= abs(x[c] - bg[c]) > DRAWN || abs(y[c] - bg[c]) > DRAWN;
            diff = abs(x[c] - y[c]) > diff ? abs(x[c] - y[c]) : diff;
        }
        if (drawn) {
            sum += diff;
            n++;
        }
    }
    return n ? sum / (double)n : -1;
}

/* sightline-render's frame of the harness's tiny dataset with the server's
 * defaults (tubes_mesh, its params, the background) at this orbit. */
static int reference(const harness *h, double azimuth, double elevation, const char *name, sl_image *out)
{
    char scene[1024];
    snprintf(scene, sizeof scene, "{\"dataset\":%s,\"technique\":\"tubes_mesh\",\"camera\":{\"orbit\":"
             "{\"azimuth\":%.3f,\"elevation\":%.17g,\"distance\":2.5}},\"width\":%d,\"height\":%d}",
             HARNESS_TINY, azimuth, elevation, W, H);
    return harness_cli_render(h, scene, name, out);
}

static void drain(tclient *c, int timeout_ms)
{
    while (tclient_next(c, timeout_ms, NULL) > 0)
        timeout_ms = 0;
}

static void *run_worker(void *arg)
{
    worker *w = arg;
    tclient c;
    if (tclient_connect(&c, w->port, NULL) != 0 || tclient_hello(&c, NULL, NULL, W, H) != 0) {
        snprintf(w->error, sizeof w->error, "connect/hello: %.200s", c.err.message);
        pthread_barrier_wait(w->barrier);
        pthread_barrier_wait(w->barrier);
        tclient_close(&c);
        return NULL;
    }
    c.auto_ack = 1;
    w->ok_connect = tclient_wait_frame(&c, 0, 1, 60000) == 0; /* warm: pipeline prepared */
    for (int round = 0; round < 2; round++) {
        pthread_barrier_wait(w->barrier);
        for (int i = round * (MESSAGES / 2) + 1; i <= (round + 1) * (MESSAGES / 2); i++) {
            const char *phase = i == MESSAGES ? "end" : "move";
            double az = load_azimuth(w->index, i);
            if (tclient_send(&c, "{\"type\":\"camera\",\"seq\":%d,\"phase\":\"%s\",\"camera\":{\"orbit\":"
                                 "{\"azimuth\":%.3f,\"elevation\":15,\"distance\":2.5}}}", i, phase, az)) {
                snprintf(w->error, sizeof w->error, "send: %.200s", c.err.message);
                break;
            }
            drain(&c, 4); /* paces the sender at <= 250 messages per second */
        }
        if (round == 1 && tclient_wait_frame(&c, MESSAGES, 1, 90000) == 0) {
            w->ok_final = 1;
            w->final_seq = c.last.h.camera_seq;
            w->final_interactive = (c.last.h.flags & SL_FRAME_FLAG_INTERACTIVE) != 0;
            w->final_image = tclient_decode_last(&c);
        } else if (round == 0) {
            drain(&c, 500);
        }
        if (round == 0)
            pthread_barrier_wait(w->barrier);
    }
    w->frames = c.frames;
    tclient_close(&c);
    return NULL;
}

typedef struct viewer {
    int port;
    const char *session, *token;
    pthread_barrier_t *barrier;
    int ok_join, ok_final, closed, frames;
    uint32_t final_seq, final_id;
    int final_interactive;
    char error[256];
} viewer;

/* After the last camera message: waits for the newest still, meets the
 * others, drains briefly and records the newest frame id it has. */
static void finish(tclient *c, pthread_barrier_t *barrier, int *ok_final, uint32_t *seq, int *interactive,
                   uint32_t *id)
{
    if (tclient_wait_frame(c, MESSAGES, 1, 90000) == 0) {
        *ok_final = 1;
        *seq = c->last.h.camera_seq;
        *interactive = (c->last.h.flags & SL_FRAME_FLAG_INTERACTIVE) != 0;
    }
    pthread_barrier_wait(barrier);   /* everyone has the still: nothing new renders */
    drain(c, 300);
    *id = c->max_frame_id;
}

static void *run_viewer(void *arg)
{
    viewer *v = arg;
    tclient c;
    v->ok_join = tclient_connect(&c, v->port, NULL) == 0 && tclient_hello(&c, v->session, v->token, W, H) == 0;
    c.auto_ack = 1;
    if (v->ok_join && tclient_wait_frame(&c, 0, 0, 60000) != 0)
        snprintf(v->error, sizeof v->error, "no frame at join");
    pthread_barrier_wait(v->barrier);   /* all joined: the controller starts */
    finish(&c, v->barrier, &v->ok_final, &v->final_seq, &v->final_interactive, &v->final_id);
    v->closed = c.closed;
    v->frames = c.frames;
    tclient_close(&c);
    return NULL;
}

/* Phase 2: one session, the controller on this thread, CLIENTS - 1 viewers. */
static void shared_session(const harness *h)
{
    tclient ctl;
    if (tclient_connect(&ctl, h->port, NULL) != 0 || tclient_hello(&ctl, NULL, NULL, W, H) != 0) {
        SL_CHECK(!"shared session created");
        tclient_close(&ctl);
        return;
    }
    ctl.auto_ack = 1;
    pthread_barrier_t barrier;
    pthread_barrier_init(&barrier, NULL, CLIENTS);
    viewer v[CLIENTS - 1];
    pthread_t th[CLIENTS - 1];
    for (int i = 0; i < CLIENTS - 1; i++) {
        v[i] = (viewer){.port = h->port, .session = ctl.session, .token = ctl.token, .barrier = &barrier};
        pthread_create(&th[i], NULL, run_viewer, &v[i]);
    }
    pthread_barrier_wait(&barrier);
    for (int i = 1; i <= MESSAGES; i++) {
        if (tclient_send(&ctl, "{\"type\":\"camera\",\"seq\":%d,\"phase\":\"%s\",\"camera\":{\"orbit\":"
                               "{\"azimuth\":%.3f,\"elevation\":25,\"distance\":2.5}}}",
                         i, i == MESSAGES ? "end" : "move", 360.0 * i / MESSAGES))
            break;
        drain(&ctl, 4);
    }
    int ctl_final = 0, ctl_interactive = 0;
    uint32_t ctl_seq = 0, ctl_id = 0;
    finish(&ctl, &barrier, &ctl_final, &ctl_seq, &ctl_interactive, &ctl_id);
    sl_image ctl_image = tclient_decode_last(&ctl); /* the newest frame: the still of seq MESSAGES */
    int joined = 0, final_ok = 0, same_id = 0, closed = ctl.closed, frames = ctl.frames;
    for (int i = 0; i < CLIENTS - 1; i++) {
        pthread_join(th[i], NULL);
        joined += v[i].ok_join;
        final_ok += v[i].ok_final && v[i].final_seq == MESSAGES && !v[i].final_interactive;
        same_id += v[i].final_id == ctl_id;
        closed += v[i].closed;
        frames += v[i].frames;
        if (v[i].error[0])
            fprintf(stderr, "viewer %d: %s\n", i, v[i].error);
    }
    uint32_t rendered = ctl.max_frame_id;
    printf("shared session: 1 controller + %d viewers, %d camera messages; %u frames rendered, %d received\n",
           CLIENTS - 1, MESSAGES, rendered, frames);
    SL_CHECK_MSG(joined == CLIENTS - 1, "%d of %d viewers joined", joined, CLIENTS - 1);
    SL_CHECK_MSG(ctl_final && ctl_seq == MESSAGES && !ctl_interactive, "controller final frame seq %u", ctl_seq);
    SL_CHECK_MSG(final_ok == CLIENTS - 1, "%d of %d viewers ended with the newest still frame", final_ok,
                 CLIENTS - 1);
    SL_CHECK_MSG(same_id == CLIENTS - 1, "%d of %d viewers ended on the controller's frame id %u", same_id,
                 CLIENTS - 1, ctl_id);
    SL_CHECK_MSG(closed == 0, "%d clients of the shared session were closed", closed);
    SL_CHECK_MSG(rendered < MESSAGES, "%u frames for %d camera messages: not coalesced", rendered, MESSAGES);
    SL_CHECK_MSG(frames <= CLIENTS * (int)rendered, "%d frames received > %d clients x %u rendered", frames, CLIENTS,
                 rendered);
    sl_image ref = {0};
    if (reference(h, 360.0, 25, "shared", &ref) == 0) {
        double d = drawn_diff(&ctl_image, &ref);
        printf("shared session: final frame vs sightline-render %.3f\n", d);
        SL_CHECK_MSG(d >= 0 && d <= MAX_OWN_DIFF, "shared session's final frame differs from its camera's render by %.3f",
                     d);
    } else {
        SL_CHECK(!"reference for the shared session rendered");
    }
    sl_image_deinit(&ref);
    sl_image_deinit(&ctl_image);
    pthread_barrier_destroy(&barrier);
    tclient_close(&ctl);
}

/* Each client's final still against sightline-render's frame of every
 * client's final camera: nearest to its own, within MAX_OWN_DIFF, and at
 * most a third as far from it as from the nearest other. */
static void check_own_cameras(const harness *h, worker *w)
{
    sl_image ref[CLIENTS];
    memset(ref, 0, sizeof ref);
    int refs = 0;
    for (int k = 0; k < CLIENTS; k++) {
        char name[32];
        snprintf(name, sizeof name, "load_ref_%d", k);
        refs += reference(h, load_azimuth(k, MESSAGES), 15, name, &ref[k]) == 0;
    }
    SL_CHECK_MSG(refs == CLIENTS, "%d of %d reference frames rendered", refs, CLIENTS);
    int own = 0;
    double worst_own = 0, closest_other = 1e9;
    for (int i = 0; i < CLIENTS && refs == CLIENTS; i++) {
        double mine = drawn_diff(&w[i].final_image, &ref[i]), other = 1e9;
        int nearest_other = -1;
        for (int k = 0; k < CLIENTS; k++) {
            double d = drawn_diff(&w[i].final_image, &ref[k]);
            if (k != i && d >= 0 && d < other) {
                other = d;
                nearest_other = k;
            }
        }
        worst_own = fmax(worst_own, mine);
        closest_other = fmin(closest_other, other);
        int ok = mine >= 0 && mine <= MAX_OWN_DIFF && mine * 3 <= other;
        own += ok;
        if (!ok)
            fprintf(stderr, "client %d (azimuth %.0f): %.3f from its own camera's frame, %.3f from client %d's\n", i,
                    load_azimuth(i, MESSAGES), mine, other, nearest_other);
    }
    printf("own cameras: worst difference to its own reference %.3f, nearest other client's %.3f\n", worst_own,
           closest_other);
    SL_CHECK_MSG(own == CLIENTS, "%d of %d clients' final frames show their own camera", own, CLIENTS);
    for (int k = 0; k < CLIENTS; k++)
        sl_image_deinit(&ref[k]);
}

static double healthz_ms(int port)
{
    double t0 = sl_clock_ms();
    char buf[1024];
    int status = harness_http_get(port, NULL, "/healthz", buf, sizeof buf);
    return status == 200 && strstr(buf, "\"status\":\"ok\"") ? sl_clock_ms() - t0 : 1e9;
}

int main(void)
{
    harness_small_asan_quarantine();
    harness h;
    /* 16 clients connect at once, all from 127.0.0.1: above the default pending
     * cap of one address (--max-pending-per-address 4), which would refuse most. */
    const char *extra[] = {"--max-pending", "32", "--max-pending-per-address", "32", NULL};
    HARNESS_START_OR_END(h, extra);
    pthread_barrier_t barrier;
    pthread_barrier_init(&barrier, NULL, CLIENTS + 1);
    worker w[CLIENTS];
    pthread_t th[CLIENTS];
    for (int i = 0; i < CLIENTS; i++) {
        w[i] = (worker){.port = h.port, .index = i, .barrier = &barrier};
        pthread_create(&th[i], NULL, run_worker, &w[i]);
    }
    double t0 = sl_clock_ms();
    pthread_barrier_wait(&barrier);          /* all connected: round 1 starts */
    double worst = 0;
    pthread_barrier_wait(&barrier);          /* round 1 sent and drained */
    long rss1 = harness_rss_kib(h.pid);
    double hz = healthz_ms(h.port);
    worst = fmax(worst, hz);
    pthread_barrier_wait(&barrier);          /* round 2 starts */
    for (int i = 0; i < 10; i++) {
        worst = fmax(worst, healthz_ms(h.port));
        usleep(100000);
    }
    for (int i = 0; i < CLIENTS; i++)
        pthread_join(th[i], NULL);
    double total_ms = sl_clock_ms() - t0;
    long rss2 = harness_rss_kib(h.pid);

    int connected = 0, final_ok = 0, frames = 0;
    for (int i = 0; i < CLIENTS; i++) {
        connected += w[i].ok_connect;
        final_ok += w[i].ok_final && w[i].final_seq == MESSAGES && !w[i].final_interactive;
        frames += w[i].frames;
        if (w[i].error[0])
            fprintf(stderr, "client %d: %s\n", i, w[i].error);
    }
    printf("load: %d clients x %d camera messages in %.0f ms; %d frames received; worst /healthz %.0f ms; "
           "RSS %ld -> %ld KiB\n", CLIENTS, MESSAGES, total_ms, frames, worst, rss1, rss2);
    SL_CHECK_MSG(connected == CLIENTS, "%d of %d clients connected", connected, CLIENTS);
    SL_CHECK_MSG(final_ok == CLIENTS, "%d of %d clients ended with the newest still frame", final_ok, CLIENTS);
    SL_CHECK_MSG(frames < CLIENTS * MESSAGES, "frames %d: camera messages were not coalesced", frames);
    SL_CHECK_MSG(frames >= CLIENTS, "frames %d", frames);
    SL_CHECK_MSG(worst < 3000, "worst /healthz latency under load %.0f ms", worst);
    SL_CHECK_MSG(rss1 > 0 && rss2 > 0 && rss2 <= rss1 + rss1 / 4 + 32 * 1024, "RSS %ld -> %ld KiB", rss1, rss2);
    check_own_cameras(&h, w);
    for (int i = 0; i < CLIENTS; i++)
        sl_image_deinit(&w[i].final_image);
    pthread_barrier_destroy(&barrier);
    shared_session(&h);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
