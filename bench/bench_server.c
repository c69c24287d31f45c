/* bench_server.c — end-to-end numbers of sightline-server on loopback.
 *
 *   bench-server [--dataset NAME (default tiny: 40 lines)] [--size WxH] [--seconds S]
 *
 * Starts a private server (tests/server/sl_server_harness.h) and measures:
 * latency from a `camera` message to the first frame echoing its seq
 * (interactive drag frames and one-off still frames; median and p95), frames
 * per second delivered to each of 1, 4 and 16 clients of one session while
 * the controller drags (closed loop: a new camera message whenever the
 * controller's previous one is shown), JPEG encode ms per megapixel at the
 * interactive and still settings (from the frame headers), and bytes per
 * frame. Prints one table. Does not check anything (tests do); one thread
 * per client.
 */
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>

#include "../tests/server/sl_server_harness.h"

typedef struct stat_acc {
    double v[4096];
    int n;
} stat_acc;

static void acc_add(stat_acc *a, double x)
{
    if (a->n < 4096)
        a->v[a->n++] = x;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double acc_pct(stat_acc *a, double p)
{
    if (a->n == 0)
        return NAN;
    qsort(a->v, (size_t)a->n, sizeof a->v[0], cmp_double);
    int i = (int)ceil(p / 100.0 * a->n) - 1;
    return a->v[i < 0 ? 0 : i];
}

static double acc_mean(const stat_acc *a)
{
    double s = 0;
    for (int i = 0; i < a->n; i++)
        s += a->v[i];
    return a->n ? s / a->n : NAN;
}

typedef struct viewer {
    int port;
    const char *session, *token;
    atomic_int *stop;
    int frames;
    double first_ms, last_ms;
    int ok;
} viewer;

static void *run_viewer(void *arg)
{
    viewer *v = arg;
    tclient c;
    if (tclient_connect(&c, v->port, NULL) != 0 || tclient_hello(&c, v->session, v->token, 64, 64) != 0)
        return NULL;
    c.auto_ack = 1;
    v->ok = 1;
    tclient_wait_frame(&c, 0, 0, 30000);
    int base = c.frames;
    v->first_ms = harness_now_ms();
    while (!atomic_load(v->stop))
        if (tclient_next(&c, 50, NULL) == 0)
            break;
    v->last_ms = harness_now_ms();
    v->frames = c.frames - base;
    tclient_close(&c);
    return NULL;
}

static int send_camera(tclient *c, uint32_t seq, const char *phase, double az)
{
    if (phase)
        return tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"phase\":\"%s\",\"camera\":{\"orbit\":"
                               "{\"azimuth\":%.4f,\"elevation\":20,\"distance\":2.5}}}", seq, phase, az);
    return tclient_send(c, "{\"type\":\"camera\",\"seq\":%u,\"camera\":{\"orbit\":"
                           "{\"azimuth\":%.4f,\"elevation\":20,\"distance\":2.5}}}", seq, az);
}

int main(int argc, char **argv)
{
    const char *dataset = "tiny"; /* server overhead; heavy datasets measure the technique instead */
    int w = 256, h = 256;
    double seconds = 3.0;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--dataset") == 0)
            dataset = argv[i + 1];
        else if (strcmp(argv[i], "--size") == 0 && sscanf(argv[i + 1], "%dx%d", &w, &h) == 2)
            ;
        else if (strcmp(argv[i], "--seconds") == 0)
            seconds = atof(argv[i + 1]);
        else {
            fprintf(stderr, "usage: bench-server [--dataset NAME] [--size WxH] [--seconds S]\n");
            return 2;
        }
    }
    if (!getenv("SIGHTLINE_BINARY_DIR")) {
        char exe[PATH_MAX];
        ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (n > 0) {
            exe[n] = 0;
            char *bin = dirname(exe);       /* build/bin */
            setenv("SIGHTLINE_BINARY_DIR", dirname(bin), 1);
        }
    }
    harness hs;
    const char *extra[] = {"--default-dataset", dataset, NULL};
    if (harness_start(&hs, extra) != 0) {
        fprintf(stderr, "bench-server: could not start the server\n");
        harness_stop(&hs);
        return 1;
    }
    tclient ctl;
    if (tclient_connect(&ctl, hs.port, NULL) != 0 || tclient_hello(&ctl, NULL, NULL, w, h) != 0) {
        fprintf(stderr, "bench-server: hello failed: %s\n", ctl.err.message);
        harness_stop(&hs);
        return 1;
    }
    ctl.auto_ack = 1;
    tclient_wait_frame(&ctl, 0, 1, 120000); /* dataset load + prepare */

    stat_acc lat_move = {0}, lat_still = {0}, enc_i = {0}, enc_s = {0}, bytes_i = {0}, bytes_s = {0};
    stat_acc render_i = {0}, render_s = {0};
    uint32_t seq = 0;
    /* Interactive latency: one move at a time, next after its frame is shown. */
    for (int i = 0; i < 40; i++) {
        double t0 = harness_now_ms();
        send_camera(&ctl, ++seq, "move", i * 3.0);
        if (tclient_wait_frame(&ctl, seq, 0, 30000) != 0)
            break;
        acc_add(&lat_move, ctl.last.arrival_ms - t0);
    }
    send_camera(&ctl, ++seq, "end", 120.0);
    tclient_wait_frame(&ctl, seq, 1, 30000);
    /* Still latency: one-off changes. */
    for (int i = 0; i < 20; i++) {
        double t0 = harness_now_ms();
        send_camera(&ctl, ++seq, NULL, 130.0 + i * 5.0);
        if (tclient_wait_frame(&ctl, seq, 1, 30000) != 0)
            break;
        acc_add(&lat_still, ctl.last.arrival_ms - t0);
    }

    /* FPS to 1, 4, 16 clients of one session (the controller counts as one). */
    int counts[3] = {1, 4, 16};
    double fps_mean[3], fps_min[3];
    for (int k = 0; k < 3; k++) {
        int nv = counts[k] - 1;
        atomic_int stop = 0;
        viewer vs[16];
        pthread_t th[16];
        for (int i = 0; i < nv; i++) {
            vs[i] = (viewer){.port = hs.port, .session = ctl.session, .token = ctl.token, .stop = &stop};
            pthread_create(&th[i], NULL, run_viewer, &vs[i]);
        }
        usleep(500000);
        int base = ctl.frames;
        double t0 = harness_now_ms(), az = 0;
        while (harness_now_ms() - t0 < seconds * 1000.0) {
            send_camera(&ctl, ++seq, "move", az += 2.0);
            if (tclient_wait_frame(&ctl, seq, 0, 30000) != 0)
                break;
            double mpx = ctl.last.h.width * ctl.last.h.height / 1e6;
            if (ctl.last.h.flags & SL_FRAME_FLAG_INTERACTIVE) {
                acc_add(&enc_i, ctl.last.h.encode_ms / mpx);
                acc_add(&bytes_i, ctl.last.h.payload_bytes);
                acc_add(&render_i, ctl.last.h.render_ms);
            }
        }
        double ctl_fps = (ctl.frames - base) / ((harness_now_ms() - t0) / 1000.0);
        atomic_store(&stop, 1);
        double sum = ctl_fps, mn = ctl_fps;
        for (int i = 0; i < nv; i++) {
            pthread_join(th[i], NULL);
            double f = vs[i].ok && vs[i].last_ms > vs[i].first_ms
                           ? vs[i].frames / ((vs[i].last_ms - vs[i].first_ms) / 1000.0) : 0;
            sum += f;
            mn = fmin(mn, f);
        }
        fps_mean[k] = sum / counts[k];
        fps_min[k] = mn;
        send_camera(&ctl, ++seq, "end", az);
        tclient_wait_frame(&ctl, seq, 1, 30000);
    }
    /* Still frames for encode cost and size. */
    for (int i = 0; i < 10; i++) {
        send_camera(&ctl, ++seq, NULL, 200.0 + i * 7.0);
        if (tclient_wait_frame(&ctl, seq, 1, 30000) != 0)
            break;
        double mpx = ctl.last.h.width * ctl.last.h.height / 1e6;
        acc_add(&enc_s, ctl.last.h.encode_ms / mpx);
        acc_add(&bytes_s, ctl.last.h.payload_bytes);
        acc_add(&render_s, ctl.last.h.render_ms);
    }
    tclient_close(&ctl);
    harness_stop(&hs);

    printf("sightline-server benchmark: dataset %s, %dx%d (interactive %dx%d), loopback\n", dataset, w, h, w / 2, h / 2);
    printf("| metric | value |\n| --- | --- |\n");
    printf("| latency camera->frame, interactive (median / p95) | %.1f / %.1f ms (n=%d) |\n",
           acc_pct(&lat_move, 50), acc_pct(&lat_move, 95), lat_move.n);
    printf("| latency camera->frame, still (median / p95) | %.1f / %.1f ms (n=%d) |\n",
           acc_pct(&lat_still, 50), acc_pct(&lat_still, 95), lat_still.n);
    for (int k = 0; k < 3; k++)
        printf("| fps per client, %2d client(s) in one session (mean / min) | %.1f / %.1f |\n", counts[k],
               fps_mean[k], fps_min[k]);
    printf("| render+readback ms per frame, interactive / still (mean) | %.2f / %.2f |\n", acc_mean(&render_i),
           acc_mean(&render_s));
    printf("| JPEG encode ms per megapixel, interactive q60 4:2:0 (mean) | %.2f |\n", acc_mean(&enc_i));
    printf("| JPEG encode ms per megapixel, still q92 4:4:4 (mean) | %.2f |\n", acc_mean(&enc_s));
    printf("| bytes per frame, interactive / still (mean) | %.0f / %.0f |\n", acc_mean(&bytes_i), acc_mean(&bytes_s));
    return 0;
}
