/* client_address.c — trusted-proxy prefixes and the X-Forwarded-For walk (see
 * sl_client_address.h). Pure: addresses parsed with inet_pton, compared as bytes;
 * the header is read right to left, at most SL_FORWARDED_HOPS entries, each cut
 * out into a bounded buffer, so a hostile header costs one pass and no memory.
 * Any thread.
 */
#include "sl_client_address.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#define SL_FORWARDED_HOPS 64   /* entries walked at most (a chain of trusted proxies is short) */

int sl_net_addr_parse(const char *text, sl_net_addr *out)
{
    if (!text)
        return 0;
    unsigned char buf[16];
    if (inet_pton(AF_INET, text, buf) == 1) {
        memset(out, 0, sizeof *out);
        out->family = AF_INET;
        memcpy(out->bytes, buf, 4);
        return 1;
    }
    if (inet_pton(AF_INET6, text, buf) == 1) {
        static const unsigned char mapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
        memset(out, 0, sizeof *out);
        if (memcmp(buf, mapped, sizeof mapped) == 0) {
            out->family = AF_INET;
            memcpy(out->bytes, buf + 12, 4);
        } else {
            out->family = AF_INET6;
            memcpy(out->bytes, buf, 16);
        }
        return 1;
    }
    return 0;
}

void sl_net_addr_format(const sl_net_addr *a, char *out, size_t size)
{
    char text[INET6_ADDRSTRLEN];
    if (!inet_ntop(a->family, a->bytes, text, sizeof text))
        snprintf(text, sizeof text, "?");
    snprintf(out, size, "%s", text);
}

sl_status sl_net_prefix_parse(const char *text, sl_net_prefix *out, sl_err *err)
{
    char addr_text[SL_CLIENT_ADDRESS_MAX];
    const char *slash = text ? strchr(text, '/') : NULL;
    size_t addr_len = text ? (slash ? (size_t)(slash - text) : strlen(text)) : 0;
    if (!text || addr_len == 0 || addr_len >= sizeof addr_text)
        return sl_err_set(err, SL_ERR_INVALID, "--trusted-proxy \"%s\": expected ADDR or ADDR/BITS (IPv4 or IPv6)",
                          text ? text : "");
    memcpy(addr_text, text, addr_len);
    addr_text[addr_len] = '\0';
    sl_net_prefix p = {0};
    if (!sl_net_addr_parse(addr_text, &p.addr))
        return sl_err_set(err, SL_ERR_INVALID, "--trusted-proxy \"%s\": \"%s\" is not an IPv4 or IPv6 address", text,
                          addr_text);
    /* An IPv4-mapped IPv6 prefix ("::ffff:10.0.0.0/104") counts its bits in IPv6. */
    int mapped = p.addr.family == AF_INET && strchr(addr_text, ':') != NULL;
    int max_bits = p.addr.family == AF_INET ? 32 : 128;
    p.bits = max_bits;
    if (slash) {
        const char *b = slash + 1;
        char *end = NULL;
        long bits = strtol(b, &end, 10);
        long lo = mapped ? 96 : 0, hi = mapped ? 128 : max_bits;
        if (b[0] < '0' || b[0] > '9' || *end != '\0' || bits < lo || bits > hi)
            return sl_err_set(err, SL_ERR_INVALID, "--trusted-proxy \"%s\": BITS must be a number in %ld..%ld", text,
                              lo, hi);
        p.bits = (int)(mapped ? bits - 96 : bits);
    }
    for (int i = p.bits; i < max_bits; i++)
        if (p.addr.bytes[i / 8] & (0x80u >> (i % 8)))
            return sl_err_set(err, SL_ERR_INVALID,
                              "--trusted-proxy \"%s\": bits beyond /%d are set (write the network address)", text,
                              p.bits);
    *out = p;
    return SL_OK;
}

int sl_net_prefix_contains(const sl_net_prefix *p, const sl_net_addr *a)
{
    if (p->addr.family != a->family)
        return 0;
    int full = p->bits / 8, rest = p->bits % 8;
    if (memcmp(p->addr.bytes, a->bytes, (size_t)full) != 0)
        return 0;
    if (rest == 0)
        return 1;
    unsigned mask = (0xffu << (8 - rest)) & 0xffu;
    return (p->addr.bytes[full] & mask) == (a->bytes[full] & mask);
}

int sl_net_prefixes_contain(const sl_net_prefix *prefixes, int n, const sl_net_addr *a)
{
    for (int i = 0; i < n; i++)
        if (sl_net_prefix_contains(&prefixes[i], a))
            return 1;
    return 0;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t';
}

/* The entry of header[start, end) without its surrounding spaces, parsed; 0 when
 * it is empty, too long or not a bare address. */
static int parse_entry(const char *header, size_t start, size_t end, sl_net_addr *out)
{
    while (start < end && is_space(header[start]))
        start++;
    while (end > start && is_space(header[end - 1]))
        end--;
    char text[SL_CLIENT_ADDRESS_MAX];
    if (end == start || end - start >= sizeof text)
        return 0;
    memcpy(text, header + start, end - start);
    text[end - start] = '\0';
    return sl_net_addr_parse(text, out);
}

sl_client_address_source sl_client_address_resolve(const char *peer, const char *forwarded_for,
                                                   const sl_net_prefix *trusted, int trusted_count, char *out,
                                                   size_t size)
{
    sl_net_addr known;
    if (!sl_net_addr_parse(peer, &known)) {
        snprintf(out, size, "%s", peer ? peer : "?");
        return forwarded_for ? SL_CLIENT_ADDRESS_IGNORED : SL_CLIENT_ADDRESS_PEER;
    }
    sl_client_address_source source = SL_CLIENT_ADDRESS_PEER;
    if (!sl_net_prefixes_contain(trusted, trusted_count, &known)) {
        source = forwarded_for ? SL_CLIENT_ADDRESS_IGNORED : SL_CLIENT_ADDRESS_PEER;
    } else if (forwarded_for) {
        /* known is a trusted hop; the entry left of it is what that hop saw. */
        size_t end = strlen(forwarded_for);
        source = SL_CLIENT_ADDRESS_MALFORMED;
        for (int hop = 0; hop < SL_FORWARDED_HOPS; hop++) {
            size_t start = end;
            while (start > 0 && forwarded_for[start - 1] != ',')
                start--;
            sl_net_addr entry;
            if (!parse_entry(forwarded_for, start, end, &entry))
                break;
            known = entry;
            if (!sl_net_prefixes_contain(trusted, trusted_count, &known) || start == 0) {
                source = SL_CLIENT_ADDRESS_FORWARDED;
                break;
            }
            end = start - 1; /* before the ',' */
        }
    }
    sl_net_addr_format(&known, out, size);
    return source;
}
