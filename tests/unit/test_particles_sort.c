/* test_particles_sort.c — the GPU pair sorts and bin tables of renderer/particles/particles_sort.h
 * against CPU references written here, and the shared GPU scan (gpu/sl_gpu_scan.h) they build on.
 *
 * Sorts: n in {0, 1, 2, 255, 256, 257, 1023, 1025, 65535, 65537, 200000},
 * keys random in [0, 2^b) for b in {1, 8, 20, 23, 32} and all equal, values 0..n-1:
 * radix and bitonic must both equal the CPU stable sort word for word (so
 * radix is stable and bitonic orders by (key, value)). Tables: keys with
 * ~1/8 sentinels >= bins, GPU-sorted, for bins in {1, 1000, 2^20}: both
 * methods equal the CPU lower_bound table, empty bins included. A second
 * round runs with 3 work groups per dispatch chunk, so the chunking is
 * exercised too; errors (bad key_bits, limits, small buffers) are refused.
 * `--time` instead prints the Release timing table of particles_sort.h
 * (median of 5, wall time to glFinish). Needs OpenGL 4.5 (llvmpipe is fine).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/sl_clock.h"
#include "gpu/sl_gpu.h"
#include "gpu/sl_gpu_scan.h"
#include "particles/particles_sort.h"
#include "sl_test.h"

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

static uint32_t next_random(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 16);
}

static GLuint buffer_with(const uint32_t *data, size_t count)
{
    GLuint b;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(count ? count * 4 : 4), data, GL_DYNAMIC_STORAGE_BIT);
    return b;
}

static void read_buffer(GLuint b, uint32_t *out, size_t count)
{
    if (count)
        glGetNamedBufferSubData(b, 0, (GLsizeiptr)(count * 4), out);
}

typedef struct pair { uint32_t key, value; } pair;

static int pair_order(const void *a, const void *b)
{
    const pair *p = a, *q = b;
    if (p->key != q->key)
        return p->key < q->key ? -1 : 1;
    return p->value < q->value ? -1 : p->value > q->value;
}

/* The CPU reference: with values = 0..n-1 in input order, sorting by
 * (key, value) is the stable sort by key. */
static void reference_sort(const uint32_t *keys, uint32_t n, uint32_t *sorted_keys, uint32_t *sorted_values)
{
    pair *p = malloc((n ? n : 1) * sizeof *p);
    for (uint32_t i = 0; i < n; i++)
        p[i] = (pair){keys[i], i};
    qsort(p, n, sizeof *p, pair_order);
    for (uint32_t i = 0; i < n; i++) {
        sorted_keys[i] = p[i].key;
        sorted_values[i] = p[i].value;
    }
    free(p);
}

/* Index of the first difference, or -1. */
static long first_difference(const uint32_t *a, const uint32_t *b, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        if (a[i] != b[i])
            return (long)i;
    return -1;
}

/* Sorts keys (values 0..n-1) on the GPU with m and checks against the reference. */
static void check_sort(pt_sorter *sorter, pt_sort_method m, const uint32_t *keys, uint32_t n, uint32_t key_bits,
                       const uint32_t *want_keys, const uint32_t *want_values, const char *what)
{
    uint32_t *values = malloc((n ? n : 1) * 4), *got_keys = malloc((n ? n : 1) * 4),
             *got_values = malloc((n ? n : 1) * 4);
    for (uint32_t i = 0; i < n; i++)
        values[i] = i;
    GLuint kb = buffer_with(keys, n), vb = buffer_with(values, n);
    sl_err err = {0};
    sl_status st = pt_sort_pairs(sorter, m, kb, vb, n, key_bits, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", what, err.message);
    read_buffer(kb, got_keys, n);
    read_buffer(vb, got_values, n);
    long dk = first_difference(got_keys, want_keys, n), dv = first_difference(got_values, want_values, n);
    SL_CHECK_MSG(dk < 0, "%s %s: key %ld is %u, the CPU sort has %u", m == PT_SORT_RADIX ? "radix" : "bitonic", what,
                 dk, dk < 0 ? 0 : got_keys[dk], dk < 0 ? 0 : want_keys[dk]);
    SL_CHECK_MSG(dv < 0, "%s %s: value %ld is %u, the CPU stable sort has %u",
                 m == PT_SORT_RADIX ? "radix" : "bitonic", what, dv, dv < 0 ? 0 : got_values[dv],
                 dv < 0 ? 0 : want_values[dv]);
    glDeleteBuffers(1, &kb);
    glDeleteBuffers(1, &vb);
    free(values);
    free(got_keys);
    free(got_values);
}

static void test_sorts(pt_sorter *sorter, const uint32_t *sizes, int size_count)
{
    /* Key bits (radix passes: 1, 2, 5 and 6, 8; odd counts end with the copy back); 0: all keys equal. */
    static const uint32_t bit_cases[] = {1, 8, 20, 23, 32, 0};
    for (int si = 0; si < size_count; si++) {
        uint32_t n = sizes[si];
        uint32_t *keys = malloc((n ? n : 1) * 4), *want_keys = malloc((n ? n : 1) * 4),
                 *want_values = malloc((n ? n : 1) * 4);
        for (size_t bi = 0; bi < sizeof bit_cases / sizeof bit_cases[0]; bi++) {
            uint32_t b = bit_cases[bi], key_bits = b ? b : 23;
            for (uint32_t i = 0; i < n; i++)
                keys[i] = b == 32 ? next_random() : b ? next_random() & ((1u << b) - 1) : 0x5A5A5Au;
            reference_sort(keys, n, want_keys, want_values);
            char what[64];
            if (b)
                snprintf(what, sizeof what, "n = %u, %u-bit keys", n, b);
            else
                snprintf(what, sizeof what, "n = %u, equal keys", n);
            check_sort(sorter, PT_SORT_RADIX, keys, n, key_bits, want_keys, want_values, what);
            check_sort(sorter, PT_SORT_BITONIC, keys, n, key_bits, want_keys, want_values, what);
        }
        free(keys);
        free(want_keys);
        free(want_values);
    }
}

/* Keys < bins with about 1/8 sentinels (bins, or above), sorted on the GPU by
 * radix; both tables against lower_bound on the CPU. */
static void test_tables(pt_sorter *sorter, const uint32_t *sizes, int size_count)
{
    static const uint32_t bin_cases[] = {1, 1000, 1u << 20};
    for (int si = 0; si < size_count; si++) {
        uint32_t n = sizes[si];
        for (size_t bi = 0; bi < sizeof bin_cases / sizeof bin_cases[0]; bi++) {
            uint32_t bins = bin_cases[bi];
            uint32_t *keys = malloc((n ? n : 1) * 4), *values = malloc((n ? n : 1) * 4);
            uint32_t *want = malloc(((size_t)bins + 1) * 4), *got = malloc(((size_t)bins + 1) * 4);
            for (uint32_t i = 0; i < n; i++) {
                uint32_t r = next_random();
                keys[i] = (r & 7) == 0 ? bins + (r >> 3) % 3 : (r >> 3) % bins;
                values[i] = i;
            }
            uint32_t key_bits = 1;
            while (key_bits < 32 && (bins + 2) >> key_bits)
                key_bits++;
            GLuint kb = buffer_with(keys, n), vb = buffer_with(values, n), sb = buffer_with(NULL, (size_t)bins + 1);
            sl_err err = {0};
            sl_status st = pt_sort_pairs(sorter, PT_SORT_RADIX, kb, vb, n, key_bits, &err);
            SL_CHECK_MSG(st == SL_OK, "sort for the table: %s", err.message);
            read_buffer(kb, keys, n);
            for (uint32_t b = 0, i = 0; b <= bins; b++) { /* lower_bound by a merge walk */
                while (i < n && keys[i] < b)
                    i++;
                want[b] = i;
            }
            for (int m = PT_LOOKUP_PREFIX_SUM; m <= PT_LOOKUP_BINARY_SEARCH; m++) {
                const uint32_t garbage = 0xDEADBEEFu;
                glClearNamedBufferData(sb, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &garbage);
                st = pt_bin_table(sorter, (pt_lookup_method)m, kb, n, bins, sb, &err);
                SL_CHECK_MSG(st == SL_OK, "table: %s", err.message);
                read_buffer(sb, got, (size_t)bins + 1);
                long d = first_difference(got, want, bins + 1);
                SL_CHECK_MSG(d < 0, "%s table, n = %u, bins = %u: start[%ld] = %u, lower_bound gives %u",
                             m == PT_LOOKUP_PREFIX_SUM ? "prefix_sum" : "binary_search", n, bins, d,
                             d < 0 ? 0 : got[d], d < 0 ? 0 : want[d]);
            }
            glDeleteBuffers(1, &kb);
            glDeleteBuffers(1, &vb);
            glDeleteBuffers(1, &sb);
            free(keys);
            free(values);
            free(want);
            free(got);
        }
    }
}

/* The shared scan: separate output and in place, capped, across 1, 2 and 3 levels. */
static void test_scan(void)
{
    sl_gpu_scan scan;
    sl_err err = {0};
    sl_status st = sl_gpu_scan_init(&scan, &err);
    SL_CHECK_MSG(st == SL_OK, "scan init: %s", err.message);
    if (st != SL_OK)
        return;
    static const uint32_t sizes[] = {1, 511, 512, 513, 262145, 300001};
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
        uint32_t n = sizes[si];
        uint32_t *in = malloc(n * 4), *want = malloc(n * 4), *want_capped = malloc(n * 4), *got = malloc(n * 4);
        uint32_t sum = 0, capped_sum = 0;
        for (uint32_t i = 0; i < n; i++) {
            in[i] = next_random() % 100;
            want[i] = sum;
            want_capped[i] = capped_sum;
            sum += in[i];
            capped_sum += in[i] < 40 ? in[i] : 40;
        }
        GLuint a = buffer_with(in, n), b = buffer_with(NULL, (size_t)n + 1);
        const uint32_t marker = 0xFEEDu;
        glClearNamedBufferData(b, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &marker);
        st = sl_gpu_scan_u32_capped(&scan, a, b, n, 40, &err);
        SL_CHECK_MSG(st == SL_OK, "capped scan: %s", err.message);
        read_buffer(b, got, n);
        SL_CHECK_MSG(first_difference(got, want_capped, n) < 0, "capped scan of %u values differs", n);
        uint32_t after = 0;
        glGetNamedBufferSubData(b, (GLintptr)n * 4, 4, &after);
        SL_CHECK_MSG(after == marker, "the scan of %u values wrote past them", n);
        st = sl_gpu_scan_u32(&scan, a, a, n, &err);
        SL_CHECK_MSG(st == SL_OK, "in-place scan: %s", err.message);
        read_buffer(a, got, n);
        SL_CHECK_MSG(first_difference(got, want, n) < 0, "in-place scan of %u values differs", n);
        glDeleteBuffers(1, &a);
        glDeleteBuffers(1, &b);
        free(in);
        free(want);
        free(want_capped);
        free(got);
    }
    sl_gpu_scan_deinit(&scan);
    sl_gpu_scan_deinit(&scan); /* deinit of a zeroed struct is fine */
}

static void test_errors(pt_sorter *sorter)
{
    uint32_t keys[4] = {3, 1, 2, 0};
    GLuint kb = buffer_with(keys, 4), vb = buffer_with(keys, 4);
    sl_err err = {0};
    SL_CHECK(pt_sort_pairs(sorter, PT_SORT_RADIX, kb, vb, 4, 0, &err) == SL_ERR_INVALID);
    SL_CHECK(pt_sort_pairs(sorter, PT_SORT_RADIX, kb, vb, 4, 33, &err) == SL_ERR_INVALID);
    SL_CHECK(pt_sort_pairs(sorter, PT_SORT_BITONIC, kb, vb, 5, 8, &err) == SL_ERR_INVALID);
    SL_CHECK_MSG(strstr(err.message, "holds 16 bytes, 20 needed") != NULL, "message: %s", err.message);
    SL_CHECK(pt_sort_pairs(sorter, PT_SORT_RADIX, kb, vb, PT_SORT_MAX_PAIRS + 1, 8, &err) == SL_ERR_LIMIT);
    SL_CHECK(pt_bin_table(sorter, PT_LOOKUP_PREFIX_SUM, kb, 4, PT_BINS_MAX + 1, vb, &err) == SL_ERR_LIMIT);
    SL_CHECK(pt_bin_table(sorter, PT_LOOKUP_BINARY_SEARCH, kb, 4, 4, vb, &err) == SL_ERR_INVALID); /* 5 needed */
    uint32_t after[4];
    read_buffer(kb, after, 4);
    SL_CHECK_MSG(memcmp(after, keys, sizeof keys) == 0, "a refused call must not touch the buffers");
    glDeleteBuffers(1, &kb);
    glDeleteBuffers(1, &vb);
    pt_sorter_destroy(NULL);
}

/* CPU time of the whole process (llvmpipe's threads included): comparable
 * across runs when other work shares the cores, unlike the wall time. */
static double process_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static double median5(double t[5])
{
    for (int i = 0; i < 5; i++)
        for (int j = i + 1; j < 5; j++)
            if (t[j] < t[i]) {
                double x = t[i];
                t[i] = t[j];
                t[j] = x;
            }
    return t[2];
}

/* Release timings for particles_sort.h: wall time to glFinish, median of 5. */
static int print_timings(pt_sorter *sorter)
{
    static const uint32_t sizes[] = {10000, 60000, 200000};
    printf("wall ms to glFinish, median of 5 (process CPU ms in brackets)\n");
    printf("sort, key_bits 20        n          radix          bitonic\n");
    for (int si = 0; si < 3; si++) {
        uint32_t n = sizes[si];
        uint32_t *keys = malloc(n * 4), *values = malloc(n * 4);
        for (uint32_t i = 0; i < n; i++) {
            keys[i] = next_random() & ((1u << 20) - 1);
            values[i] = i;
        }
        GLuint pristine_keys = buffer_with(keys, n), pristine_values = buffer_with(values, n);
        GLuint kb = buffer_with(NULL, n), vb = buffer_with(NULL, n);
        double ms[2], cpu[2];
        for (int m = 0; m < 2; m++) {
            double t[5], c[5];
            for (int r = -1; r < 5; r++) { /* r = -1: compiles the programs, grows the scratch */
                glCopyNamedBufferSubData(pristine_keys, kb, 0, 0, (GLsizeiptr)n * 4);
                glCopyNamedBufferSubData(pristine_values, vb, 0, 0, (GLsizeiptr)n * 4);
                glFinish();
                double t0 = sl_clock_ms(), c0 = process_cpu_ms();
                sl_err err;
                if (pt_sort_pairs(sorter, (pt_sort_method)m, kb, vb, n, 20, &err) != SL_OK) {
                    fprintf(stderr, "%s\n", err.message);
                    return 1;
                }
                glFinish();
                if (r >= 0) {
                    t[r] = sl_clock_ms() - t0;
                    c[r] = process_cpu_ms() - c0;
                }
            }
            ms[m] = median5(t);
            cpu[m] = median5(c);
        }
        printf("%24s %6u %7.2f (%6.2f) %7.2f (%6.2f)\n", "", n, ms[0], cpu[0], ms[1], cpu[1]);
        GLuint names[4] = {pristine_keys, pristine_values, kb, vb};
        glDeleteBuffers(4, names);
        free(keys);
        free(values);
    }
    const uint32_t n = 60000;
    uint32_t *keys = malloc(n * 4);
    printf("table, n = %u     bins     prefix_sum    binary_search\n", n);
    for (int e = 20; e <= 22; e += 2) {
        uint32_t bins = 1u << e;
        for (uint32_t i = 0; i < n; i++)
            keys[i] = (uint32_t)(((uint64_t)i * bins) / n); /* sorted, spread over the bins */
        GLuint kb = buffer_with(keys, n), sb = buffer_with(NULL, (size_t)bins + 1);
        double ms[2], cpu[2];
        for (int m = 0; m < 2; m++) {
            double t[5], c[5];
            for (int r = -1; r < 5; r++) {
                glFinish();
                double t0 = sl_clock_ms(), c0 = process_cpu_ms();
                sl_err err;
                if (pt_bin_table(sorter, (pt_lookup_method)m, kb, n, bins, sb, &err) != SL_OK) {
                    fprintf(stderr, "%s\n", err.message);
                    return 1;
                }
                glFinish();
                if (r >= 0) {
                    t[r] = sl_clock_ms() - t0;
                    c[r] = process_cpu_ms() - c0;
                }
            }
            ms[m] = median5(t);
            cpu[m] = median5(c);
        }
        printf("%24s   2^%d %7.2f (%6.2f) %7.2f (%6.2f)\n", "", e, ms[0], cpu[0], ms[1], cpu[1]);
        glDeleteBuffers(1, &kb);
        glDeleteBuffers(1, &sb);
    }
    free(keys);
    return 0;
}

int main(int argc, char **argv)
{
    int timing = argc > 1 && strcmp(argv[1], "--time") == 0;
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "test_particles_sort: %s\n", err.message);
        return 1;
    }
    pt_sorter *sorter = NULL;
    sl_status st = pt_sorter_create(&sorter, &err);
    SL_CHECK_MSG(st == SL_OK, "pt_sorter_create: %s", err.message);
    if (st == SL_OK && timing) {
        int rc = print_timings(sorter);
        pt_sorter_destroy(sorter);
        sl_gpu_destroy(gpu);
        return rc;
    }
    if (st == SL_OK) {
        static const uint32_t sizes[] = {0, 1, 2, 255, 256, 257, 1023, 1025, 65535, 65537, 200000};
        static const uint32_t table_sizes[] = {0, 1, 257, 65537, 200000};
        double t0 = sl_clock_ms();
        test_sorts(sorter, sizes, (int)(sizeof sizes / sizeof sizes[0]));
        test_tables(sorter, table_sizes, (int)(sizeof table_sizes / sizeof table_sizes[0]));
        printf("sorts and tables: %.0f ms\n", sl_clock_ms() - t0);
        /* Again with 3 groups per dispatch chunk: every dispatch above is split. */
        pt_sorter_set_max_groups(sorter, 3);
        static const uint32_t chunked_sizes[] = {4097, 65537};
        static const uint32_t chunked_table_sizes[] = {4097};
        test_sorts(sorter, chunked_sizes, 2);
        test_tables(sorter, chunked_table_sizes, 1);
        pt_sorter_set_max_groups(sorter, 0);
        test_errors(sorter);
    }
    test_scan();
    SL_CHECK_MSG(sl_gl_check_errors("test", &err) == SL_OK, "%s", err.message);
    pt_sorter_destroy(sorter);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
