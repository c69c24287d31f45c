/* test_server_cluster_proxy.c — the client address behind HAProxy (issue 31, part 2):
 * one render node behind the balancer as scripts/cluster starts it (nodes with
 * --trusted-proxy 127.0.0.1 and the default --max-pending-per-address 4), loopback
 * sources 127.0.0.2..5 as distinct clients (Linux routes all of 127/8 to lo).
 *
 *  1. a forged X-Forwarded-For sent straight to the node from 127.0.0.2 (not a
 *     trusted proxy) changes nothing: five silent upgrades, each naming another
 *     address, are counted as 127.0.0.2's, so the fifth is refused;
 *     from 127.0.0.1 (trusted, as the balancer) the header names the client, two
 *     header lines read as one list, and an entry with a port is malformed;
 *  2. one source (127.0.0.3) opens 64 silent WebSockets through the balancer, each
 *     with a forged X-Forwarded-For of its own: the node counts all of them as
 *     127.0.0.3 (its 4 pending, 60 refused), since the balancer replaces the header;
 *  3. meanwhile a client from 127.0.0.2 connects through the balancer, says hello and
 *     gets a frame while the 4 silent ones are still open (their hello
 *     timeout is 60 s, so it did not get in by waiting them out). Before the fix every
 *     connection came from HAProxy's address and this upgrade was refused;
 *  4. the edge: a source with 64 connections open at the balancer gets its 65th
 *     closed unanswered, while another source is served.
 * The scene is prepared by a first session before the flood, so the printed time is
 * network and one 64x64 render (28-30 ms here); the check is on the decision (served
 * before any silent slot could time out), not on the machine's speed. Bounded;
 * everything stopped on every path.
 */
#include "sl_cluster.h"

#define SIZE 64
#define FLOOD 64
#define EDGE_CONNS 64

static int failures;
#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        if (!(cond)) {                                                     \
            failures++;                                                    \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);           \
            fprintf(stderr, __VA_ARGS__);                                  \
            fputc('\n', stderr);                                           \
        }                                                                  \
    } while (0)

/* A TCP connection from src to 127.0.0.1:port, or -1. */
static int connect_from(const char *src, int port)
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
    return fd;
}

/* Writes req and reads the response head into resp (size bytes) within 5 s. Returns
 * the HTTP status, 0 when the connection closed with no response, -1 on a timeout. */
static int request(int fd, const char *req, char *resp, size_t size)
{
    size_t n = strlen(req);
    resp[0] = 0;
    if (write(fd, req, n) != (ssize_t)n)
        return 0;
    size_t len = 0;
    double deadline = sl_clock_ms() + 5000;
    while (len + 1 < size) {
        if (sl_clock_ms() > deadline)
            return -1;
        struct pollfd pfd = {.fd = fd, .events = POLLIN};
        if (poll(&pfd, 1, 100) <= 0)
            continue;
        ssize_t r = read(fd, resp + len, size - 1 - len);
        if (r <= 0)
            break;
        len += (size_t)r;
        resp[len] = 0;
        if (strstr(resp, "\r\n\r\n"))
            break;
    }
    return len >= 12 && strncmp(resp, "HTTP/1.1 ", 9) == 0 ? atoi(resp + 9) : 0;
}

/* A WebSocket upgrade from src to port that never says hello, with an X-Forwarded-For
 * header when forwarded is not NULL. The socket when the answer was 101, else -1. */
static int silent_upgrade(int port, const char *src, const char *forwarded)
{
    int fd = connect_from(src, port);
    if (fd < 0)
        return -1;
    char req[768], resp[2048], xff[128] = "";
    if (forwarded)
        snprintf(xff, sizeof xff, "X-Forwarded-For: %s\r\n", forwarded);
    snprintf(req, sizeof req,
             "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
             "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
             "Sec-WebSocket-Protocol: " SL_PROTO_SUBPROTOCOL "\r\n%s\r\n", port, xff);
    if (request(fd, req, resp, sizeof resp) != 101) {
        close(fd);
        return -1;
    }
    return fd;
}

/* 1 while fd is open and the peer has sent nothing (no close, no data). */
static int still_open(int fd)
{
    struct pollfd pfd = {.fd = fd, .events = POLLIN};
    return fd >= 0 && poll(&pfd, 1, 0) == 0;
}

static void close_all(int *fds, int n)
{
    for (int i = 0; i < n; i++)
        if (fds[i] >= 0)
            close(fds[i]);
}

int main(void)
{
    harness_small_asan_quarantine();
    signal(SIGPIPE, SIG_IGN);
    sl_cluster cl;
    const char *args[] = {"--default-dataset", "tiny", "--hello-timeout", "60", NULL};
    if (sl_cluster_start(&cl, 1, args) != 0 || sl_cluster_add_generator(&cl, "tiny", HARNESS_TINY) != 0) {
        sl_cluster_stop(&cl);
        fprintf(stderr, "FAIL: the cluster did not start\n");
        return 1;
    }
    sl_cluster_stop_on_signal(&cl);
    const int node = cl.node_port[0];

    /* 0. Prepare the scene once (the later sessions share it). */
    tclient warm;
    int warmed = tclient_connect_page(&warm, cl.port, NULL) == 0 && tclient_hello(&warm, NULL, NULL, SIZE, SIZE) == 0;
    if (warmed) {
        warm.auto_ack = 1;
        warmed = tclient_wait_frame(&warm, 0, 0, 60000) == 0;
    }
    CHECK(warmed, "the first session through the balancer got no frame (%s)", warm.err.message);
    tclient_close(&warm);
    CHECK(harness_wait_metric(node, "sightline_pending_connections", 0, 10000) == 0, "pending did not drop to 0");

    /* 1. A forged header straight to the node from an untrusted address changes nothing. */
    double forwarded0 = 0, ignored0 = harness_metric(node, "sightline_forwarded_ignored_total");
    double refused0 = harness_metric(node, "sightline_refused_address_total");
    int direct[5];
    for (int i = 0; i < 5; i++) {
        char forged[32];
        snprintf(forged, sizeof forged, "198.51.100.%d", i + 1);
        direct[i] = silent_upgrade(node, "127.0.0.2", forged);
    }
    CHECK(direct[0] >= 0 && direct[1] >= 0 && direct[2] >= 0 && direct[3] >= 0,
          "silent upgrades from 127.0.0.2 below the cap were refused: %d %d %d %d", direct[0], direct[1], direct[2],
          direct[3]);
    CHECK(direct[4] < 0, "a fifth silent upgrade from 127.0.0.2 was let in (the cap is 4 per address, whatever X-Forwarded-For says)");
    CHECK(harness_metric(node, "sightline_forwarded_ignored_total") - ignored0 == 5,
          "the node counted %g ignored X-Forwarded-For headers, not 5",
          harness_metric(node, "sightline_forwarded_ignored_total") - ignored0);
    CHECK(harness_metric(node, "sightline_refused_address_total") - refused0 == 1,
          "the node refused %g upgrades for the address cap, not 1",
          harness_metric(node, "sightline_refused_address_total") - refused0);
    close_all(direct, 5);
    CHECK(harness_wait_metric(node, "sightline_pending_connections", 0, 10000) == 0, "pending did not drop to 0");

    /* 1b. From the trusted address (127.0.0.1, as the balancer) the header names the client:
     * two header lines are one list (the client is the last line's entry), and garbage
     * leaves the client as the proxy itself. */
    forwarded0 = harness_metric(node, "sightline_forwarded_clients_total");
    double malformed0 = harness_metric(node, "sightline_forwarded_malformed_total");
    int trusted[6];
    for (int i = 0; i < 5; i++) {
        char header[96];
        snprintf(header, sizeof header, "6.6.6.6\r\nX-Forwarded-For: 192.0.2.%d", i + 1);
        trusted[i] = silent_upgrade(node, "127.0.0.1", header);
    }
    trusted[5] = silent_upgrade(node, "127.0.0.1", "192.0.2.77:4711");
    int trusted_in = 0;
    for (int i = 0; i < 6; i++)
        trusted_in += trusted[i] >= 0;
    CHECK(trusted_in == 6, "%d of 6 silent upgrades forwarded by the trusted address for distinct clients got in",
          trusted_in);
    CHECK(harness_metric(node, "sightline_forwarded_clients_total") - forwarded0 == 5 &&
              harness_metric(node, "sightline_forwarded_malformed_total") - malformed0 == 1,
          "from the trusted address: %g forwarded (want 5), %g malformed (want 1)",
          harness_metric(node, "sightline_forwarded_clients_total") - forwarded0,
          harness_metric(node, "sightline_forwarded_malformed_total") - malformed0);
    close_all(trusted, 6);
    CHECK(harness_wait_metric(node, "sightline_pending_connections", 0, 10000) == 0, "pending did not drop to 0");

    /* 2. One source, 64 silent WebSockets through the balancer, each forging its own address. */
    forwarded0 = harness_metric(node, "sightline_forwarded_clients_total");
    refused0 = harness_metric(node, "sightline_refused_address_total");
    int flood[FLOOD], held = 0;
    for (int i = 0; i < FLOOD; i++) {
        char forged[32];
        snprintf(forged, sizeof forged, "203.0.113.%d", i + 1);
        flood[i] = silent_upgrade(cl.port, "127.0.0.3", forged);
        held += flood[i] >= 0;
    }
    fprintf(stderr, "flood through the balancer: %d of %d silent WebSockets held\n", held, FLOOD);
    CHECK(held == 4, "the node held %d silent WebSockets of one source through the balancer, not 4", held);
    CHECK(harness_metric(node, "sightline_forwarded_clients_total") - forwarded0 == FLOOD,
          "%g upgrades took their address from the balancer's header, not %d",
          harness_metric(node, "sightline_forwarded_clients_total") - forwarded0, FLOOD);
    CHECK(harness_metric(node, "sightline_refused_address_total") - refused0 == FLOOD - 4,
          "the node refused %g of the flood for the address cap, not %d",
          harness_metric(node, "sightline_refused_address_total") - refused0, FLOOD - 4);

    /* 3. Another source gets in at once. */
    tclient good;
    memset(&good, 0, sizeof good);
    double t0 = sl_clock_ms();
    int in = sl_wsclient_connect_from("127.0.0.2", "127.0.0.1", cl.port, NULL, "/ws", SL_PROTO_SUBPROTOCOL, NULL,
                                      10000, &good.ws, &good.err) == SL_OK;
    CHECK(in, "a client from 127.0.0.2 could not connect through the balancer: %s", good.err.message);
    if (in) {
        good.auto_ack = 1;
        in = tclient_hello(&good, NULL, NULL, SIZE, SIZE) == 0;
        CHECK(in, "the client from 127.0.0.2 got no welcome");
    }
    if (in) {
        int framed = tclient_wait_frame(&good, 0, 0, 10000) == 0;
        double ms = sl_clock_ms() - t0;
        fprintf(stderr, "client from 127.0.0.2 during the flood: first frame %.0f ms after connecting\n", ms);
        /* The decision, not the speed: served while the silent ones still hold their slots
         * (their hello timeout is 60 s), so well before a slot could have been freed. The
         * time is printed; it was 28-30 ms here (the 1 s is a measurement). */
        CHECK(framed && ms < 30000, "the client from 127.0.0.2 got %s after %.0f ms (the silent ones time out at 60 s)",
              framed ? "its first frame" : "no frame", ms);
    }
    int open_now = 0;
    for (int i = 0; i < FLOOD; i++)
        open_now += still_open(flood[i]);
    CHECK(open_now == 4, "%d of the flood's 4 silent WebSockets were still open after the client got in", open_now);
    tclient_close(&good);
    close_all(flood, FLOOD);

    /* 4. The balancer's own limit per source: 64 open connections. */
    int edge[EDGE_CONNS], served = 0;
    char resp[2048], get[256];
    snprintf(get, sizeof get, "GET /healthz HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n", cl.port);
    for (int i = 0; i < EDGE_CONNS; i++) {
        edge[i] = connect_from("127.0.0.4", cl.port);
        served += edge[i] >= 0 && request(edge[i], get, resp, sizeof resp) == 200; /* kept alive */
    }
    CHECK(served == EDGE_CONNS, "%d of %d connections from 127.0.0.4 were served", served, EDGE_CONNS);
    int over = connect_from("127.0.0.4", cl.port);
    int over_status = over >= 0 ? request(over, get, resp, sizeof resp) : 0;
    CHECK(over_status == 0, "the 65th connection from 127.0.0.4 got HTTP %d, not closed unanswered", over_status);
    if (over >= 0)
        close(over);
    int other = connect_from("127.0.0.5", cl.port);
    int other_status = other >= 0 ? request(other, get, resp, sizeof resp) : -2;
    CHECK(other_status == 200, "a connection from 127.0.0.5 got %d while 127.0.0.4 was at its limit", other_status);
    if (other >= 0)
        close(other);
    close_all(edge, EDGE_CONNS);

    sl_cluster_stop_on_signal(NULL);
    sl_cluster_stop(&cl);
    if (failures)
        fprintf(stderr, "%d check(s) failed\n", failures);
    else
        fprintf(stderr, "all checks passed\n");
    return failures ? 1 : 0;
}
