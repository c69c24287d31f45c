/* ws_client_address.c — the client address of a WebSocket upgrade, as the
 * admission rules, the logs and /metrics see it: the socket's peer, or when the
 * peer is a --trusted-proxy the X-Forwarded-For entry that proxy vouches for
 * (the walk is sl_client_address.h; this file only reads the header from lws).
 * A header from any other peer is ignored and counted. Service thread, inside
 * the lws callbacks of an upgrade (the request headers are still attached).
 */
#include "sl_net.h"

#include <stdio.h>
#include <stdlib.h>

#include <libwebsockets.h>

void sl_ws_client_address(sl_server *srv, struct lws *wsi, int count, char *out, size_t size)
{
    char peer[SL_CLIENT_ADDRESS_MAX];
    if (!lws_get_peer_simple(wsi, peer, sizeof peer))
        snprintf(peer, sizeof peer, "?");
    /* lws joins repeated header lines with ','; the whole value is bounded by its
     * header buffer, so it is copied whole (room for one separator per line). */
    int total = lws_hdr_total_length(wsi, WSI_TOKEN_X_FORWARDED_FOR);
    char *forwarded = NULL;
    if (total > 0) {
        size_t cap = 2 * (size_t)total + 2;
        forwarded = malloc(cap);
        if (!forwarded || lws_hdr_copy(wsi, forwarded, (int)cap, WSI_TOKEN_X_FORWARDED_FOR) < 0) {
            free(forwarded);
            forwarded = NULL;
            total = -1; /* present but unreadable: walked as a malformed value */
        }
    }
    sl_client_address_source source =
        sl_client_address_resolve(peer, total < 0 ? "" : forwarded, srv->cfg.trusted_proxies,
                                  srv->cfg.trusted_proxy_count, out, size);
    if (count && (source == SL_CLIENT_ADDRESS_IGNORED || source == SL_CLIENT_ADDRESS_MALFORMED)) {
        if (source == SL_CLIENT_ADDRESS_IGNORED)
            lwsl_notice("ignored X-Forwarded-For from %s: not a --trusted-proxy\n", peer);
        else
            lwsl_notice("malformed X-Forwarded-For from trusted proxy %s: client taken as %s\n", peer, out);
        pthread_mutex_lock(&srv->lock);
        if (source == SL_CLIENT_ADDRESS_IGNORED)
            srv->metrics.forwarded_ignored++;
        else
            srv->metrics.forwarded_malformed++;
        pthread_mutex_unlock(&srv->lock);
    } else if (count && source == SL_CLIENT_ADDRESS_FORWARDED) {
        pthread_mutex_lock(&srv->lock);
        srv->metrics.forwarded_clients++;
        pthread_mutex_unlock(&srv->lock);
    }
    free(forwarded);
}
