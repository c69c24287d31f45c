/* test_server_slots.c — connection slots: pending connections cannot lock real users out.
 *
 * The server runs with --max-clients 3 --max-pending 8
 * --max-pending-per-address 2 --hello-timeout 4. Connections that never
 * send hello are raw sockets bound to other loopback addresses (127.0.0.2
 * ... 127.0.0.9: Linux routes all of 127/8 to lo), so the per-address cap is
 * exercised with distinct peers; real users are tclients from 127.0.0.1.
 * Checks: a third silent upgrade from one address is refused while two are
 * pending; a full pending budget evicts the oldest silent connection (closed
 * well before its hello timeout) and accepts the new one; silent
 * connections take no client slot (3 users are welcomed while 8 silent ones
 * are pending); hello on a full server gets `full` and a close, an upgrade
 * is refused, a slot frees when a user leaves; while a flood from 8
 * addresses reconnects for 10 s (bounded: it stops by itself), every real
 * user (joining the long-connected user's session) gets welcome and a frame, the long-connected user keeps working, the
 * pending count never exceeds the budget, and the server refused or evicted
 * flood connections. Loopback only. Exit status 0 required.
 */
#include <pthread.h>
#include <stdatomic.h>

#include "sl_server_harness.h"
#include "sl_test.h"

#define MAX_CLIENTS 3
#define MAX_PENDING 8
#define PER_ADDRESS 2
#define HELLO_TIMEOUT_S 4
#define FLOOD_MS 10000
#define FLOOD_SAFETY_MS 180000
#define FLOOD_MIN_ROUNDS 6   /* users tried during the flood, whatever the machine's speed */
#define FLOOD_OPEN_MAX 48
#define T 20000

/* A WebSocket upgrade from source address src that never sends hello.
 * Returns the socket when the server answered 101, -1 when it refused
 * (closed or answered without 101) or the connection failed. */
static int raw_upgrade(int port, const char *src)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0)
        return -1;
    struct sockaddr_in local = {.sin_family = AF_INET}, remote = {.sin_family = AF_INET,
                                                                   .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, src, &local.sin_addr);
    inet_pton(AF_INET, "127.0.0.1", &remote.sin_addr);
    if (bind(fd, (struct sockaddr *)&local, sizeof local) != 0 ||
        connect(fd, (struct sockaddr *)&remote, sizeof remote) != 0) {
        close(fd);
        return -1;
    }
    char req[512];
    int n = snprintf(req, sizeof req,
                     "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                     "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                     "Sec-WebSocket-Protocol: " SL_PROTO_SUBPROTOCOL "\r\n\r\n", port);
    if (write(fd, req, (size_t)n) != n) {
        close(fd);
        return -1;
    }
    char resp[2048];
    size_t len = 0;
    double deadline = sl_clock_ms() + 5000;
    while (len + 1 < sizeof resp && sl_clock_ms() < deadline) {
        struct pollfd pfd = {.fd = fd, .events = POLLIN};
        if (poll(&pfd, 1, 100) <= 0)
            continue;
        ssize_t r = read(fd, resp + len, sizeof resp - 1 - len);
        if (r <= 0)
            break;
        len += (size_t)r;
        resp[len] = 0;
        if (strstr(resp, "\r\n\r\n"))
            break;
    }
    resp[len] = 0;
    if (strncmp(resp, "HTTP/1.1 101", 12) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

/* 1 when the server has closed fd (EOF or reset) within timeout_ms; data
 * (a close frame) is read and skipped. */
static int closed_by_server(int fd, int timeout_ms)
{
    double deadline = sl_clock_ms() + timeout_ms;
    for (;;) {
        int left = (int)(deadline - sl_clock_ms());
        struct pollfd pfd = {.fd = fd, .events = POLLIN};
        if (poll(&pfd, 1, left > 0 ? left : 0) <= 0)
            return 0;
        char buf[256];
        ssize_t r = read(fd, buf, sizeof buf);
        if (r <= 0)
            return 1;
    }
}

/* The server notices closes asynchronously: waits until /healthz shows pending == want. */
static int wait_pending(int port, int want)
{
    for (int i = 0; i < 100; i++) {
        if ((int)harness_healthz_number(port, "pending") == want)
            return 1;
        usleep(50000);
    }
    return 0;
}

/* A real user: connect, hello (a new session, or joining `join`), first
 * frame. 1 when all three happened. */
static int user_served(int port, tclient *c, int keep, const tclient *join)
{
    int ok = tclient_connect(c, port, NULL) == 0 &&
             tclient_hello(c, join ? join->session : NULL, join ? join->token : NULL, 32, 32) == 0;
    c->auto_ack = 1;
    ok = ok && tclient_wait_frame(c, 0, 0, T) == 0;
    if (!keep)
        tclient_close(c);
    return ok;
}

typedef struct flood {
    int port;
    atomic_int stop;   /* set by main once its user rounds are done */
    int attempts, accepted, refused, closed_by_server;
} flood;

/* Reconnects silent upgrades from 127.0.0.2..9 until main sets stop (at least
 * FLOOD_MS, however slow the machine: main's user rounds run inside it), at most
 * FLOOD_OPEN_MAX open at once (the oldest is closed to make room), one
 * attempt every 20 ms; replaces what the server closes. Gives up by itself
 * after FLOOD_SAFETY_MS. */
static void *run_flood(void *arg)
{
    flood *f = arg;
    int fds[FLOOD_OPEN_MAX], open_n = 0;
    double end = sl_clock_ms() + FLOOD_SAFETY_MS;
    for (int i = 0; !atomic_load(&f->stop) && sl_clock_ms() < end; i++) {
        for (int k = 0; k < open_n;) {
            if (closed_by_server(fds[k], 0)) {
                f->closed_by_server++;
                close(fds[k]);
                fds[k] = fds[--open_n];
            } else {
                k++;
            }
        }
        if (open_n == FLOOD_OPEN_MAX) {
            close(fds[0]);
            memmove(fds, fds + 1, sizeof fds[0] * (size_t)--open_n);
        }
        char src[32];
        snprintf(src, sizeof src, "127.0.0.%d", 2 + i % 8);
        f->attempts++;
        int fd = raw_upgrade(f->port, src);
        if (fd >= 0) {
            f->accepted++;
            fds[open_n++] = fd;
        } else {
            f->refused++;
        }
        usleep(20000);
    }
    for (int k = 0; k < open_n; k++)
        close(fds[k]);
    return NULL;
}

int main(void)
{
    harness h;
    char mc[16], mp[16], pa[16], ht[16];
    snprintf(mc, sizeof mc, "%d", MAX_CLIENTS);
    snprintf(mp, sizeof mp, "%d", MAX_PENDING);
    snprintf(pa, sizeof pa, "%d", PER_ADDRESS);
    snprintf(ht, sizeof ht, "%d", HELLO_TIMEOUT_S);
    const char *extra[] = {"--max-clients", mc, "--max-pending", mp, "--max-pending-per-address", pa,
                           "--hello-timeout", ht, NULL};
    HARNESS_START_OR_END(h, extra);

    /* --- the per-address cap: two silent upgrades from 127.0.0.2, the third refused;
     *     127.0.0.1 is another address and still gets in --- */
    int p[PER_ADDRESS + 1];
    double opened[PER_ADDRESS + 1];
    for (int i = 0; i <= PER_ADDRESS; i++) {
        opened[i] = sl_clock_ms();
        p[i] = raw_upgrade(h.port, "127.0.0.2");
    }
    SL_CHECK_MSG(p[0] >= 0 && p[1] >= 0, "silent upgrades from 127.0.0.2: %d %d", p[0], p[1]);
    SL_CHECK_MSG(p[2] < 0, "a third pending upgrade from one address was accepted");
    SL_CHECK(wait_pending(h.port, PER_ADDRESS));
    SL_CHECK(harness_metric(h.port, "sightline_refused_address_total") >= 1);
    tclient u;
    SL_CHECK(tclient_connect(&u, h.port, NULL) == 0 && tclient_hello(&u, NULL, NULL, 32, 32) == 0);
    tclient_close(&u);

    /* --- the pending budget: 8 silent connections fill it; a ninth evicts the
     *     oldest (p[0]) long before its hello timeout, the others stay --- */
    int q[MAX_PENDING - PER_ADDRESS];
    int nq = 0;
    for (int a = 3; nq < MAX_PENDING - PER_ADDRESS; a++) {
        char src[32];
        snprintf(src, sizeof src, "127.0.0.%d", a);
        for (int k = 0; k < PER_ADDRESS && nq < MAX_PENDING - PER_ADDRESS; k++)
            q[nq++] = raw_upgrade(h.port, src);
    }
    int all_q = 1;
    for (int i = 0; i < nq; i++)
        all_q &= q[i] >= 0;
    SL_CHECK_MSG(all_q, "silent upgrades from 127.0.0.3..6 refused below the budget");
    SL_CHECK(wait_pending(h.port, MAX_PENDING));
    int ninth = raw_upgrade(h.port, "127.0.0.7");
    SL_CHECK_MSG(ninth >= 0, "an upgrade with the pending budget full was refused, not given the oldest's place");
    int evicted = closed_by_server(p[0], 1500);
    double age = sl_clock_ms() - opened[0];
    SL_CHECK_MSG(evicted && age < HELLO_TIMEOUT_S * 1000 - 500, "oldest pending closed=%d at age %.0f ms", evicted, age);
    SL_CHECK_MSG(!closed_by_server(p[1], 0) && !closed_by_server(q[0], 0), "a newer pending connection was closed");
    SL_CHECK(harness_healthz_number(h.port, "pending") == MAX_PENDING);
    SL_CHECK(harness_metric(h.port, "sightline_pending_evicted_total") >= 1);

    /* --- silent connections take no client slot: with the budget full, three
     *     users are served; a fourth that upgraded in time gets `full` at hello;
     *     an upgrade is refused; a slot frees when a user leaves --- */
    tclient users[MAX_CLIENTS], late, extra_user;
    SL_CHECK(user_served(h.port, &users[0], 1, NULL));
    SL_CHECK(user_served(h.port, &users[1], 1, NULL));
    SL_CHECK(tclient_connect(&late, h.port, NULL) == 0);   /* pending: upgraded, no hello yet */
    SL_CHECK(tclient_connect(&users[2], h.port, NULL) == 0 && tclient_hello(&users[2], NULL, NULL, 32, 32) == 0);
    users[2].auto_ack = 1;
    SL_CHECK(harness_healthz_number(h.port, "clients") == MAX_CLIENTS);
    SL_CHECK(tclient_send(&late, "{\"type\":\"hello\",\"version\":1,\"width\":32,\"height\":32}") == 0);
    cJSON *e = tclient_wait_type(&late, "error", T);
    const cJSON *code = cJSON_GetObjectItemCaseSensitive(e, "code");
    SL_CHECK_MSG(cJSON_IsString(code) && strcmp(code->valuestring, "full") == 0, "hello on a full server: %s",
                 cJSON_IsString(code) ? code->valuestring : "(no error)");
    cJSON_Delete(e);
    int r;
    do
        r = tclient_next(&late, T, NULL);
    while (r > 0);
    SL_CHECK_MSG(late.closed, "refused hello not closed");
    tclient_close(&late);
    SL_CHECK(tclient_connect(&extra_user, h.port, NULL) != 0);
    tclient_close(&extra_user);
    SL_CHECK(tclient_wait_frame(&users[2], 0, 0, T) == 0);
    tclient_close(&users[0]);
    int ok = 0;
    for (int i = 0; i < 50 && !ok; i++) {
        ok = tclient_connect(&extra_user, h.port, NULL) == 0 && tclient_hello(&extra_user, NULL, NULL, 32, 32) == 0;
        tclient_close(&extra_user);
        if (!ok)
            usleep(100000);
    }
    SL_CHECK_MSG(ok, "no slot after a user left");
    tclient_close(&users[1]);
    tclient_close(&users[2]);
    for (int i = 1; i <= PER_ADDRESS; i++)
        if (p[i] >= 0)
            close(p[i]);
    close(p[0]);
    for (int i = 0; i < nq; i++)
        if (q[i] >= 0)
            close(q[i]);
    if (ninth >= 0)
        close(ninth);
    SL_CHECK(wait_pending(h.port, 0));

    /* --- a flood from 8 addresses that reconnects for FLOOD_MS (longer than the
     *     hello timeout, so it also replaces timed-out connections); a user who
     *     connected before it keeps working, new users keep being served --- */
    tclient steady;
    SL_CHECK(user_served(h.port, &steady, 1, NULL));
    double refused0 = harness_metric(h.port, "sightline_refused_address_total");
    double evicted0 = harness_metric(h.port, "sightline_pending_evicted_total");
    flood f = {.port = h.port};
    atomic_init(&f.stop, 0);
    pthread_t th;
    double flood_t0 = sl_clock_ms();
    pthread_create(&th, NULL, run_flood, &f);
    usleep(1000000); /* the flood has filled the pending budget */
    int rounds = 0, served = 0, max_pending = 0;
    double worst_welcome = 0;
    uint32_t seq = 0;
    double flood_end = sl_clock_ms() + FLOOD_MS - 1500;
    while ((sl_clock_ms() < flood_end || rounds < FLOOD_MIN_ROUNDS) && rounds < 20) {
        int pend = (int)harness_healthz_number(h.port, "pending");
        max_pending = pend > max_pending ? pend : max_pending;
        tclient c;
        double t0 = sl_clock_ms();
        int got = user_served(h.port, &c, 0, &steady);
        double took = sl_clock_ms() - t0;
        worst_welcome = took > worst_welcome ? took : worst_welcome;
        served += got;
        if (!got)
            fprintf(stderr, "round %d: user not served (%s)\n", rounds, c.err.message);
        rounds++;
        seq++;
        tclient_send(&steady, "{\"type\":\"camera\",\"seq\":%u,\"camera\":{\"orbit\":{\"azimuth\":%u,\"elevation\":10,"
                              "\"distance\":2.5}}}", seq, 20 * seq);
        usleep(300000);
    }
    int steady_frame = tclient_wait_frame(&steady, seq, 1, T) == 0;
    atomic_store(&f.stop, 1);
    pthread_join(th, NULL);
    int flood_ms = (int)(sl_clock_ms() - flood_t0);
    double refused1 = harness_metric(h.port, "sightline_refused_address_total");
    double evicted1 = harness_metric(h.port, "sightline_pending_evicted_total");
    printf("flood: %d upgrades from 8 addresses in %d ms, %d accepted, %d refused, %d closed by the server; "
           "%d of %d users served during it (slowest %.0f ms to welcome and first frame); max pending %d; "
           "server refused %g by address, evicted %g\n",
           f.attempts, flood_ms, f.accepted, f.refused, f.closed_by_server, served, rounds, worst_welcome,
           max_pending, refused1 - refused0, evicted1 - evicted0);
    SL_CHECK_MSG(rounds >= FLOOD_MIN_ROUNDS && served == rounds, "%d of %d users served during the flood", served, rounds);
    SL_CHECK_MSG(steady_frame && !steady.closed, "the user connected before the flood: frame %d, closed %d",
                 steady_frame, steady.closed);
    SL_CHECK_MSG(max_pending <= MAX_PENDING, "pending %d > budget %d", max_pending, MAX_PENDING);
    SL_CHECK_MSG(f.accepted > MAX_PENDING && refused1 - refused0 + evicted1 - evicted0 >= 1,
                 "the flood did not press the budget: %d accepted, %g refused, %g evicted", f.accepted,
                 refused1 - refused0, evicted1 - evicted0);
    tclient_close(&steady);

    int status = harness_stop(&h);
    SL_CHECK_MSG(status == 0, "server exit status %d", status);
    SL_TEST_END();
}
