/* particles_sort.h — GPU sorts of (key, value) u32 pairs and bin start tables (particles_sort.c).
 *
 * Generic steps I–II of van Pelt et al. §4.1.2 (docs/particles_plan.md §1.2):
 * sort indices by bin, then find each bin's first sorted index. Two sorts and
 * two table builds, each pair with identical results (test_particles_sort).
 * Not done here: keys above 32 bits, descending order, CPU fallbacks.
 * Render thread only; every call changes the current program and the shader
 * storage bindings 0..5. Limits: n <= PT_SORT_MAX_PAIRS, bins <= PT_BINS_MAX.
 * Defaults from llvmpipe (2 shared cores, Release, process CPU ms, median of
 * 5, `test_particles_sort --time`): radix, 7-10x faster than bitonic at
 * key_bits 20 (60k pairs 7 vs 50 ms, 200k 23 vs 250; bitonic's local stages
 * have 10-55 barriers per block, and barriers are what llvmpipe pays for);
 * prefix_sum, 4x faster than binary_search for bins >> n (60k keys: 2^20
 * bins 9 vs 34 ms, 2^22 bins 32 vs 135).
 */
#ifndef PT_PARTICLES_SORT_H
#define PT_PARTICLES_SORT_H

#include <stdint.h>

#include "../gpu/sl_gpu.h"

#define PT_SORT_MAX_PAIRS (1u << 23) /* bitonic pads to a power of two: 64 MiB of pairs */
#define PT_BINS_MAX (1u << 24)       /* start[] of 64 MiB */

typedef enum pt_sort_method { PT_SORT_RADIX, PT_SORT_BITONIC } pt_sort_method;
typedef enum pt_lookup_method { PT_LOOKUP_PREFIX_SUM, PT_LOOKUP_BINARY_SEARCH } pt_lookup_method;
#define PT_SORT_DEFAULT PT_SORT_RADIX
#define PT_LOOKUP_DEFAULT PT_LOOKUP_PREFIX_SUM

/* Programs (compiled at the first use of each method) and scratch buffers
 * (grown as needed, kept), owned. */
typedef struct pt_sorter pt_sorter;

/* SL_ERR_NOMEM, or SL_ERR_GPU when the scan programs do not build (*out NULL). */
sl_status pt_sorter_create(pt_sorter **out, sl_err *err);
void pt_sorter_destroy(pt_sorter *s); /* NULL fine */
/* Tests only: at most max_groups work groups per dispatch (0 = the driver's
 * limit), so small inputs exercise the chunking that large ones need. */
void pt_sorter_set_max_groups(pt_sorter *s, unsigned max_groups);

/* Sorts n (key, value) u32 pairs held in two SSBOs (keys[n], values[n]) in
 * place by key ascending. key_bits: keys are < 2^key_bits (1..32; higher bits
 * are ignored by radix), so radix runs ceil(key_bits / 4) passes of 4-bit
 * digits. Radix is stable (equal keys keep input order); bitonic sorts by
 * (key, value) lexicographically, so with values = 0..n-1 in input order
 * both give identical output. Ends with a shader-storage and buffer-update
 * barrier. SL_ERR_INVALID: key_bits outside 1..32, a buffer smaller than n
 * u32; SL_ERR_LIMIT: n > PT_SORT_MAX_PAIRS or a scratch buffer above the
 * GPU's shader storage block size (radix 4n bytes, bitonic 8 per padded
 * pair); SL_ERR_GPU: a program failed to
 * build or a GL call failed (sl_gl_check_errors; the buffers' contents are
 * then undefined). n = 0 or 1 does nothing. */
sl_status pt_sort_pairs(pt_sorter *s, pt_sort_method m, GLuint keys, GLuint values, uint32_t n, uint32_t key_bits,
                        sl_err *err);

/* start[b] for b in [0, bins] = the first index i with sorted_keys[i] >= b
 * (lower bound); start[bins] = the count of keys < bins. Keys >= bins (the
 * sentinel for dead entries) sort after every bin. `start` holds bins + 1
 * u32. Both methods give identical tables; prefix_sum does not even need the
 * keys sorted, binary_search does. Ends with a shader-storage barrier.
 * SL_ERR_INVALID: a buffer too small; SL_ERR_LIMIT: n > PT_SORT_MAX_PAIRS or
 * bins > PT_BINS_MAX or 4 (bins + 1) bytes above the block size; SL_ERR_GPU
 * as pt_sort_pairs. */
sl_status pt_bin_table(pt_sorter *s, pt_lookup_method m, GLuint sorted_keys, uint32_t n, uint32_t bins, GLuint start,
                       sl_err *err);

#endif
