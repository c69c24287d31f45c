/* agent.c — the HAProxy agent-check listener (--agent-port P).
 *
 * HAProxy's agent-check opens a TCP connection, reads one ASCII line and
 * closes (HAProxy configuration manual, "agent-check"). This node answers
 *   "up ready W%\n"  while it takes new sessions, and
 *   "drain\n"        while it drains (SIGTERM): HAProxy then sends it no new
 *                    sessions but keeps routing persistent ones (a session
 *                    id in the URL query, PROTOCOL.md), which is why the
 *                    balancer must not use the 503 of /healthz as its check.
 * "ready" cancels a DRAIN that an earlier answer (a drained node of the
 * same name) left in HAProxy's admin state; "up" alone would not.
 * W = 100 - floor(99 * sessions / --max-sessions), at least 1: a node
 * loses 99/max_sessions percent per live session, and a full node still
 * gets 1% (the weight of zero would mean drain).
 * Bounded: one connection at a time, one short non-blocking write, then
 * the input (an agent-send string) is read for at most 100 ms and the
 * connection closed. Runs on its own thread; it only reads the counts under
 * sl_server.lock. Not here: the HTTP health check (http.c).
 */
#include "sl_net.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

typedef struct sl_agent {
    sl_server *srv;           /* borrowed */
    int fd;                   /* listening socket */
    atomic_int stop;
    pthread_t thread;
} sl_agent;

void sl_agent_reply(sl_server *srv, char out[32])
{
    pthread_mutex_lock(&srv->lock);
    int draining = srv->draining || srv->stop, sessions = srv->session_count;
    pthread_mutex_unlock(&srv->lock);
    int max = srv->cfg.max_sessions > 0 ? srv->cfg.max_sessions : 1;
    int weight = 100 - (99 * (sessions < max ? sessions : max)) / max;
    if (draining)
        snprintf(out, 32, "drain\n");
    else
        snprintf(out, 32, "up ready %d%%\n", weight < 1 ? 1 : weight);
}

static void answer(sl_agent *a, int fd)
{
    char line[32];
    sl_agent_reply(a->srv, line);
    if (send(fd, line, strlen(line), MSG_DONTWAIT | MSG_NOSIGNAL) < 0)
        fprintf(stderr, "sightline-server: agent-check reply not sent: %s\n", strerror(errno));
    shutdown(fd, SHUT_WR);
    /* Read what the checker sent (if anything) so the close is a FIN, not a
     * reset that could discard the reply; 100 ms and 4 reads at most. */
    char junk[256];
    for (int i = 0; i < 4; i++) {
        struct pollfd p = {.fd = fd, .events = POLLIN};
        if (poll(&p, 1, 100) <= 0 || recv(fd, junk, sizeof junk, MSG_DONTWAIT) <= 0)
            break;
    }
    close(fd);
}

static void *agent_main(void *arg)
{
    sl_agent *a = arg;
    while (!atomic_load(&a->stop)) {
        struct pollfd p = {.fd = a->fd, .events = POLLIN};
        if (poll(&p, 1, 200) <= 0)
            continue;
        int fd = accept(a->fd, NULL, NULL);
        if (fd >= 0)
            answer(a, fd);
    }
    return NULL;
}

sl_status sl_agent_start(sl_server *srv, sl_err *err)
{
    srv->agent = NULL;
    if (srv->cfg.agent_port <= 0)
        return SL_OK;
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM, .ai_flags = AI_PASSIVE | AI_NUMERICSERV};
    struct addrinfo *res = NULL;
    char port[16];
    snprintf(port, sizeof port, "%d", srv->cfg.agent_port);
    int gai = getaddrinfo(srv->cfg.bind, port, &hints, &res);
    if (gai != 0)
        return sl_err_set(err, SL_ERR_IO, "--agent-port: cannot resolve %s: %s", srv->cfg.bind, gai_strerror(gai));
    int fd = socket(res->ai_family, res->ai_socktype | SOCK_CLOEXEC, 0);
    int one = 1;
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
        bind(fd, res->ai_addr, res->ai_addrlen) != 0 || listen(fd, 16) != 0) {
        sl_status st = sl_err_set(err, SL_ERR_IO, "--agent-port: cannot listen on %s:%d: %s", srv->cfg.bind,
                                  srv->cfg.agent_port, strerror(errno));
        if (fd >= 0)
            close(fd);
        freeaddrinfo(res);
        return st;
    }
    freeaddrinfo(res);
    sl_agent *a = calloc(1, sizeof *a);
    if (!a) {
        close(fd);
        return sl_err_set(err, SL_ERR_NOMEM, "--agent-port: out of memory");
    }
    a->srv = srv;
    a->fd = fd;
    atomic_init(&a->stop, 0);
    if (pthread_create(&a->thread, NULL, agent_main, a) != 0) {
        close(fd);
        free(a);
        return sl_err_set(err, SL_ERR_NOMEM, "--agent-port: cannot start its thread");
    }
    srv->agent = a;
    return SL_OK;
}

void sl_agent_stop(sl_server *srv)
{
    sl_agent *a = srv->agent;
    if (!a)
        return;
    atomic_store(&a->stop, 1);
    pthread_join(a->thread, NULL);
    close(a->fd);
    free(a);
    srv->agent = NULL;
}
