/* fuzz_http.c — the Host and Origin rules of sightline-server
 * (server/net/http_host.c, sl_http_host.h) on arbitrary header values.
 *
 * libwebsockets parses the request line and headers; what the server adds
 * is the decision on the Host and Origin values, which is what this drives.
 * Input: two bytes of port (little-endian), then '\n'-separated fields:
 * Host, Origin ("-" alone = no Origin header), --bind, then up to 4
 * --allow-origin URLs; each field is cut at 255 bytes (ws.c copies headers
 * into 256-byte buffers) and at a NUL. Oracle: an independent statement of
 * the rules (the exact Host strings that name the server; an allowed
 * origin's authority; "http://" + Host or an allow-listed origin) must give
 * the same answers, an upgrade is never allowed for a refused Host, and
 * without --bind and --allow-origin every allowed Host starts with a
 * loopback name. Violations abort(). Seed corpus: tests/fuzz/corpus/http/.
 * Single-threaded; test-only.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "sl_http_host.h"

#define FIELD_MAX 255
#define ORIGINS_MAX 4

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The Host values that name the server by `name`: "name:port", and "name" on port 80. */
static int names_server(const char *host, const char *name, int port)
{
    char with_port[FIELD_MAX + 32];
    snprintf(with_port, sizeof with_port, "%s:%d", name, port);
    return strcasecmp(host, with_port) == 0 || (port == 80 && strcasecmp(host, name) == 0);
}

static int oracle_host(const char *host, int port, const char *bind, const char *const *origins, int n)
{
    static const char *const loopback[] = {"localhost", "127.0.0.1", "[::1]"};
    for (int i = 0; i < 3; i++)
        if (names_server(host, loopback[i], port))
            return 1;
    if (bind && bind[0]) {
        char name[FIELD_MAX + 3];
        if (strchr(bind, ':'))
            snprintf(name, sizeof name, "[%s]", bind);
        else
            snprintf(name, sizeof name, "%s", bind);
        if (names_server(host, name, port))
            return 1;
    }
    for (int i = 0; i < n; i++) {
        const char *scheme_end = strstr(origins[i], "://");
        if (!scheme_end)
            continue;
        char authority[FIELD_MAX + 1];
        size_t k = 0;
        for (const char *p = scheme_end + 3; *p && *p != '/'; p++)
            authority[k++] = *p;
        authority[k] = '\0';
        if (k > 0 && strcasecmp(host, authority) == 0)
            return 1;
    }
    return 0;
}

static int starts_with_loopback(const char *host)
{
    static const char *const loopback[] = {"localhost", "127.0.0.1", "[::1]"};
    for (int i = 0; i < 3; i++)
        if (strncasecmp(host, loopback[i], strlen(loopback[i])) == 0)
            return 1;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    int port = data[0] | (data[1] << 8);
    char fields[3 + ORIGINS_MAX][FIELD_MAX + 1];
    int count = 0;
    size_t at = 2;
    while (count < 3 + ORIGINS_MAX && at <= size) {
        size_t k = 0;
        while (at < size && data[at] != '\n') {
            if (k < FIELD_MAX && data[at] != '\0')
                fields[count][k++] = (char)data[at];
            at++;
        }
        fields[count++][k] = '\0';
        at++;
    }
    if (count < 1)
        return 0;
    const char *host = fields[0];
    const char *origin = count > 1 && strcmp(fields[1], "-") != 0 ? fields[1] : NULL;
    const char *bind = count > 2 ? fields[2] : NULL;
    const char *origins[ORIGINS_MAX];
    int n = 0;
    for (int i = 3; i < count; i++)
        origins[n++] = fields[i];

    sl_http_site site = {.port = port, .bind = bind, .origins = origins, .origin_count = n};
    int host_ok = sl_http_host_allowed(&site, host);
    if (host_ok != oracle_host(host, port, bind, origins, n))
        abort();
    if (host_ok && (!bind || !bind[0]) && n == 0 && !starts_with_loopback(host))
        abort();
    int upgrade_ok = sl_http_origin_allowed(&site, host, origin);
    int expect = host_ok;
    if (expect && origin) {
        char served[FIELD_MAX + 8];
        snprintf(served, sizeof served, "http://%s", host);
        expect = strcasecmp(origin, served) == 0;
        for (int i = 0; i < n && !expect; i++)
            expect = strcmp(origin, origins[i]) == 0;
    }
    if (upgrade_ok != expect)
        abort();
    if (sl_http_origin_allowed(&site, host, NULL) != host_ok)
        abort();
    return 0;
}
