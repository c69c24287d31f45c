/* sl_hash.h — FNV-1a, 64 bit: a fast, non-cryptographic hash for cache keys and
 * file checksums (scene keys of the server's adaptive scale, the particles' volume
 * cache, the catalog's file checksums). Not for anything an attacker may choose to
 * collide (tokens use SHA-256). Pure, any thread.
 */
#ifndef SL_HASH_H
#define SL_HASH_H

#include <stddef.h>
#include <stdint.h>

#define SL_FNV1A_SEED 0xcbf29ce484222325ull /* the offset basis: start a hash with it */

/* Folds n bytes at data into h. */
static inline uint64_t sl_fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

#endif
