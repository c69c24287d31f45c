/* particles_cache.h — finished particle sets kept across prepares, so a new
 * set of isovalues recomputes only the sets that changed (adding a second
 * surface does not redistribute the first one again).
 *
 * An entry is a CPU copy of one set's records, bin table and statistics,
 * keyed by the volume's content (a 64-bit FNV-1a hash of its voxel bytes,
 * dimensions, spacing and type) and every system parameter that changes the
 * particles (pt_system_desc). At most PT_CACHE_ENTRIES entries and
 * PT_CACHE_BYTES bytes, least recently used first out. Module-level state:
 * render thread only (every prepare runs there).
 */
#ifndef PARTICLES_CACHE_H
#define PARTICLES_CACHE_H

#include <stdint.h>

#include "../core/sl_status.h"
#include "../data/sl_dataset.h"
#include "particles_system.h"

#define PT_CACHE_ENTRIES 8
#define PT_CACHE_BYTES ((size_t)256 << 20)

/* The content hash of a volume (voxels, dims, spacing, type). */
uint64_t pt_cache_volume_hash(const sl_volume *vol);

/* On a hit, *out is a set rebuilt on the GPU from the copy (returns 1); on a
 * miss 0 and *out untouched; on a GPU error -1 with err filled. */
int pt_cache_lookup(uint64_t volume_hash, const pt_system_desc *d, pt_set *out, sl_err *err);
/* Keeps a copy of a finished set (read back from the GPU). A set too large
 * for the cache is not kept; out of memory just skips it. */
void pt_cache_store(uint64_t volume_hash, const pt_system_desc *d, const pt_set *set);
/* Forgets everything (tests). */
void pt_cache_clear(void);
/* Hits and stores since start (tests and stats). */
void pt_cache_counts(uint64_t *hits, uint64_t *stores);

#endif
