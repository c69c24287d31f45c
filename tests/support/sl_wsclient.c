/* sl_wsclient.c — minimal blocking WebSocket client (see sl_wsclient.h).
 *
 * Reads go through a 64 KiB buffer filled with poll()+recv() under a
 * deadline (the caller's timeout for a message to start, 10 s to finish); a message larger than SL_WSCLIENT_MAX_MESSAGE is refused before
 * it is allocated. Masks come from a per-client xorshift PRNG (tests do not
 * need unpredictable masks, only masked frames). One thread per client.
 */
#include "sl_wsclient.h"

#include <errno.h>
#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include "core/sl_clock.h"

#define SL_WSCLIENT_MAX_MESSAGE (64u * 1024u * 1024u)

struct sl_wsclient {
    int fd;
    uint8_t rbuf[65536];
    size_t rlen, rpos;
    uint8_t *msg;             /* reassembled message, NUL-terminated */
    size_t msg_size, msg_cap;
    uint64_t rng;
    int timed_out;
};

static sl_status send_all(sl_wsclient *c, const uint8_t *p, size_t n, sl_err *err)
{
    while (n) {
        ssize_t w = send(c->fd, p, n, MSG_NOSIGNAL);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            return sl_err_set(err, SL_ERR_IO, "websocket send failed: %s", strerror(errno));
        }
        p += w;
        n -= (size_t)w;
    }
    return SL_OK;
}

/* Ensures `need` unread bytes are buffered (need <= sizeof rbuf) before the deadline. */
static sl_status fill(sl_wsclient *c, size_t need, double deadline, sl_err *err)
{
    if (c->rpos > 0 && c->rlen - c->rpos < need) {
        memmove(c->rbuf, c->rbuf + c->rpos, c->rlen - c->rpos);
        c->rlen -= c->rpos;
        c->rpos = 0;
    }
    while (c->rlen - c->rpos < need) {
        int wait = (int)(deadline - sl_clock_ms());
        if (wait <= 0) {
            c->timed_out = 1;
            return sl_err_set(err, SL_ERR_IO, "websocket receive timeout");
        }
        struct pollfd pfd = {.fd = c->fd, .events = POLLIN};
        int pr = poll(&pfd, 1, wait);
        if (pr < 0 && errno != EINTR)
            return sl_err_set(err, SL_ERR_IO, "poll failed: %s", strerror(errno));
        if (pr <= 0)
            continue;
        ssize_t r = recv(c->fd, c->rbuf + c->rlen, sizeof c->rbuf - c->rlen, 0);
        if (r == 0)
            return sl_err_set(err, SL_ERR_IO, "websocket connection closed by the server");
        if (r < 0) {
            if (errno == EINTR || errno == EAGAIN)
                continue;
            return sl_err_set(err, SL_ERR_IO, "websocket recv failed: %s", strerror(errno));
        }
        c->rlen += (size_t)r;
    }
    return SL_OK;
}

/* Reads n bytes into dst (any n) before the deadline. */
static sl_status read_bytes(sl_wsclient *c, uint8_t *dst, size_t n, double deadline, sl_err *err)
{
    while (n) {
        size_t chunk = n < sizeof c->rbuf ? n : sizeof c->rbuf;
        sl_status st = fill(c, chunk, deadline, err);
        if (st)
            return st;
        memcpy(dst, c->rbuf + c->rpos, chunk);
        c->rpos += chunk;
        dst += chunk;
        n -= chunk;
    }
    return SL_OK;
}

sl_status sl_wsclient_connect(const char *host, int port, const char *path, const char *subprotocol,
                              const char *origin, int timeout_ms, sl_wsclient **out, sl_err *err)
{
    return sl_wsclient_connect_host(host, port, NULL, path, subprotocol, origin, timeout_ms, out, err);
}

sl_status sl_wsclient_connect_host(const char *host, int port, const char *host_header, const char *path,
                                   const char *subprotocol, const char *origin, int timeout_ms, sl_wsclient **out,
                                   sl_err *err)
{
    return sl_wsclient_connect_from(NULL, host, port, host_header, path, subprotocol, origin, timeout_ms, out, err);
}

/* Binds fd to the numeric address source (port 0); 0, or -1. */
static int bind_source(int fd, int family, const char *source)
{
    struct sockaddr_storage ss;
    memset(&ss, 0, sizeof ss);
    socklen_t len = 0;
    if (family == AF_INET) {
        struct sockaddr_in *a = (struct sockaddr_in *)&ss;
        a->sin_family = AF_INET;
        if (inet_pton(AF_INET, source, &a->sin_addr) != 1)
            return -1;
        len = sizeof *a;
    } else {
        struct sockaddr_in6 *a = (struct sockaddr_in6 *)&ss;
        a->sin6_family = AF_INET6;
        if (inet_pton(AF_INET6, source, &a->sin6_addr) != 1)
            return -1;
        len = sizeof *a;
    }
    return bind(fd, (struct sockaddr *)&ss, len);
}

sl_status sl_wsclient_connect_from(const char *source, const char *host, int port, const char *host_header,
                                   const char *path, const char *subprotocol, const char *origin, int timeout_ms,
                                   sl_wsclient **out, sl_err *err)
{
    *out = NULL;
    sl_wsclient *c = calloc(1, sizeof *c);
    if (!c)
        return sl_err_set(err, SL_ERR_NOMEM, "websocket client allocation failed");
    c->fd = -1;
    c->rng = 0x9e3779b97f4a7c15ull ^ (uint64_t)(uintptr_t)c;
    char portstr[16];
    snprintf(portstr, sizeof portstr, "%d", port);
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM}, *ai = NULL;
    if (getaddrinfo(host, portstr, &hints, &ai) != 0 || !ai) {
        free(c);
        return sl_err_set(err, SL_ERR_IO, "cannot resolve %s", host);
    }
    for (struct addrinfo *a = ai; a && c->fd < 0; a = a->ai_next) {
        c->fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (c->fd >= 0 && ((source && bind_source(c->fd, a->ai_family, source) != 0) ||
                           connect(c->fd, a->ai_addr, a->ai_addrlen) != 0)) {
            close(c->fd);
            c->fd = -1;
        }
    }
    freeaddrinfo(ai);
    if (c->fd >= 0) {
        /* Small messages (camera, ack) must not wait for Nagle + delayed ACK (~40 ms). */
        int one = 1;
        setsockopt(c->fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
    if (c->fd < 0) {
        free(c);
        return sl_err_set(err, SL_ERR_IO, "cannot connect to %s:%d", host, port);
    }
    char req[1024], host_value[300];
    if (host_header)
        snprintf(host_value, sizeof host_value, "%s", host_header);
    else
        snprintf(host_value, sizeof host_value, "%s:%d", host, port);
    int n = snprintf(req, sizeof req,
                     "GET %s HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                     "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                     "Sec-WebSocket-Protocol: %s\r\n%s%s%s\r\n",
                     path, host_value, subprotocol, origin ? "Origin: " : "", origin ? origin : "",
                     origin ? "\r\n" : "");
    sl_status st = send_all(c, (const uint8_t *)req, (size_t)n, err);
    if (st) {
        sl_wsclient_destroy(c);
        return st;
    }
    /* Read the response head byte by byte until the blank line (bounded). */
    char head[4096];
    size_t hl = 0;
    double deadline = sl_clock_ms() + timeout_ms;
    while (hl < 4 || memcmp(head + hl - 4, "\r\n\r\n", 4) != 0) {
        if (hl + 1 >= sizeof head) {
            sl_wsclient_destroy(c);
            return sl_err_set(err, SL_ERR_IO, "handshake response longer than %zu bytes", sizeof head);
        }
        st = read_bytes(c, (uint8_t *)head + hl, 1, deadline, err);
        if (st) {
            sl_wsclient_destroy(c);
            return sl_err_set(err, SL_ERR_IO, "handshake failed: no complete response (%zu bytes read)", hl);
        }
        hl++;
    }
    head[hl] = '\0';
    if (strncmp(head, "HTTP/1.1 101", 12) != 0) {
        char *eol = strstr(head, "\r\n");
        if (eol)
            *eol = '\0';
        sl_wsclient_destroy(c);
        return sl_err_set(err, SL_ERR_IO, "upgrade refused: %s", head);
    }
    char want[256];
    snprintf(want, sizeof want, "sec-websocket-protocol: %s", subprotocol);
    int found = 0;
    for (char *line = head; line && *line; line = strstr(line, "\r\n") ? strstr(line, "\r\n") + 2 : NULL)
        if (strncasecmp(line, want, strlen(want)) == 0)
            found = 1;
    if (!found) {
        sl_wsclient_destroy(c);
        return sl_err_set(err, SL_ERR_IO, "server did not agree to subprotocol %s", subprotocol);
    }
    *out = c;
    return SL_OK;
}

void sl_wsclient_destroy(sl_wsclient *c)
{
    if (!c)
        return;
    if (c->fd >= 0) {
        uint8_t close_frame[8] = {0x88, 0x82, 0, 0, 0, 0, 0x03, 0xe8}; /* 1000, zero mask */
        (void)send(c->fd, close_frame, sizeof close_frame, MSG_NOSIGNAL);
        close(c->fd);
    }
    free(c->msg);
    free(c);
}

/* Appends one masked frame to buf (which has room for len + 14 bytes); returns its size. */
static size_t encode_frame(sl_wsclient *c, int opcode, const uint8_t *data, size_t len, uint8_t *buf)
{
    uint8_t hdr[14];
    size_t h = 0;
    hdr[h++] = (uint8_t)(0x80 | (opcode & 0x0f));
    if (len < 126) {
        hdr[h++] = (uint8_t)(0x80 | len);
    } else if (len < 65536) {
        hdr[h++] = 0x80 | 126;
        hdr[h++] = (uint8_t)(len >> 8);
        hdr[h++] = (uint8_t)len;
    } else {
        hdr[h++] = 0x80 | 127;
        for (int i = 7; i >= 0; i--)
            hdr[h++] = (uint8_t)((uint64_t)len >> (8 * i));
    }
    c->rng ^= c->rng << 13; c->rng ^= c->rng >> 7; c->rng ^= c->rng << 17;
    uint8_t mask[4] = {(uint8_t)c->rng, (uint8_t)(c->rng >> 8), (uint8_t)(c->rng >> 16), (uint8_t)(c->rng >> 24)};
    memcpy(hdr + h, mask, 4);
    h += 4;
    memcpy(buf, hdr, h);
    for (size_t i = 0; i < len; i++)
        buf[h + i] = data[i] ^ mask[i & 3];
    return h + len;
}

sl_status sl_wsclient_send_frame(sl_wsclient *c, int opcode, const uint8_t *data, size_t len, sl_err *err)
{
    uint8_t *buf = malloc(len + 14);
    if (!buf)
        return sl_err_set(err, SL_ERR_NOMEM, "cannot allocate a %zu-byte frame", len);
    size_t n = encode_frame(c, opcode, data, len, buf);
    sl_status st = send_all(c, buf, n, err);
    free(buf);
    return st;
}

sl_status sl_wsclient_send_texts(sl_wsclient *c, const char *const *texts, int count, sl_err *err)
{
    size_t total = 0;
    for (int i = 0; i < count; i++)
        total += strlen(texts[i]) + 14;
    uint8_t *buf = malloc(total ? total : 1);
    if (!buf)
        return sl_err_set(err, SL_ERR_NOMEM, "cannot allocate %zu bytes of frames", total);
    size_t n = 0;
    for (int i = 0; i < count; i++)
        n += encode_frame(c, 1, (const uint8_t *)texts[i], strlen(texts[i]), buf + n);
    sl_status st = send_all(c, buf, n, err);
    free(buf);
    return st;
}

sl_status sl_wsclient_send_text(sl_wsclient *c, const char *text, size_t len, sl_err *err)
{
    return sl_wsclient_send_frame(c, 1, (const uint8_t *)text, len, err);
}

int sl_wsclient_timed_out(const sl_wsclient *c)
{
    return c->timed_out;
}

sl_status sl_wsclient_recv(sl_wsclient *c, int timeout_ms, sl_ws_kind *kind, const uint8_t **data,
                           size_t *size, int *close_code, sl_err *err)
{
    double deadline = sl_clock_ms() + timeout_ms;
    c->timed_out = 0;
    c->msg_size = 0;
    int msg_opcode = 0;
    /* The timeout applies to the start of a message only: once its first byte
     * is here, the rest is read under a fixed 10 s deadline, so a short
     * timeout can never leave a frame half-consumed and the stream out of step. */
    sl_status first = fill(c, 1, deadline, err);
    if (first)
        return first;
    deadline = sl_clock_ms() + 10000.0;
    for (;;) {
        uint8_t h[2];
        sl_status st = read_bytes(c, h, 2, deadline, err);
        if (st)
            return st;
        int fin = h[0] & 0x80, opcode = h[0] & 0x0f;
        uint64_t len = h[1] & 0x7f;
        if (h[1] & 0x80)
            return sl_err_set(err, SL_ERR_FORMAT, "server sent a masked frame");
        if (len == 126 || len == 127) {
            uint8_t ext[8];
            int nb = len == 126 ? 2 : 8;
            if ((st = read_bytes(c, ext, (size_t)nb, deadline, err)))
                return st;
            len = 0;
            for (int i = 0; i < nb; i++)
                len = (len << 8) | ext[i];
        }
        if (len > SL_WSCLIENT_MAX_MESSAGE || c->msg_size + len > SL_WSCLIENT_MAX_MESSAGE)
            return sl_err_set(err, SL_ERR_LIMIT, "server message of %llu bytes exceeds the client limit %u",
                              (unsigned long long)len, SL_WSCLIENT_MAX_MESSAGE);
        if (opcode >= 8) { /* control frame: at most 125 bytes */
            uint8_t ctl[128];
            if ((st = read_bytes(c, ctl, (size_t)len, deadline, err)))
                return st;
            if (opcode == 9) {
                if ((st = sl_wsclient_send_frame(c, 10, ctl, (size_t)len, err)))
                    return st;
                continue;
            }
            if (opcode == 8) {
                /* The reason (after the 2-byte code) goes where a message would. */
                size_t reason = len >= 2 ? (size_t)len - 2 : 0;
                if (c->msg_cap < reason + 1) {
                    uint8_t *m = realloc(c->msg, reason + 1);
                    if (!m)
                        return sl_err_set(err, SL_ERR_NOMEM, "cannot allocate a close reason");
                    c->msg = m;
                    c->msg_cap = reason + 1;
                }
                memcpy(c->msg, ctl + 2, reason);
                c->msg[reason] = 0;
                c->msg_size = reason;
                *kind = SL_WS_CLOSED;
                *close_code = len >= 2 ? (ctl[0] << 8 | ctl[1]) : 1005;
                *data = c->msg;
                *size = reason;
                return SL_OK;
            }
            continue; /* pong */
        }
        if (opcode != 0)
            msg_opcode = opcode;
        if (c->msg_size + len + 1 > c->msg_cap) {
            size_t cap = (size_t)(c->msg_size + len + 1);
            uint8_t *m = realloc(c->msg, cap);
            if (!m)
                return sl_err_set(err, SL_ERR_NOMEM, "cannot allocate %zu bytes for a message", cap);
            c->msg = m;
            c->msg_cap = cap;
        }
        if ((st = read_bytes(c, c->msg + c->msg_size, (size_t)len, deadline, err)))
            return st;
        c->msg_size += (size_t)len;
        c->msg[c->msg_size] = 0;
        if (fin) {
            *kind = msg_opcode == 2 ? SL_WS_BINARY : SL_WS_TEXT;
            *data = c->msg;
            *size = c->msg_size;
            *close_code = 0;
            return SL_OK;
        }
    }
}
