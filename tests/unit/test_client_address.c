/* test_client_address.c — server/client_address.c: --trusted-proxy prefixes
 * (IPv4, IPv6, bits, host bits, garbage), prefix matching at byte and bit
 * boundaries, IPv4-mapped peers, and the X-Forwarded-For walk on honest and
 * hostile headers (forged entries left of the proxy's, chains of trusted
 * proxies, spaces, IPv6, garbage, empty entries, long lists, untrusted peers).
 */
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>

#include "sl_client_address.h"
#include "sl_test.h"

static sl_net_prefix prefix(const char *text)
{
    sl_net_prefix p = {0};
    sl_err err = {0};
    if (sl_net_prefix_parse(text, &p, &err) != SL_OK)
        fprintf(stderr, "prefix %s: %s\n", text, err.message);
    return p;
}

static int contains(const char *prefix_text, const char *addr_text)
{
    sl_net_prefix p = prefix(prefix_text);
    sl_net_addr a;
    return sl_net_addr_parse(addr_text, &a) && sl_net_prefix_contains(&p, &a);
}

static int refused(const char *text, const char *says)
{
    sl_net_prefix p = {.bits = 77};
    sl_err err = {0};
    int r = sl_net_prefix_parse(text, &p, &err) == SL_ERR_INVALID && strstr(err.message, says) != NULL &&
            p.bits == 77;
    if (!r)
        fprintf(stderr, "prefix \"%s\": \"%s\"\n", text, err.message);
    return r;
}

/* The address resolved for peer + header with trusted = the given prefixes; source in *src. */
static const char *resolve(const char *peer, const char *header, const char *const *trusted, int n,
                           sl_client_address_source *src)
{
    static char out[SL_CLIENT_ADDRESS_MAX];
    sl_net_prefix t[SL_TRUSTED_PROXY_MAX];
    for (int i = 0; i < n; i++)
        t[i] = prefix(trusted[i]);
    *src = sl_client_address_resolve(peer, header, t, n, out, sizeof out);
    return out;
}

#define RESOLVES(peer, header, trusted, want, want_src)                                                      \
    do {                                                                                                     \
        sl_client_address_source s_;                                                                         \
        const char *h_ = (header);                                                                           \
        const char *got_ = resolve(peer, h_, trusted, (int)(sizeof trusted / sizeof trusted[0]), &s_);       \
        SL_CHECK_MSG(strcmp(got_, want) == 0 && s_ == want_src, "peer %s header \"%.80s\": %s (source %d), not %s (%d)", \
                     peer, h_ ? h_ : "(none)", got_, (int)s_, want, (int)want_src);                  \
    } while (0)

int main(void)
{
    /* Parsing prefixes. */
    sl_net_prefix p = prefix("127.0.0.1");
    SL_CHECK(p.addr.family == AF_INET && p.bits == 32);
    p = prefix("10.0.0.0/8");
    SL_CHECK(p.bits == 8 && p.addr.bytes[0] == 10);
    p = prefix("2001:db8::/32");
    SL_CHECK(p.addr.family == AF_INET6 && p.bits == 32);
    p = prefix("::1");
    SL_CHECK(p.addr.family == AF_INET6 && p.bits == 128);
    p = prefix("0.0.0.0/0");
    SL_CHECK(p.bits == 0);
    SL_CHECK(refused("", "expected ADDR"));
    SL_CHECK(refused("/8", "expected ADDR"));
    SL_CHECK(refused("localhost", "not an IPv4 or IPv6 address"));
    SL_CHECK(refused("10.0.0", "not an IPv4 or IPv6 address"));
    SL_CHECK(refused(" 10.0.0.1", "not an IPv4 or IPv6 address"));
    SL_CHECK(refused("10.0.0.1/33", "0..32"));
    SL_CHECK(refused("::/129", "0..128"));
    SL_CHECK(refused("10.0.0.0/", "0..32"));
    SL_CHECK(refused("10.0.0.0/8x", "0..32"));
    SL_CHECK(refused("10.0.0.0/-1", "0..32"));
    SL_CHECK(refused("10.0.0.0/+8", "0..32"));
    SL_CHECK(refused("10.0.0.0/99999999999999999999", "0..32"));
    SL_CHECK(refused("10.0.0.1/8", "bits beyond /8"));
    SL_CHECK(refused("2001:db8::1/64", "bits beyond /64"));
    SL_CHECK(refused("1111:2222:3333:4444:5555:6666:7777:8888:9999/64", "not an IPv4 or IPv6 address"));
    SL_CHECK(sl_net_prefix_parse(NULL, &p, NULL) == SL_ERR_INVALID);

    /* Matching at byte and bit boundaries, both families, and mapped IPv4. */
    SL_CHECK(contains("127.0.0.1", "127.0.0.1"));
    SL_CHECK(!contains("127.0.0.1", "127.0.0.2"));
    SL_CHECK(contains("10.0.0.0/8", "10.255.1.2"));
    SL_CHECK(!contains("10.0.0.0/8", "11.0.0.0"));
    SL_CHECK(contains("192.168.4.0/22", "192.168.7.255"));
    SL_CHECK(!contains("192.168.4.0/22", "192.168.8.0"));
    SL_CHECK(!contains("192.168.4.0/22", "192.168.3.255"));
    SL_CHECK(contains("0.0.0.0/0", "203.0.113.9"));
    SL_CHECK(!contains("0.0.0.0/0", "::1"));
    SL_CHECK(contains("2001:db8::/32", "2001:db8:ffff::1"));
    SL_CHECK(!contains("2001:db8::/32", "2001:db9::1"));
    SL_CHECK(contains("fe80::/10", "febf::1"));
    SL_CHECK(!contains("fe80::/10", "fec0::1"));
    SL_CHECK(contains("127.0.0.1", "::ffff:127.0.0.1"));
    /* An IPv4-mapped prefix is the IPv4 network, its bits counted in IPv6. */
    SL_CHECK(contains("::ffff:10.0.0.0/104", "10.1.2.3"));
    SL_CHECK(contains("::ffff:10.0.0.0/104", "::ffff:10.1.2.3"));
    SL_CHECK(!contains("::ffff:10.0.0.0/104", "11.0.0.1"));
    SL_CHECK(contains("::ffff:0:0/96", "192.0.2.1"));
    SL_CHECK(refused("::ffff:0:0/95", "96..128"));
    sl_net_addr a;
    SL_CHECK(!sl_net_addr_parse("127.0.0.1 ", &a));
    SL_CHECK(!sl_net_addr_parse("[::1]", &a));
    SL_CHECK(!sl_net_addr_parse("1.2.3.4:80", &a));
    SL_CHECK(!sl_net_addr_parse(NULL, &a));
    char text[SL_CLIENT_ADDRESS_MAX];
    SL_CHECK(sl_net_addr_parse("2001:DB8:0:0::1", &a));
    sl_net_addr_format(&a, text, sizeof text);
    SL_CHECK_MSG(strcmp(text, "2001:db8::1") == 0, "canonical %s", text);

    /* The walk. */
    const char *const lo[] = {"127.0.0.1"};
    const char *const chain[] = {"127.0.0.1", "10.0.0.0/8"};
    const char *const v6[] = {"2001:db8::/48"};
    /* Behind the balancer: the entry it adds names the client. */
    RESOLVES("127.0.0.1", "203.0.113.7", lo, "203.0.113.7", SL_CLIENT_ADDRESS_FORWARDED);
    /* ...also through a dual-stack listener's mapped peer, and with spaces and tabs. */
    RESOLVES("::ffff:127.0.0.1", " \t203.0.113.7 ", lo, "203.0.113.7", SL_CLIENT_ADDRESS_FORWARDED);
    /* A client's forged entries stand left of the balancer's and change nothing. */
    RESOLVES("127.0.0.1", "1.1.1.1, 2.2.2.2,203.0.113.7", lo, "203.0.113.7", SL_CLIENT_ADDRESS_FORWARDED);
    /* A forged entry naming a trusted proxy does not make the balancer's entry trusted. */
    RESOLVES("127.0.0.1", "127.0.0.1, 203.0.113.7", lo, "203.0.113.7", SL_CLIENT_ADDRESS_FORWARDED);
    /* A chain of trusted proxies is walked to the first untrusted entry. */
    RESOLVES("127.0.0.1", "9.9.9.9, 198.51.100.4, 10.1.2.3, 10.4.5.6", chain, "198.51.100.4",
             SL_CLIENT_ADDRESS_FORWARDED);
    /* Every entry trusted: the leftmost is the client (a user on the balancer's machine). */
    RESOLVES("127.0.0.1", "10.0.0.9,127.0.0.1", chain, "10.0.0.9", SL_CLIENT_ADDRESS_FORWARDED);
    /* IPv6 clients and proxies; entries come out canonical. */
    RESOLVES("2001:db8::5", "2001:DB8:1::0:7", v6, "2001:db8:1::7", SL_CLIENT_ADDRESS_FORWARDED);
    RESOLVES("2001:db8::5", "2001:db9::7, 2001:db8:0:1::2", v6, "2001:db9::7", SL_CLIENT_ADDRESS_FORWARDED);
    RESOLVES("127.0.0.1", "::ffff:203.0.113.7", lo, "203.0.113.7", SL_CLIENT_ADDRESS_FORWARDED);
    /* No header from the balancer (its own health checks): the peer. */
    RESOLVES("127.0.0.1", NULL, lo, "127.0.0.1", SL_CLIENT_ADDRESS_PEER);
    /* From anyone else the header is ignored. */
    RESOLVES("127.0.0.2", "203.0.113.7", lo, "127.0.0.2", SL_CLIENT_ADDRESS_IGNORED);
    RESOLVES("127.0.0.2", NULL, lo, "127.0.0.2", SL_CLIENT_ADDRESS_PEER);
    RESOLVES("2001:db9::1", "2001:db8::1", v6, "2001:db9::1", SL_CLIENT_ADDRESS_IGNORED);
    /* Garbage where a trusted hop vouches: the last hop known, never the garbage or what lies left of it. */
    RESOLVES("127.0.0.1", "", lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "   ", lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "203.0.113.7,", lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "unknown", lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "203.0.113.7:4711", lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "[2001:db8::1]", lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "203.0.113.7 198.51.100.1", lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "1.2.3.4, garbage, 10.0.0.3", chain, "10.0.0.3", SL_CLIENT_ADDRESS_MALFORMED);
    RESOLVES("127.0.0.1", "203.0.113.7,,10.0.0.3", chain, "10.0.0.3", SL_CLIENT_ADDRESS_MALFORMED);
    /* An untrusted entry stops the walk before garbage further left is read. */
    RESOLVES("127.0.0.1", "garbage, 203.0.113.7", lo, "203.0.113.7", SL_CLIENT_ADDRESS_FORWARDED);
    /* A peer that is not an address (lws gave none) is kept as it is and trusted for nothing. */
    RESOLVES("?", "203.0.113.7", lo, "?", SL_CLIENT_ADDRESS_IGNORED);
    /* No trusted proxies at all: the header never counts. */
    {
        sl_client_address_source s;
        char out[SL_CLIENT_ADDRESS_MAX];
        s = sl_client_address_resolve("127.0.0.1", "203.0.113.7", NULL, 0, out, sizeof out);
        SL_CHECK(s == SL_CLIENT_ADDRESS_IGNORED && strcmp(out, "127.0.0.1") == 0);
    }

    /* Long lists: an overlong entry is malformed; a long chain of trusted entries is walked
     * at most 64 hops and then ends on a trusted hop, never on what the sender wrote further left. */
    {
        static char header[64 * 1024];
        size_t n = 0;
        n += (size_t)snprintf(header + n, sizeof header - n, "1.2.3.4");
        for (int i = 0; i < 1000; i++)
            n += (size_t)snprintf(header + n, sizeof header - n, ", 10.0.%d.%d", i / 250, i % 250);
        RESOLVES("127.0.0.1", header, chain, "10.0.3.186", SL_CLIENT_ADDRESS_MALFORMED);
        memset(header, '1', 5000);
        header[5000] = '\0';
        RESOLVES("127.0.0.1", header, lo, "127.0.0.1", SL_CLIENT_ADDRESS_MALFORMED);
        /* 1000 forged entries left of the balancer's are never walked. */
        n = 0;
        for (int i = 0; i < 1000; i++)
            n += (size_t)snprintf(header + n, sizeof header - n, "6.6.%d.%d, ", i / 250, i % 250);
        snprintf(header + n, sizeof header - n, "203.0.113.7");
        RESOLVES("127.0.0.1", header, lo, "203.0.113.7", SL_CLIENT_ADDRESS_FORWARDED);
    }

    /* A small output buffer is cut, never overrun. */
    {
        char small[8];
        sl_net_prefix t = prefix("127.0.0.1");
        sl_client_address_resolve("127.0.0.1", "203.0.113.7", &t, 1, small, sizeof small);
        SL_CHECK_MSG(strcmp(small, "203.0.1") == 0, "cut to %s", small);
    }
    SL_TEST_END();
}
