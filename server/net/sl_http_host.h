/* sl_http_host.h — which Host and Origin headers sightline-server accepts
 * (the DNS-rebinding and cross-site WebSocket rules of ws.c), as pure
 * functions of the header values and the server's address.
 *
 * Header values come from libwebsockets (which parses the request line and
 * the headers); these functions only decide, so tests/fuzz/fuzz_http.c can
 * drive them without a socket. No lws, no locks, no allocation; any thread.
 */
#ifndef SL_HTTP_HOST_H
#define SL_HTTP_HOST_H

typedef struct sl_http_site {
    int port;                      /* the listening port */
    const char *bind;              /* --bind address; NULL or "" = none */
    const char *const *origins;    /* --allow-origin URLs (borrowed) */
    int origin_count;
} sl_http_site;

/* 1 when host (a Host header value) names this server: localhost, 127.0.0.1,
 * [::1] or the bind address ("[addr]" when it holds ':') followed by
 * ":port" (or alone when port is 80), case-insensitively; or the authority
 * ("host[:port]", up to the first '/' after "://") of an allowed origin URL,
 * case-insensitively. 0 otherwise, and for NULL. */
int sl_http_host_allowed(const sl_http_site *site, const char *host);

/* 1 when a WebSocket upgrade with these Host and Origin values may proceed:
 * the host must be allowed; then origin NULL (no Origin header: not a
 * browser) is allowed, and so is "http://" + host (case-insensitively, the
 * page this server serves) or an allowed origin URL exactly. */
int sl_http_origin_allowed(const sl_http_site *site, const char *host, const char *origin);

#endif
