/* sl_net.h — the transport of sightline-server: the libwebsockets context, the
 * WebSocket callbacks and the pre-hello budget, HTTP routes (static files,
 * /healthz, /metrics, /recording), the Host rules, the write loop and its
 * back-pressure, and the HAProxy agent-check listener. The top layer: it calls
 * the sessions and hands them sl_transport_hooks at start (sl_ws_create).
 *
 *   ws.c               lws context, WebSocket protocol, static files (service thread)
 *   client_write.c     the write loop: one message per writable callback (service thread)
 *   http.c             /healthz and /metrics bodies (service thread)
 *   http_host.c        the Host / Origin rules, pure (sl_http_host.h; any thread)
 *   ws_client_address.c  the client address of an upgrade (service thread)
 *   agent.c            the HAProxy agent-check listener (--agent-port; its own thread)
 */
#ifndef SL_NET_H
#define SL_NET_H

#include <signal.h>

#include "sessions/sl_sessions.h"

struct lws;

/* client_write.c: called from ws.c on writable: sends one message. Returns -1 to close. */
int sl_client_write_next(sl_server *srv, sl_client *c);

/* agent.c: the HAProxy agent-check listener on cfg.agent_port (its own thread). */
/* The one line the agent answers now (lock not held by the caller): "drain\n"
 * while draining, else "up ready W%\n" (see agent.c for W). out gets 32 bytes. */
void sl_agent_reply(sl_server *srv, char out[32]);
sl_status sl_agent_start(sl_server *srv, sl_err *err);
void sl_agent_stop(sl_server *srv);                 /* NULL agent is fine */

/* http.c */
char *sl_http_healthz(sl_server *srv, int *status);
char *sl_http_metrics(sl_server *srv);

/* ws.c */
sl_status sl_ws_create(sl_server *srv, int *port, sl_err *err);
/* ws_client_address.c: the client address of upgrade wsi (the peer, or behind a
 * --trusted-proxy the address it forwards), canonical text in out (size >=
 * SL_CLIENT_ADDRESS_MAX). count: 1 at the first look of an upgrade, which
 * counts and logs a forwarded, ignored or malformed header. Service thread. */
void sl_ws_client_address(sl_server *srv, struct lws *wsi, int count, char *out, size_t size);
/* Serves until *interrupted; *drain (the first SIGTERM) starts draining, and
 * the loop ends once sl_sessions_drain_done says so. */
void sl_ws_run(sl_server *srv, volatile sig_atomic_t *interrupted, volatile sig_atomic_t *drain);
void sl_ws_destroy(sl_server *srv);

#endif
