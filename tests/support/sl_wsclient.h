/* sl_wsclient.h — a minimal blocking WebSocket client (RFC 6455) for the
 * server tests and the server benchmark.
 *
 * One TCP connection, HTTP/1.1 upgrade with a subprotocol and an optional
 * Origin, masked client frames, fragmented server messages reassembled,
 * pings answered. It does not do TLS, extensions or redirects, and it does
 * not verify Sec-WebSocket-Accept (the server under test is libwebsockets;
 * the client checks the 101 status and the agreed subprotocol). Every
 * receive has a timeout and a size limit, so a broken server cannot hang or
 * exhaust a test. One thread per client object.
 */
#ifndef SL_WSCLIENT_H
#define SL_WSCLIENT_H

#include <stddef.h>
#include <stdint.h>

#include "core/sl_status.h"

typedef struct sl_wsclient sl_wsclient;

typedef enum sl_ws_kind { SL_WS_TEXT = 1, SL_WS_BINARY = 2, SL_WS_CLOSED = 8 } sl_ws_kind;

/* Connects to ws://host:port/path. origin may be NULL (no Origin header).
 * Fails with SL_ERR_IO on connect/handshake failure; a refused upgrade's
 * HTTP status line is in err. */
sl_status sl_wsclient_connect(const char *host, int port, const char *path, const char *subprotocol,
                              const char *origin, int timeout_ms, sl_wsclient **out, sl_err *err);
/* The same with an explicit Host header value (tests of the server's Host
 * check); host_header NULL sends "host:port". */
sl_status sl_wsclient_connect_host(const char *host, int port, const char *host_header, const char *path,
                                   const char *subprotocol, const char *origin, int timeout_ms, sl_wsclient **out,
                                   sl_err *err);
/* The same from local address source (numeric, NULL = any): tests that need distinct
 * client addresses use other loopback addresses (127.0.0.2, ...). */
sl_status sl_wsclient_connect_from(const char *source, const char *host, int port, const char *host_header,
                                   const char *path, const char *subprotocol, const char *origin, int timeout_ms,
                                   sl_wsclient **out, sl_err *err);
void sl_wsclient_destroy(sl_wsclient *c);   /* closes; NULL is fine */

sl_status sl_wsclient_send_text(sl_wsclient *c, const char *text, size_t len, sl_err *err);
/* Sends a frame of any opcode (tests send oversize or binary messages). */
sl_status sl_wsclient_send_frame(sl_wsclient *c, int opcode, const uint8_t *data, size_t len, sl_err *err);
/* Sends count text messages in one write, so the server reads them as one
 * burst (tests of flooding). */
sl_status sl_wsclient_send_texts(sl_wsclient *c, const char *const *texts, int count, sl_err *err);

/* Receives one whole message that starts within timeout_ms (once started, it
 * has 10 s to complete, so a timeout never splits a message). *data is owned by the
 * client and valid until the next receive; it is NUL-terminated for text.
 * On a close frame returns SL_OK with *kind = SL_WS_CLOSED, *close_code
 * (1005 when the frame has none) and the close reason in *data / *size
 * (NUL-terminated, "" when there is none).
 * Returns SL_ERR_IO on timeout (message says "timeout") or a dropped
 * connection, SL_ERR_LIMIT above max_bytes. */
sl_status sl_wsclient_recv(sl_wsclient *c, int timeout_ms, sl_ws_kind *kind, const uint8_t **data,
                           size_t *size, int *close_code, sl_err *err);

/* 1 when the last error was a timeout (the connection is still usable). */
int sl_wsclient_timed_out(const sl_wsclient *c);

#endif
