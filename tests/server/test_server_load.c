/* test_server_load.c — bounded load: 16 clients x 200 camera messages on loopback.
 *
 * Each client (one thread, its own session, 128x96) sends 200 camera
 * messages, up to 250 a second (a fast drag) — phase move, the last one end —
 * in two rounds of 100, draining and acking frames as they come. Meanwhile
 * the main thread times GET /healthz. Checks: every client ends with a
 * still frame showing its newest camera (seq 200) — newest wins, nothing is
 * lost at the end; the server coalesced (rendered fewer frames than camera
 * messages arrived); /healthz kept answering within 3 s under load; the
 * server's resident memory after round 2 is not more than round 1's plus
 * 25% + 32 MiB (no growth per message: state is newest-wins, frames are
 * replaced, queues are bounded); the server exits cleanly.
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

typedef struct worker {
    int port;
    int index;
    pthread_barrier_t *barrier;
    int ok_connect, ok_final;
    int frames;
    uint32_t final_seq;
    int final_interactive;
    char error[256];
} worker;

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
            double az = 360.0 * i / MESSAGES + 7.0 * w->index;
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

static long rss_kib(pid_t pid)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    FILE *f = fopen(path, "r");
    long kib = -1;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmRSS:", 6) == 0)
            kib = atol(line + 6);
    if (f)
        fclose(f);
    return kib;
}

static double healthz_ms(int port)
{
    double t0 = harness_now_ms();
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        if (fd >= 0)
            close(fd);
        return 1e9;
    }
    const char *req = "GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
    char buf[1024];
    size_t len = 0;
    if (write(fd, req, strlen(req)) < 0) {
        close(fd);
        return 1e9;
    }
    while (harness_now_ms() - t0 < 10000 && len + 1 < sizeof buf) {
        struct pollfd pfd = {.fd = fd, .events = POLLIN};
        if (poll(&pfd, 1, 100) <= 0)
            continue;
        ssize_t r = read(fd, buf + len, sizeof buf - 1 - len);
        if (r <= 0)
            break;
        len += (size_t)r;
        buf[len] = 0;
        if (strstr(buf, "\"status\":\"ok\""))
            break;
    }
    close(fd);
    buf[len] = 0;
    return strstr(buf, "\"status\":\"ok\"") ? harness_now_ms() - t0 : 1e9;
}

int main(void)
{
    /* A small ASan quarantine, so resident memory reflects live data, not freed buffers. */
    const char *asan = getenv("ASAN_OPTIONS");
    char opts[512];
    snprintf(opts, sizeof opts, "%s%squarantine_size_mb=8", asan ? asan : "", asan && asan[0] ? ":" : "");
    setenv("ASAN_OPTIONS", opts, 1);
    harness h;
    if (harness_start(&h, NULL) != 0) {
        SL_CHECK(!"server started");
        harness_stop(&h);
        SL_TEST_END();
    }
    pthread_barrier_t barrier;
    pthread_barrier_init(&barrier, NULL, CLIENTS + 1);
    worker w[CLIENTS];
    pthread_t th[CLIENTS];
    for (int i = 0; i < CLIENTS; i++) {
        w[i] = (worker){.port = h.port, .index = i, .barrier = &barrier};
        pthread_create(&th[i], NULL, run_worker, &w[i]);
    }
    double t0 = harness_now_ms();
    pthread_barrier_wait(&barrier);          /* all connected: round 1 starts */
    double worst = 0;
    pthread_barrier_wait(&barrier);          /* round 1 sent and drained */
    long rss1 = rss_kib(h.pid);
    double hz = healthz_ms(h.port);
    worst = fmax(worst, hz);
    pthread_barrier_wait(&barrier);          /* round 2 starts */
    for (int i = 0; i < 10; i++) {
        worst = fmax(worst, healthz_ms(h.port));
        usleep(100000);
    }
    for (int i = 0; i < CLIENTS; i++)
        pthread_join(th[i], NULL);
    double total_ms = harness_now_ms() - t0;
    long rss2 = rss_kib(h.pid);

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
    pthread_barrier_destroy(&barrier);
    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
