/* random_hex.c — sl_random_hex (sl_sessions.h): random lowercase hex for session ids, tokens and
 * recording keys. Any thread. */
#include "sl_sessions.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/random.h>

void sl_random_hex(char *out, int bytes)
{
    unsigned char buf[32];
    if (getrandom(buf, (size_t)bytes, 0) != bytes) {
        /* getrandom on Linux does not fail for <= 256 bytes once seeded; mix the clock in as a fallback. */
        double t = sl_clock_ms();
        for (int i = 0; i < bytes; i++)
            buf[i] = (unsigned char)((long long)(t * 1000.0) >> (i % 8) ^ (unsigned)rand());
    }
    for (int i = 0; i < bytes; i++)
        snprintf(out + 2 * i, 3, "%02x", buf[i]);
}
