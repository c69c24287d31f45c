/* http_host.c — the Host and Origin rules of sightline-server (see sl_http_host.h).
 * Pure string checks on header values; ws.c reads the headers and acts on
 * the answer. Any thread.
 */
#include "sl_http_host.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

/* 1 when host is "name:port" (or "name" with port 80) for the listening port. */
static int host_is(const char *host, const char *name, int port)
{
    size_t n = strlen(name);
    if (strncasecmp(host, name, n) != 0)
        return 0;
    if (host[n] == '\0')
        return port == 80;
    char want[16];
    snprintf(want, sizeof want, ":%d", port);
    return strcmp(host + n, want) == 0;
}

/* The authority ("host[:port]") of an allow-listed origin URL such as
 * "https://viz.example.org" or "http://10.0.0.5:8080". */
static int host_of_origin(const char *host, const char *origin)
{
    const char *p = strstr(origin, "://");
    if (!p)
        return 0;
    p += 3;
    size_t n = strcspn(p, "/");
    return n > 0 && strlen(host) == n && strncasecmp(host, p, n) == 0;
}

int sl_http_host_allowed(const sl_http_site *site, const char *host)
{
    static const char *const local[] = {"localhost", "127.0.0.1", "[::1]"};
    if (!host)
        return 0;
    for (size_t i = 0; i < sizeof local / sizeof local[0]; i++)
        if (host_is(host, local[i], site->port))
            return 1;
    const char *bind = site->bind;
    if (bind && bind[0]) {
        char name[300];
        snprintf(name, sizeof name, strchr(bind, ':') ? "[%s]" : "%s", bind);
        if (host_is(host, name, site->port))
            return 1;
    }
    for (int i = 0; i < site->origin_count; i++)
        if (host_of_origin(host, site->origins[i]))
            return 1;
    return 0;
}

int sl_http_origin_allowed(const sl_http_site *site, const char *host, const char *origin)
{
    if (!sl_http_host_allowed(site, host))
        return 0;
    if (!origin)
        return 1;
    char served[300];
    snprintf(served, sizeof served, "http://%s", host);
    if (strcasecmp(origin, served) == 0)
        return 1;
    for (int i = 0; i < site->origin_count; i++)
        if (strcmp(origin, site->origins[i]) == 0)
            return 1;
    return 0;
}
