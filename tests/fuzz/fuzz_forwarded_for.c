/* fuzz_forwarded_for.c — the X-Forwarded-For walk of sightline-server
 * (server/client_address.c, sl_client_address.h) on arbitrary header values.
 *
 * Input: one byte choosing the trusted prefixes (bit 0: 127.0.0.1, bit 1:
 * 10.0.0.0/8, bit 2: 2001:db8::/32, bit 3: ::ffff:192.168.0.0/112), then the
 * peer up to '\n', then the header (absent when there is no '\n'); NULs end
 * the header as they would a C string. Oracle: an independent statement of the
 * rule (split on ',', trim spaces and tabs, walk from the right through trusted
 * entries, stop at the first untrusted one; an entry that is not a bare address,
 * or more than 64 entries walked, leaves the last hop known) must give the same
 * address and source; the answer is never an entry the walk did not vouch for,
 * and an untrusted peer always gets its own address. Violations abort().
 * Seed corpus: tests/fuzz/corpus/forwarded_for/. Single-threaded; test-only.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl_client_address.h"

#define INPUT_MAX 8192

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int trimmed_addr(const char *s, size_t n, sl_net_addr *out)
{
    while (n > 0 && (*s == ' ' || *s == '\t'))
        s++, n--;
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t'))
        n--;
    char text[SL_CLIENT_ADDRESS_MAX];
    if (n == 0 || n >= sizeof text)
        return 0;
    memcpy(text, s, n);
    text[n] = '\0';
    return sl_net_addr_parse(text, out);
}

static sl_client_address_source oracle(const char *peer, const char *header, const sl_net_prefix *t, int nt,
                                       char *out, size_t size)
{
    sl_net_addr known;
    if (!sl_net_addr_parse(peer, &known)) {
        snprintf(out, size, "%s", peer);
        return header ? SL_CLIENT_ADDRESS_IGNORED : SL_CLIENT_ADDRESS_PEER;
    }
    sl_client_address_source src = SL_CLIENT_ADDRESS_PEER;
    if (!sl_net_prefixes_contain(t, nt, &known)) {
        src = header ? SL_CLIENT_ADDRESS_IGNORED : SL_CLIENT_ADDRESS_PEER;
    } else if (header) {
        /* Split left to right into entries, then walk them from the right. */
        static const char *starts[INPUT_MAX + 1];
        static size_t lens[INPUT_MAX + 1];
        int n = 0;
        const char *p = header;
        for (;;) {
            const char *comma = strchr(p, ',');
            starts[n] = p;
            lens[n] = comma ? (size_t)(comma - p) : strlen(p);
            n++;
            if (!comma)
                break;
            p = comma + 1;
        }
        src = SL_CLIENT_ADDRESS_MALFORMED;
        for (int i = n - 1, walked = 0; i >= 0 && walked < 64; i--, walked++) {
            sl_net_addr e;
            if (!trimmed_addr(starts[i], lens[i], &e))
                break;
            known = e;
            if (!sl_net_prefixes_contain(t, nt, &e) || i == 0) {
                src = SL_CLIENT_ADDRESS_FORWARDED;
                break;
            }
        }
    }
    sl_net_addr_format(&known, out, size);
    return src;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > INPUT_MAX)
        return 0;
    static const char *const sets[] = {"127.0.0.1", "10.0.0.0/8", "2001:db8::/32", "::ffff:192.168.0.0/112"};
    sl_net_prefix t[4];
    int nt = 0;
    for (int i = 0; i < 4; i++)
        if (data[0] & (1u << i)) {
            sl_err err;
            if (sl_net_prefix_parse(sets[i], &t[nt], &err) != SL_OK)
                abort();
            nt++;
        }
    static char buf[INPUT_MAX + 1];
    memcpy(buf, data + 1, size - 1);
    buf[size - 1] = '\0';
    char *nl = memchr(buf, '\n', size - 1);
    const char *header = NULL;
    if (nl) {
        *nl = '\0';
        header = nl + 1;
    }
    char peer[SL_CLIENT_ADDRESS_MAX];
    size_t peer_len = strnlen(buf, sizeof peer - 1);
    memcpy(peer, buf, peer_len);
    peer[peer_len] = '\0';

    char got[SL_CLIENT_ADDRESS_MAX], want[SL_CLIENT_ADDRESS_MAX];
    sl_client_address_source s = sl_client_address_resolve(peer, header, t, nt, got, sizeof got);
    sl_client_address_source w = oracle(peer, header, t, nt, want, sizeof want);
    if (s != w || strcmp(got, want) != 0)
        abort();
    /* An untrusted or unparsable peer gets its own address, whatever the header says. */
    sl_net_addr pa;
    if (!sl_net_addr_parse(peer, &pa) || !sl_net_prefixes_contain(t, nt, &pa)) {
        char own[SL_CLIENT_ADDRESS_MAX];
        if (sl_net_addr_parse(peer, &pa))
            sl_net_addr_format(&pa, own, sizeof own);
        else
            snprintf(own, sizeof own, "%s", peer);
        if (strcmp(got, own) != 0 || s == SL_CLIENT_ADDRESS_FORWARDED || s == SL_CLIENT_ADDRESS_MALFORMED)
            abort();
    }
    /* A malformed walk ends on a trusted hop. */
    sl_net_addr ga;
    if (s == SL_CLIENT_ADDRESS_MALFORMED && (!sl_net_addr_parse(got, &ga) || !sl_net_prefixes_contain(t, nt, &ga)))
        abort();
    /* A tiny output buffer is cut, not overrun. */
    char tiny[5];
    sl_client_address_resolve(peer, header, t, nt, tiny, sizeof tiny);
    if (strlen(tiny) >= sizeof tiny)
        abort();
    return 0;
}
