/* particles_sort.c — radix and bitonic pair sorts and bin start tables on the GPU (particles_sort.h).
 *
 * Radix: LSD, 4-bit digits, per pass a work-group digit histogram (1024 keys
 * per group) → the shared exclusive scan (gpu/sl_gpu_scan.h) of the
 * digit-major histogram → a stable scatter; passes ping-pong between the
 * caller's buffers and two scratch buffers, and an odd pass count ends with
 * one copy back. 4-bit digits because they measured fastest on llvmpipe
 * (60k pairs, key_bits 20, CPU ms): 8-bit digits (3 passes instead of 5, the
 * group ranked by two 4-bit splits in shared memory: 7 barriers per group
 * instead of 2) took 25 ms against 7; 16 keys per invocation instead of 4
 * changed nothing measurable. Bitonic: the pairs are packed as uvec2 into a
 * scratch buffer padded to N = max(1024, 2^ceil(log2 n)) with 0xFFFFFFFF
 * pairs (they sort last and are dropped); one local dispatch sorts every 1024-block in shared
 * memory, then each level k > 1024 is one global compare-exchange dispatch per
 * distance j >= 1024 and one local dispatch fusing j = 512..1. The first local
 * dispatch reads the caller's buffers and the last writes them back.
 * Tables: binary_search = one lower_bound per bin; prefix_sum = zeroed start,
 * one atomicAdd per key < bins, then the in-place exclusive scan of bins + 1
 * entries (start[bins] stays 0 before it, so it ends as the count).
 * Render thread only.
 */
#include "particles_sort.h"

#include <stdlib.h>

#include "../gpu/sl_gpu_scan.h"

#define RADIX_BITS 4u
#define RADIX_DIGITS (1u << RADIX_BITS)
#define RADIX_GROUP_KEYS 1024u
#define BITONIC_BLOCK 1024u
#define LOOKUP_GROUP 256u

/* Explicit uniform locations of particles_sort.comp.glsl / particles_lookup.comp.glsl. */
enum { LOC_GROUP_BASE = 0, LOC_N = 1, LOC_SHIFT_OR_K = 2, LOC_GROUPS_OR_J = 3, LOC_FLAGS = 4 };
enum { LOC_BINS = 2 };
enum { BITONIC_READ_INPUT = 1, BITONIC_WRITE_OUTPUT = 2 };

enum {
    PROGRAM_RADIX_HISTOGRAM,
    PROGRAM_RADIX_SCATTER,
    PROGRAM_BITONIC_LOCAL,
    PROGRAM_BITONIC_GLOBAL,
    PROGRAM_LOOKUP_HISTOGRAM,
    PROGRAM_LOOKUP_SEARCH,
    PROGRAM_COUNT
};

static const struct {
    const char *file, *defines, *label;
} program_specs[PROGRAM_COUNT] = {
    {"particles/particles_sort.comp.glsl", "#define PT_SORT_STAGE 1\n", "pt radix histogram"},
    {"particles/particles_sort.comp.glsl", "#define PT_SORT_STAGE 2\n", "pt radix scatter"},
    {"particles/particles_sort.comp.glsl", "#define PT_SORT_STAGE 3\n", "pt bitonic local"},
    {"particles/particles_sort.comp.glsl", "#define PT_SORT_STAGE 4\n", "pt bitonic global"},
    {"particles/particles_lookup.comp.glsl", "#define PT_LOOKUP_STAGE 1\n", "pt lookup histogram"},
    {"particles/particles_lookup.comp.glsl", "#define PT_LOOKUP_STAGE 2\n", "pt lookup binary search"},
};

/* A scratch SSBO that only grows (immutable storage: a bigger one replaces it). */
typedef struct scratch_buffer {
    GLuint name;
    size_t bytes;
    const char *label;
} scratch_buffer;

struct pt_sorter {
    sl_gpu_scan scan;
    GLuint programs[PROGRAM_COUNT];          /* 0 until first used */
    scratch_buffer radix_keys, radix_values; /* ping-pong partners of the caller's buffers */
    scratch_buffer radix_hist;               /* digit-major counts, then first slots */
    scratch_buffer bitonic_pairs;            /* N uvec2 */
    unsigned max_groups;                     /* per dispatch chunk; 0 = the driver's limit */
};

sl_status pt_sorter_create(pt_sorter **out, sl_err *err)
{
    *out = NULL;
    pt_sorter *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "GPU sorter: out of memory");
    s->radix_keys.label = "pt radix scratch keys";
    s->radix_values.label = "pt radix scratch values";
    s->radix_hist.label = "pt radix histogram";
    s->bitonic_pairs.label = "pt bitonic pairs";
    sl_status st = sl_gpu_scan_init(&s->scan, err);
    if (st != SL_OK) {
        pt_sorter_destroy(s);
        return st;
    }
    *out = s;
    return SL_OK;
}

static void scratch_release(scratch_buffer *b)
{
    if (b->name)
        glDeleteBuffers(1, &b->name);
    b->name = 0;
    b->bytes = 0;
}

void pt_sorter_destroy(pt_sorter *s)
{
    if (!s)
        return;
    sl_gpu_scan_deinit(&s->scan);
    for (int p = 0; p < PROGRAM_COUNT; p++)
        if (s->programs[p])
            glDeleteProgram(s->programs[p]);
    scratch_release(&s->radix_keys);
    scratch_release(&s->radix_values);
    scratch_release(&s->radix_hist);
    scratch_release(&s->bitonic_pairs);
    free(s);
}

void pt_sorter_set_max_groups(pt_sorter *s, unsigned max_groups)
{
    s->max_groups = max_groups;
    s->scan.max_groups = max_groups ? max_groups : sl_gpu_max_groups();
}

/* Makes the program current, compiling it at its first use. */
static sl_status use_program(pt_sorter *s, int which, sl_err *err)
{
    if (!s->programs[which]) {
        sl_status st = sl_gl_program_create(&(sl_program_desc){.compute = program_specs[which].file,
                                                               .defines = program_specs[which].defines,
                                                               .label = program_specs[which].label},
                                            &s->programs[which], err);
        if (st != SL_OK)
            return st;
    }
    glUseProgram(s->programs[which]);
    return SL_OK;
}

/* Grows b to at least `bytes` (rounded up to a power of two, at least 4 KiB). */
static void scratch_reserve(scratch_buffer *b, size_t bytes)
{
    if (b->bytes >= bytes)
        return;
    size_t capacity = 4096;
    while (capacity < bytes)
        capacity *= 2;
    scratch_release(b);
    glCreateBuffers(1, &b->name);
    glNamedBufferStorage(b->name, (GLsizeiptr)capacity, NULL, 0);
    glObjectLabel(GL_BUFFER, b->name, -1, b->label);
    b->bytes = capacity;
}

/* SL_ERR_INVALID unless `buffer` is a buffer of at least `bytes`. */
static sl_status check_buffer(GLuint buffer, size_t bytes, const char *what, sl_err *err)
{
    GLint64 size = 0;
    if (buffer && glIsBuffer(buffer))
        glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &size);
    if (!buffer || size < 0 || (size_t)size < bytes)
        return sl_err_set(err, SL_ERR_INVALID, "GPU sort: the %s buffer (%u) holds %lld bytes, %zu needed", what,
                          (unsigned)buffer, (long long)size, bytes);
    return SL_OK;
}

/* SL_ERR_LIMIT when one shader storage block of `bytes` exceeds the GPU's
 * GL_MAX_SHADER_STORAGE_BLOCK_SIZE (GL guarantees only 16 MiB). */
static sl_status check_block_limit(size_t bytes, const char *what, sl_err *err)
{
    GLint64 limit = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &limit);
    if (limit > 0 && bytes > (size_t)limit)
        return sl_err_set(err, SL_ERR_LIMIT, "%s needs a %zu-byte shader storage block; this GPU allows %lld", what,
                          bytes, (long long)limit);
    return SL_OK;
}

static void dispatch(const pt_sorter *s, size_t groups)
{
    sl_gpu_dispatch_chunked(LOC_GROUP_BASE, groups, s->max_groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

static sl_status radix_sort(pt_sorter *s, GLuint keys, GLuint values, uint32_t n, uint32_t key_bits, sl_err *err)
{
    uint32_t passes = (key_bits + RADIX_BITS - 1) / RADIX_BITS;
    uint32_t groups = (n + RADIX_GROUP_KEYS - 1) / RADIX_GROUP_KEYS;
    sl_status st = use_program(s, PROGRAM_RADIX_HISTOGRAM, err);
    if (st == SL_OK)
        st = use_program(s, PROGRAM_RADIX_SCATTER, err);
    if (st != SL_OK)
        return st;
    scratch_reserve(&s->radix_keys, (size_t)n * 4);
    scratch_reserve(&s->radix_values, (size_t)n * 4);
    scratch_reserve(&s->radix_hist, (size_t)groups * RADIX_DIGITS * 4);
    GLuint src_keys = keys, src_values = values, dst_keys = s->radix_keys.name, dst_values = s->radix_values.name;
    for (uint32_t pass = 0; pass < passes; pass++) {
        GLuint uniforms[4] = {n, pass * RADIX_BITS, groups, 0};
        for (int p = PROGRAM_RADIX_HISTOGRAM; p <= PROGRAM_RADIX_SCATTER; p++) {
            if (p == PROGRAM_RADIX_SCATTER) {
                st = sl_gpu_scan_u32(&s->scan, s->radix_hist.name, s->radix_hist.name, groups * RADIX_DIGITS, err);
                if (st != SL_OK)
                    return st;
            }
            glUseProgram(s->programs[p]);
            glUniform1ui(LOC_N, uniforms[0]);
            glUniform1ui(LOC_SHIFT_OR_K, uniforms[1]);
            glUniform1ui(LOC_GROUPS_OR_J, uniforms[2]);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, src_keys);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, src_values);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, dst_keys);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, dst_values);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s->radix_hist.name);
            dispatch(s, groups);
        }
        GLuint k = src_keys, v = src_values;
        src_keys = dst_keys;
        src_values = dst_values;
        dst_keys = k;
        dst_values = v;
    }
    if (src_keys != keys) { /* odd pass count: the result is in the scratch pair */
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glCopyNamedBufferSubData(src_keys, keys, 0, 0, (GLsizeiptr)n * 4);
        glCopyNamedBufferSubData(src_values, values, 0, 0, (GLsizeiptr)n * 4);
    }
    return SL_OK;
}

/* The bitonic network's size: the power of two >= n, at least one block. */
static uint32_t bitonic_padded(uint32_t n)
{
    uint32_t padded = BITONIC_BLOCK;
    while (padded < n)
        padded *= 2;
    return padded;
}

static void bitonic_local(const pt_sorter *s, size_t blocks, uint32_t k, GLuint flags)
{
    glUseProgram(s->programs[PROGRAM_BITONIC_LOCAL]);
    glUniform1ui(LOC_SHIFT_OR_K, k);
    glUniform1ui(LOC_FLAGS, flags);
    dispatch(s, blocks);
}

static sl_status bitonic_sort(pt_sorter *s, GLuint keys, GLuint values, uint32_t n, sl_err *err)
{
    sl_status st = use_program(s, PROGRAM_BITONIC_LOCAL, err);
    if (st == SL_OK)
        st = use_program(s, PROGRAM_BITONIC_GLOBAL, err);
    if (st != SL_OK)
        return st;
    uint32_t padded = bitonic_padded(n);
    size_t blocks = padded / BITONIC_BLOCK;
    scratch_reserve(&s->bitonic_pairs, (size_t)padded * 8);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, keys);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, values);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, s->bitonic_pairs.name);
    for (int p = PROGRAM_BITONIC_LOCAL; p <= PROGRAM_BITONIC_GLOBAL; p++) {
        glUseProgram(s->programs[p]);
        glUniform1ui(LOC_N, n);
    }
    bitonic_local(s, blocks, 0, BITONIC_READ_INPUT | (padded == BITONIC_BLOCK ? BITONIC_WRITE_OUTPUT : 0));
    for (uint32_t k = 2 * BITONIC_BLOCK; k <= padded; k *= 2) {
        glUseProgram(s->programs[PROGRAM_BITONIC_GLOBAL]);
        glUniform1ui(LOC_SHIFT_OR_K, k);
        for (uint32_t j = k / 2; j >= BITONIC_BLOCK; j /= 2) {
            glUniform1ui(LOC_GROUPS_OR_J, j);
            dispatch(s, blocks); /* padded / 2 pairs, 512 per group */
        }
        bitonic_local(s, blocks, k, k == padded ? BITONIC_WRITE_OUTPUT : 0);
    }
    return SL_OK;
}

sl_status pt_sort_pairs(pt_sorter *s, pt_sort_method m, GLuint keys, GLuint values, uint32_t n, uint32_t key_bits,
                        sl_err *err)
{
    if (key_bits < 1 || key_bits > 32)
        return sl_err_set(err, SL_ERR_INVALID, "GPU sort: key_bits %u outside 1..32", key_bits);
    if (m != PT_SORT_RADIX && m != PT_SORT_BITONIC)
        return sl_err_set(err, SL_ERR_INVALID, "GPU sort: unknown method %d", (int)m);
    if (n > PT_SORT_MAX_PAIRS)
        return sl_err_set(err, SL_ERR_LIMIT, "GPU sort of %u pairs: at most %u are supported", n,
                          PT_SORT_MAX_PAIRS);
    if (n <= 1)
        return SL_OK;
    sl_status st = check_buffer(keys, (size_t)n * 4, "keys", err);
    if (st == SL_OK)
        st = check_buffer(values, (size_t)n * 4, "values", err);
    if (st == SL_OK)
        st = check_block_limit(m == PT_SORT_RADIX ? (size_t)n * 4 : (size_t)bitonic_padded(n) * 8,
                               m == PT_SORT_RADIX ? "GPU radix sort" : "GPU bitonic sort", err);
    if (st == SL_OK)
        st = m == PT_SORT_RADIX ? radix_sort(s, keys, values, n, key_bits, err) : bitonic_sort(s, keys, values, n, err);
    if (st != SL_OK)
        return st;
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    return sl_gl_check_errors(m == PT_SORT_RADIX ? "GPU radix sort" : "GPU bitonic sort", err);
}

sl_status pt_bin_table(pt_sorter *s, pt_lookup_method m, GLuint sorted_keys, uint32_t n, uint32_t bins, GLuint start,
                       sl_err *err)
{
    if (m != PT_LOOKUP_PREFIX_SUM && m != PT_LOOKUP_BINARY_SEARCH)
        return sl_err_set(err, SL_ERR_INVALID, "bin table: unknown method %d", (int)m);
    if (n > PT_SORT_MAX_PAIRS || bins > PT_BINS_MAX)
        return sl_err_set(err, SL_ERR_LIMIT, "bin table of %u keys and %u bins: at most %u keys and %u bins", n,
                          bins, PT_SORT_MAX_PAIRS, PT_BINS_MAX);
    sl_status st = check_buffer(start, ((size_t)bins + 1) * 4, "start", err);
    if (st == SL_OK && n > 0)
        st = check_buffer(sorted_keys, (size_t)n * 4, "sorted keys", err);
    if (st == SL_OK)
        st = check_block_limit(((size_t)bins + 1) * 4, "bin table", err);
    if (st == SL_OK)
        st = use_program(s, m == PT_LOOKUP_PREFIX_SUM ? PROGRAM_LOOKUP_HISTOGRAM : PROGRAM_LOOKUP_SEARCH, err);
    if (st != SL_OK)
        return st;
    glUniform1ui(LOC_N, n);
    glUniform1ui(LOC_BINS, bins);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, n > 0 ? sorted_keys : start); /* unread when n = 0 */
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, start);
    if (m == PT_LOOKUP_PREFIX_SUM) {
        const GLuint zero = 0;
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT); /* the clear comes after any shader write to start */
        glClearNamedBufferSubData(start, GL_R32UI, 0, ((GLsizeiptr)bins + 1) * 4, GL_RED_INTEGER, GL_UNSIGNED_INT,
                                  &zero);
        dispatch(s, ((size_t)n + LOOKUP_GROUP - 1) / LOOKUP_GROUP);
        st = sl_gpu_scan_u32(&s->scan, start, start, bins + 1, err);
        if (st != SL_OK)
            return st;
    } else {
        dispatch(s, ((size_t)bins + 1 + LOOKUP_GROUP - 1) / LOOKUP_GROUP);
    }
    return sl_gl_check_errors(m == PT_LOOKUP_PREFIX_SUM ? "bin table by prefix sum" : "bin table by binary search",
                              err);
}
