/* particles_cache.c — finished particle sets across prepares (particles_cache.h). */
#include "particles_cache.h"

#include <stdlib.h>
#include <string.h>

#include "../core/sl_hash.h"
#include "../gpu/sl_gpu.h"

typedef struct cache_entry {
    int used;
    uint64_t volume_hash;
    pt_system_desc desc;
    pt_set shape;                /* everything but the GL names */
    void *records, *table;       /* CPU copies */
    size_t record_bytes, table_bytes;
    uint64_t last_use;
} cache_entry;

static cache_entry entries[PT_CACHE_ENTRIES];
static uint64_t use_clock, hit_count, store_count;

uint64_t pt_cache_volume_hash(const sl_volume *vol)
{
    uint64_t h = SL_FNV1A_SEED;
    h = sl_fnv1a(h, vol->dims, sizeof vol->dims);
    h = sl_fnv1a(h, vol->spacing, sizeof vol->spacing);
    h = sl_fnv1a(h, &vol->type, sizeof vol->type);
    h = sl_fnv1a(h, &vol->components, sizeof vol->components);
    size_t voxels = (size_t)vol->dims[0] * vol->dims[1] * vol->dims[2] * (size_t)vol->components;
    return sl_fnv1a(h, vol->data, voxels * sl_voxel_type_size(vol->type));
}

static int same_desc(const pt_system_desc *a, const pt_system_desc *b)
{
    return a->iso == b->iso && a->lattice_step == b->lattice_step && a->sigma == b->sigma &&
           a->energy_tol == b->energy_tol && a->max_steps == b->max_steps && a->sort == b->sort &&
           a->lookup == b->lookup && a->max_particles == b->max_particles;
}

static void drop(cache_entry *e)
{
    free(e->records);
    free(e->table);
    memset(e, 0, sizeof *e);
}

static size_t cached_bytes(void)
{
    size_t total = 0;
    for (int i = 0; i < PT_CACHE_ENTRIES; i++)
        if (entries[i].used)
            total += entries[i].record_bytes + entries[i].table_bytes;
    return total;
}

static GLuint upload(const void *data, size_t bytes)
{
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(bytes ? bytes : 16), bytes ? data : NULL, GL_DYNAMIC_STORAGE_BIT);
    return b;
}

int pt_cache_lookup(uint64_t volume_hash, const pt_system_desc *d, pt_set *out, sl_err *err)
{
    for (int i = 0; i < PT_CACHE_ENTRIES; i++) {
        cache_entry *e = &entries[i];
        if (!e->used || e->volume_hash != volume_hash || !same_desc(&e->desc, d))
            continue;
        pt_set s = e->shape;
        s.records = upload(e->records, e->record_bytes);
        s.table = upload(e->table, e->table_bytes);
        if (sl_gl_check_errors("particles: a cached set", err) != SL_OK) {
            pt_set_release(&s);
            return -1;
        }
        e->last_use = ++use_clock;
        hit_count++;
        *out = s;
        return 1;
    }
    return 0;
}

void pt_cache_store(uint64_t volume_hash, const pt_system_desc *d, const pt_set *set)
{
    size_t record_bytes = (size_t)set->count * sizeof(pt_record), table_bytes = ((size_t)set->bins + 1) * 4;
    if (record_bytes + table_bytes > PT_CACHE_BYTES / 2)
        return;
    cache_entry fresh = {.used = 1, .volume_hash = volume_hash, .desc = *d, .shape = *set,
                         .record_bytes = record_bytes, .table_bytes = table_bytes};
    fresh.shape.records = fresh.shape.table = 0;
    fresh.records = malloc(record_bytes ? record_bytes : 1);
    fresh.table = malloc(table_bytes);
    if (!fresh.records || !fresh.table) {
        drop(&fresh);
        return;
    }
    if (record_bytes)
        glGetNamedBufferSubData(set->records, 0, (GLsizeiptr)record_bytes, fresh.records);
    glGetNamedBufferSubData(set->table, 0, (GLsizeiptr)table_bytes, fresh.table);
    /* Room: the least recently used entries go until it fits. */
    for (;;) {
        int free_slot = -1, oldest = -1;
        for (int i = 0; i < PT_CACHE_ENTRIES; i++) {
            if (!entries[i].used)
                free_slot = free_slot < 0 ? i : free_slot;
            else if (oldest < 0 || entries[i].last_use < entries[oldest].last_use)
                oldest = i;
        }
        if (free_slot >= 0 && cached_bytes() + record_bytes + table_bytes <= PT_CACHE_BYTES) {
            fresh.last_use = ++use_clock;
            entries[free_slot] = fresh;
            store_count++;
            return;
        }
        drop(&entries[oldest]);
    }
}

void pt_cache_clear(void)
{
    for (int i = 0; i < PT_CACHE_ENTRIES; i++)
        if (entries[i].used)
            drop(&entries[i]);
}

void pt_cache_counts(uint64_t *hits, uint64_t *stores)
{
    *hits = hit_count;
    *stores = store_count;
}
