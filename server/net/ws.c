/* ws.c — the libwebsockets side: one context, static files, /healthz, /metrics, /ws.
 *
 * Everything here runs on the lws service thread (the thread that calls
 * sl_ws_run). Every request (HTTP and WebSocket) must name this server in
 * its Host header: localhost, 127.0.0.1, [::1] or the --bind address with
 * the listening port (no port only when it is 80), or the host of an
 * --allow-origin URL; anything else gets 421 (or a refused upgrade). That
 * stops DNS rebinding: a hostile page whose name resolves to this machine
 * still sends its own name as Host. WebSocket upgrades are accepted only
 * on path /ws with subprotocol sightline.v1 and an Origin that is absent
 * (non-browser clients), equal to the served origin http://<Host> (Host
 * checked as above) or in the allow-list. The rules themselves are pure functions
 * (http_host.c); this file reads the headers.
 * Admission: --max-clients counts only clients past hello. A connection
 * between upgrade and hello is "pending": pending connections have their own
 * budget (--max-pending) and a cap per client address
 * (--max-pending-per-address; an upgrade over it is refused; the address is the
 * peer's, or behind a --trusted-proxy the one it forwards: ws_client_address.c), so connections
 * that never say hello cannot lock real users out. When the budget is full a
 * new upgrade evicts the oldest pending connection (which has had the
 * longest to send hello), so a flood from many addresses delays nobody who
 * says hello promptly. hello itself is refused with `full` when
 * --max-clients clients are past it (session.c).
 * Incoming messages are reassembled up to SL_PROTO_MAX_HELLO bytes before
 * hello and SL_PROTO_MAX_MESSAGE after; a larger one closes only that
 * connection with 1009, a binary frame with 1003, no hello within
 * --hello-timeout with 1008 (every close says why: proto/PROTOCOL.md,
 * "Close codes"). Writes happen only in
 * SERVER_WRITEABLE, one message per callback (session.c chooses which).
 * The render thread wakes this thread with lws_cancel_service, which arrives
 * as LWS_CALLBACK_EVENT_WAIT_CANCELLED. Never calls GL.
 */
#include "sl_net.h"
#include "sl_http_host.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <strings.h>

#include <libwebsockets.h>

typedef struct ws_pss {
    sl_client *client;
} ws_pss;

typedef struct http_pss {
    char *body;
    size_t len;
    int status;
    const char *mime;
} http_pss;

static struct {
    lws_sorted_usec_list_t sul;
    sl_server *srv;
} sweep_timer;

static sl_server *server_of(struct lws *wsi)
{
    return lws_context_user(lws_get_context(wsi));
}

/* The Host / Origin rules' view of this server (sl_http_host.h). */
static sl_http_site site_of(const sl_server *srv)
{
    return (sl_http_site){.port = srv->port, .bind = srv->cfg.bind, .origins = srv->cfg.origins,
                          .origin_count = srv->cfg.origin_count};
}

/* Host header check for any request (see the file comment). */
static int request_host_allowed(sl_server *srv, struct lws *wsi)
{
    char host[256];
    sl_http_site site = site_of(srv);
    if (lws_hdr_copy(wsi, host, sizeof host, WSI_TOKEN_HOST) <= 0 || !sl_http_host_allowed(&site, host)) {
        lwsl_notice("refused request for Host \"%s\"\n", lws_hdr_total_length(wsi, WSI_TOKEN_HOST) > 0 ? host : "");
        return 0;
    }
    return 1;
}

static int origin_allowed(sl_server *srv, struct lws *wsi)
{
    char origin[256] = "", host[256];
    if (!request_host_allowed(srv, wsi))
        return 0;
    if (lws_hdr_copy(wsi, host, sizeof host, WSI_TOKEN_HOST) <= 0)
        return 0;
    /* A present Origin that does not fit the buffer is foreign, never "absent"
     * (a long hostile domain must not pass as a non-browser client). */
    int has_origin = lws_hdr_total_length(wsi, WSI_TOKEN_ORIGIN) > 0;
    if (has_origin && lws_hdr_copy(wsi, origin, sizeof origin, WSI_TOKEN_ORIGIN) <= 0) {
        lwsl_notice("refused WebSocket upgrade: Origin of %d bytes\n", lws_hdr_total_length(wsi, WSI_TOKEN_ORIGIN));
        return 0;
    }
    sl_http_site site = site_of(srv);
    if (sl_http_origin_allowed(&site, host, has_origin ? origin : NULL))
        return 1;
    lwsl_notice("refused WebSocket upgrade from origin %s\n", origin);
    return 0;
}

/* LWS_CALLBACK_FILTER_HTTP_CONNECTION: a plain HTTP request with a foreign
 * Host gets 421 Misdirected Request and the connection is closed. */
static int filter_http(sl_server *srv, struct lws *wsi)
{
    if (request_host_allowed(srv, wsi))
        return 0;
    lws_return_http_status(wsi, 421, "unknown Host");
    return 1;
}

static int pending_from(const sl_server *srv, const char *addr)
{
    int n = 0;
    for (const sl_client *c = srv->pending; c; c = c->pending_next)
        n += strcmp(c->addr, addr) == 0;
    return n;
}

static void pending_leave(sl_server *srv, sl_client *c)
{
    if (!c->pending)
        return;
    for (sl_client **pp = &srv->pending; *pp; pp = &(*pp)->pending_next)
        if (*pp == c) {
            *pp = c->pending_next;
            break;
        }
    c->pending = 0;
    c->pending_next = NULL;
    pthread_mutex_lock(&srv->lock);
    srv->pending_count--;
    pthread_mutex_unlock(&srv->lock);
}

/* The budget is full: the oldest pending connection (the list's tail) is
 * closed with 1008 at its next writable callback and ignored until then. */
static void evict_oldest_pending(sl_server *srv)
{
    sl_client *oldest = srv->pending;
    while (oldest && oldest->pending_next)
        oldest = oldest->pending_next;
    if (!oldest)
        return;
    lwsl_notice("evicted a pending WebSocket from %s (--max-pending %d)\n", oldest->addr, srv->cfg.max_pending);
    pending_leave(srv, oldest);
    char reason[80];
    snprintf(reason, sizeof reason, "pending budget: %d connections without hello (--max-pending)",
             srv->cfg.max_pending);
    sl_client_close(oldest, LWS_CLOSE_STATUS_POLICY_VIOLATION, reason, 0);
    pthread_mutex_lock(&srv->lock);
    srv->metrics.pending_evicted++;
    pthread_mutex_unlock(&srv->lock);
}

/* 1 when an upgrade from addr is refused: --max-clients past hello, or
 * --max-pending-per-address pending from addr already. */
static int admission_refused(sl_server *srv, const char *addr)
{
    int full = srv->client_count >= srv->cfg.max_clients;
    int crowded = !full && pending_from(srv, addr) >= srv->cfg.max_pending_per_address;
    if (!full && !crowded)
        return 0;
    if (full)
        lwsl_notice("refused WebSocket: %d clients (--max-clients)\n", srv->client_count);
    else
        lwsl_notice("refused WebSocket: %d pending from %s (--max-pending-per-address)\n",
                    srv->cfg.max_pending_per_address, addr);
    pthread_mutex_lock(&srv->lock);
    if (full)
        srv->metrics.refused_full++;
    else
        srv->metrics.refused_address++;
    pthread_mutex_unlock(&srv->lock);
    return 1;
}

/* Ends wsi's link from its own callback with a close frame; returns -1, which the callback returns. */
static int close_now(struct lws *wsi, enum lws_close_status code, const char *reason)
{
    lws_close_reason(wsi, code, (unsigned char *)reason, strlen(reason));
    return -1;
}

static int callback_ws(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
    ws_pss *pss = user;
    sl_server *srv = server_of(wsi);
    switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION: {
        char uri[64];
        if (lws_hdr_copy(wsi, uri, sizeof uri, WSI_TOKEN_GET_URI) <= 0 || strcmp(uri, "/ws") != 0)
            return 1;
        if (!origin_allowed(srv, wsi))
            return 1;
        char addr[SL_CLIENT_ADDRESS_MAX];
        sl_ws_client_address(srv, wsi, 1, addr, sizeof addr);
        return admission_refused(srv, addr);
    }
    case LWS_CALLBACK_ESTABLISHED: {
        sl_client *c = calloc(1, sizeof *c);
        if (!c)
            return close_now(wsi, LWS_CLOSE_STATUS_UNEXPECTED_CONDITION, "out of memory");
        sl_ws_client_address(srv, wsi, 0, c->addr, sizeof c->addr);
        /* Checked again: another upgrade may have been established since the filter. */
        if (admission_refused(srv, c->addr)) {
            free(c);
            return -1;
        }
        if (srv->pending_count >= srv->cfg.max_pending)
            evict_oldest_pending(srv);
        c->link = wsi;
        c->transport = &srv->transport;
        c->id = ++srv->next_client_id;
        c->pending = 1;
        c->pending_next = srv->pending;
        srv->pending = c;
        pss->client = c;
        /* hello must come within --hello-timeout s (LWS_CALLBACK_TIMER closes with 1008; both are
         * cleared by hello_done when it comes; the timeout drops a link that cannot take the close). */
        lws_set_timer_usecs(wsi, (lws_usec_t)srv->cfg.hello_timeout_s * LWS_USEC_PER_SEC);
        lws_set_timeout(wsi, PENDING_TIMEOUT_USER_REASON_BASE + 1, srv->cfg.hello_timeout_s + SL_CLOSE_GRACE_S);
        pthread_mutex_lock(&srv->lock);
        srv->pending_count++;
        pthread_mutex_unlock(&srv->lock);
        return 0;
    }
    case LWS_CALLBACK_CLOSED:
        if (pss->client) {
            sl_client *c = pss->client;
            int counted = c->hello_done;
            pending_leave(srv, c);
            sl_sessions_on_close(srv, c);
            free(c);
            pss->client = NULL;
            if (counted) {
                pthread_mutex_lock(&srv->lock);
                srv->client_count--;
                pthread_mutex_unlock(&srv->lock);
            }
        }
        return 0;
    case LWS_CALLBACK_TIMER: {
        sl_client *c = pss->client;
        if (!c || c->hello_done || c->close_code)
            return 0;
        char reason[64];
        snprintf(reason, sizeof reason, "no hello within %d s (--hello-timeout)", srv->cfg.hello_timeout_s);
        return close_now(wsi, LWS_CLOSE_STATUS_POLICY_VIOLATION, reason);
    }
    case LWS_CALLBACK_RECEIVE: {
        sl_client *c = pss->client;
        if (!c)
            return -1;
        if (c->close_code)
            return 0; /* closing: only what was queued before is still sent */
        if (lws_frame_is_binary(wsi))
            return close_now(wsi, LWS_CLOSE_STATUS_UNACCEPTABLE_OPCODE, "binary frames are not part of the protocol");
        size_t limit = c->hello_done ? SL_PROTO_MAX_MESSAGE : SL_PROTO_MAX_HELLO;
        size_t remaining = lws_remaining_packet_payload(wsi);
        if (c->rx_len + len + remaining > limit) {
            char reason[64];
            snprintf(reason, sizeof reason, "message over %zu bytes", limit);
            return close_now(wsi, LWS_CLOSE_STATUS_MESSAGE_TOO_LARGE, reason);
        }
        if (c->rx_len + len + 1 > c->rx_cap) {
            size_t cap = c->rx_len + len + remaining + 1;
            char *p = realloc(c->rx, cap);
            if (!p)
                return close_now(wsi, LWS_CLOSE_STATUS_UNEXPECTED_CONDITION, "out of memory");
            c->rx = p;
            c->rx_cap = cap;
        }
        memcpy(c->rx + c->rx_len, in, len);
        c->rx_len += len;
        if (lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0) {
            size_t n = c->rx_len;
            c->rx_len = 0;
            sl_sessions_on_text(srv, c, c->rx, n);
        }
        return 0;
    }
    case LWS_CALLBACK_SERVER_WRITEABLE:
        if (!pss->client)
            return -1;
        return sl_client_write_next(srv, pss->client);
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        sl_sessions_on_wake(srv);
        return 0;
    default:
        return 0;
    }
}

/* GET /recording/KEY?token=T: a finished recording, once (record.c); the
 * file is removed as soon as libwebsockets has it open. */
static int serve_recording(sl_server *srv, struct lws *wsi, const char *key)
{
    char arg[96] = "", file[400];
    const char *mime = NULL;
    const char *token = lws_get_urlarg_by_name(wsi, "token=", arg, (int)sizeof arg);
    int status = sl_record_take_download(srv, key, token ? token : "", file, sizeof file, &mime);
    if (status != 200) {
        if (lws_return_http_status(wsi, (unsigned)status, NULL))
            return -1;
        return lws_http_transaction_completed(wsi) ? -1 : 0;
    }
    int rc = lws_serve_http_file(wsi, file, mime, NULL, 0);
    unlink(file);
    return rc < 0 ? -1 : 0;
}

static int callback_http_extras(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
    http_pss *pss = user;
    sl_server *srv = server_of(wsi);
    uint8_t headers[LWS_PRE + 1024], *start = headers + LWS_PRE, *p = start, *end = headers + sizeof headers - 1;
    switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
        return 1; /* WebSocket only on sightline.v1 */
    case LWS_CALLBACK_FILTER_HTTP_CONNECTION:
        return filter_http(srv, wsi);
    case LWS_CALLBACK_HTTP: {
        char uri[96] = "";
        lws_hdr_copy(wsi, uri, sizeof uri, WSI_TOKEN_GET_URI);
        free(pss->body);
        pss->body = NULL;
        if (strncmp(uri, "/recording/", 11) == 0)
            return serve_recording(srv, wsi, uri + 11);
        if (strcmp(uri, "/healthz") == 0) {
            pss->body = sl_http_healthz(srv, &pss->status);
            pss->mime = "application/json";
        } else if (strcmp(uri, "/metrics") == 0) {
            pss->body = sl_http_metrics(srv);
            pss->status = 200;
            pss->mime = "text/plain; version=0.0.4";
        } else {
            if (lws_return_http_status(wsi, HTTP_STATUS_NOT_FOUND, NULL))
                return -1;
            return lws_http_transaction_completed(wsi) ? -1 : 0;
        }
        if (!pss->body)
            return -1;
        pss->len = strlen(pss->body);
        if (lws_add_http_common_headers(wsi, (unsigned)pss->status, pss->mime, pss->len, &p, end) ||
            lws_add_http_header_by_token(wsi, WSI_TOKEN_HTTP_CACHE_CONTROL, (const unsigned char *)"no-store", 8,
                                         &p, end) ||
            lws_finalize_write_http_header(wsi, start, &p, end))
            return 1;
        lws_callback_on_writable(wsi);
        return 0;
    }
    case LWS_CALLBACK_HTTP_WRITEABLE: {
        if (!pss->body)
            return -1;
        uint8_t *buf = malloc(LWS_PRE + pss->len + 1);
        if (!buf)
            return -1;
        memcpy(buf + LWS_PRE, pss->body, pss->len);
        int n = lws_write(wsi, buf + LWS_PRE, pss->len, LWS_WRITE_HTTP_FINAL);
        free(buf);
        free(pss->body);
        pss->body = NULL;
        if (n < (int)pss->len)
            return -1;
        if (lws_http_transaction_completed(wsi))
            return -1;
        return 0;
    }
    case LWS_CALLBACK_CLOSED_HTTP:
        free(pss->body);
        pss->body = NULL;
        return 0;
    default:
        return lws_callback_http_dummy(wsi, reason, user, in, len);
    }
}

/* protocols[0] handles plain HTTP (files, 404s) and refuses WebSocket
 * upgrades that name no subprotocol. */
static int callback_default(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
    if (reason == LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION)
        return 1;
    if (reason == LWS_CALLBACK_FILTER_HTTP_CONNECTION)
        return filter_http(server_of(wsi), wsi);
    return lws_callback_http_dummy(wsi, reason, user, in, len);
}

static const struct lws_protocols protocols[] = {
    {"http", callback_default, 0, 0, 0, NULL, 0},
    {"http-extras", callback_http_extras, sizeof(http_pss), 0, 0, NULL, 0},
    {SL_PROTO_SUBPROTOCOL, callback_ws, sizeof(ws_pss), 16384, 0, NULL, 0},
    {NULL, NULL, 0, 0, 0, NULL, 0},
};

static struct lws_http_mount mount_recording = {
    .mountpoint = "/recording", .mountpoint_len = 10, .origin = "http-extras", .origin_protocol = LWSMPRO_CALLBACK,
};
static struct lws_http_mount mount_metrics = {
    .mount_next = &mount_recording, .mountpoint = "/metrics", .mountpoint_len = 8, .origin = "http-extras",
    .origin_protocol = LWSMPRO_CALLBACK,
};
static struct lws_http_mount mount_healthz = {
    .mount_next = &mount_metrics, .mountpoint = "/healthz", .mountpoint_len = 8, .origin = "http-extras",
    .origin_protocol = LWSMPRO_CALLBACK,
};
static struct lws_http_mount mount_root = {
    .mount_next = &mount_healthz, .mountpoint = "/", .mountpoint_len = 1, .def = "index.html",
    .origin_protocol = LWSMPRO_FILE,
};

static void sweep_cb(lws_sorted_usec_list_t *sul)
{
    (void)sul;
    sl_sessions_sweep(sweep_timer.srv);
    lws_sul_schedule(sweep_timer.srv->lws, 0, &sweep_timer.sul, sweep_cb, LWS_US_PER_SEC);
}

/* Path playback (playback.c): steps every playing session, then sleeps until the next step is due. */
static struct {
    sl_server *srv;
    lws_sorted_usec_list_t sul;
} play_timer;

static void play_cb(lws_sorted_usec_list_t *sul)
{
    (void)sul;
    double next_ms = sl_play_tick(play_timer.srv);
    if (next_ms >= 0)
        lws_sul_schedule(play_timer.srv->lws, 0, &play_timer.sul, play_cb, (lws_usec_t)(next_ms * 1000.0) + 1);
}

/* sl_transport_hooks for the sessions (service thread). */
static void hello_done(sl_server *srv, sl_client *c)
{
    pending_leave(srv, c);
    lws_set_timeout(c->link, NO_PENDING_TIMEOUT, 0);
    lws_set_timer_usecs(c->link, LWS_SET_TIMER_USEC_CANCEL); /* the hello timeout */
}

static void want_write(sl_client *c) { lws_callback_on_writable(c->link); }

static void wake_service(sl_server *srv) { lws_cancel_service(srv->lws); }

static void closing(sl_client *c)
{
    lws_set_timeout(c->link, PENDING_TIMEOUT_CLOSE_SEND, SL_CLOSE_GRACE_S);
    lws_callback_on_writable(c->link);
}

static void schedule_play(sl_server *srv, double ms)
{
    play_timer.srv = srv;
    lws_sul_schedule(srv->lws, 0, &play_timer.sul, play_cb, (lws_usec_t)(ms * 1000.0) + 1);
}

sl_status sl_ws_create(sl_server *srv, int *port, sl_err *err)
{
    lws_set_log_level(LLL_ERR | LLL_WARN, NULL);
    srv->transport = (sl_transport_hooks){.schedule_play = schedule_play, .hello_done = hello_done,
                                          .want_write = want_write, .closing = closing,
                                          .wake_service = wake_service};
    mount_root.origin = srv->cfg.web_dir;
    struct lws_context_creation_info info;
    memset(&info, 0, sizeof info);
    info.port = srv->cfg.port;
    info.iface = srv->cfg.bind;
    info.protocols = protocols;
    info.mounts = &mount_root;
    info.user = srv;
    info.options = LWS_SERVER_OPTION_HTTP_HEADERS_SECURITY_BEST_PRACTICES_ENFORCE |
                   LWS_SERVER_OPTION_VALIDATE_UTF8;
    srv->lws = lws_create_context(&info);
    if (!srv->lws)
        return sl_err_set(err, SL_ERR_IO, "cannot listen on %s:%d (libwebsockets context creation failed)",
                          srv->cfg.bind, srv->cfg.port);
    struct lws_vhost *vh = lws_get_vhost_by_name(srv->lws, "default");
    *port = vh ? lws_get_vhost_listen_port(vh) : srv->cfg.port;
    srv->port = *port;
    sweep_timer.srv = srv;
    lws_sul_schedule(srv->lws, 0, &sweep_timer.sul, sweep_cb, LWS_US_PER_SEC);
    return SL_OK;
}

void sl_ws_run(sl_server *srv, volatile sig_atomic_t *interrupted, volatile sig_atomic_t *drain)
{
    int draining = 0;
    while (!*interrupted) {
        if (*drain && !draining) {
            sl_sessions_drain_begin(srv);
            draining = 1;
        }
        /* Checked at least once a second: the sweep timer wakes lws_service. */
        if (draining && sl_sessions_drain_done(srv))
            break;
        if (lws_service(srv->lws, 0) < 0)
            break;
    }
}

void sl_ws_destroy(sl_server *srv)
{
    if (!srv->lws)
        return;
    lws_context_destroy(srv->lws);
    srv->lws = NULL;
}
