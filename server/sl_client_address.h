/* sl_client_address.h — the real client address of a connection that may come
 * through a balancer: --trusted-proxy prefixes (ADDR[/BITS], IPv4 and IPv6) and
 * the X-Forwarded-For walk, as pure functions of the peer address and the header.
 *
 * The header is believed only when the peer is a trusted proxy, and then only
 * from the right: each trusted hop vouches for the entry to its left, so the
 * client is the rightmost entry that is not itself a trusted proxy. A client
 * cannot pick its address: what it writes stands left of what the proxy adds.
 * Not here: the PROXY protocol, RFC 7239 `Forwarded`, ports in entries. No lws,
 * no locks, no allocation; any thread (ws_client_address.c reads the header).
 */
#ifndef SL_CLIENT_ADDRESS_H
#define SL_CLIENT_ADDRESS_H

#include <stddef.h>

#include "core/sl_status.h"

#define SL_CLIENT_ADDRESS_MAX 64   /* an address as text, NUL included (INET6_ADDRSTRLEN is 46) */
#define SL_TRUSTED_PROXY_MAX 16    /* --trusted-proxy options */

typedef struct sl_net_addr {
    int family;                    /* AF_INET or AF_INET6 (an IPv4-mapped IPv6 address is AF_INET) */
    unsigned char bytes[16];       /* network order; IPv4 in the first 4 */
} sl_net_addr;

typedef struct sl_net_prefix {
    sl_net_addr addr;              /* host bits are zero */
    int bits;                      /* 0..32 (IPv4) or 0..128 (IPv6) */
} sl_net_prefix;

/* How sl_client_address_resolve chose. */
typedef enum sl_client_address_source {
    SL_CLIENT_ADDRESS_PEER = 0,    /* the socket's peer: untrusted, or trusted and sent no header */
    SL_CLIENT_ADDRESS_FORWARDED,   /* an X-Forwarded-For entry vouched for by trusted hops */
    SL_CLIENT_ADDRESS_IGNORED,     /* the peer is not trusted and sent a header: the peer, header ignored */
    SL_CLIENT_ADDRESS_MALFORMED    /* a vouched-for entry is not an address: the last hop known, the peer
                                      or a trusted proxy (so never an address the sender chose) */
} sl_client_address_source;

/* 1 when text (exactly, no spaces) is an IPv4 or IPv6 address, filling *out;
 * 0 otherwise (*out untouched). "::ffff:a.b.c.d" becomes the IPv4 address. */
int sl_net_addr_parse(const char *text, sl_net_addr *out);

/* The canonical text of a (inet_ntop: "10.0.0.1", "2001:db8::1") in out
 * (at least SL_CLIENT_ADDRESS_MAX bytes). */
void sl_net_addr_format(const sl_net_addr *a, char *out, size_t size);

/* Parses "ADDR" or "ADDR/BITS" (a --trusted-proxy value). Returns SL_OK, or
 * SL_ERR_INVALID naming the value and the rule (not an address, BITS not a
 * number in 0..32 / 0..128, host bits set: "10.0.0.1/8" is refused so a typo
 * does not trust a whole network silently); *out is untouched on failure. */
sl_status sl_net_prefix_parse(const char *text, sl_net_prefix *out, sl_err *err);

/* 1 when a lies in p (same family, the first p->bits bits equal). */
int sl_net_prefix_contains(const sl_net_prefix *p, const sl_net_addr *a);

/* 1 when a lies in any of the n prefixes. */
int sl_net_prefixes_contain(const sl_net_prefix *prefixes, int n, const sl_net_addr *a);

/* The client address of a connection from peer (its socket's numeric address)
 * carrying forwarded_for (the X-Forwarded-For value, lines joined by ','; NULL
 * when absent), canonical text in out (SL_CLIENT_ADDRESS_MAX bytes). Entries are
 * separated by ',' with optional spaces or tabs; an empty entry, anything but a
 * bare address, or a value of more than 64 entries to walk is malformed. A peer
 * that does not parse is copied as it is (cut to size) and treated as untrusted. */
sl_client_address_source sl_client_address_resolve(const char *peer, const char *forwarded_for,
                                                   const sl_net_prefix *trusted, int trusted_count, char *out,
                                                   size_t size);

#endif
