/* sl_gpu_scan.h — exclusive prefix sum of u32 buffers on the GPU (scan.c, gpu/glsl/scan.comp.glsl).
 *
 * Blocks of 4096 values are scanned by one work group; the block totals are
 * scanned the same way, recursively (3 of the SL_GPU_SCAN_LEVELS levels
 * cover any n < 2^32), and added back. An sl_gpu_scan owns the two programs and one
 * block-sum buffer per level, made at the first use and grown as needed, so
 * repeated scans allocate nothing. Sums wrap modulo 2^32 (callers keep totals
 * below it). Not done here: segmented scans, inclusive scans, other types.
 * Render thread only; a scan changes the current program and the shader
 * storage bindings 0..2.
 */
#ifndef SL_GPU_SCAN_H
#define SL_GPU_SCAN_H

#include "sl_gpu.h"

#define SL_GPU_SCAN_LEVELS 4

typedef struct sl_gpu_scan {
    GLuint block_program, add_program;          /* SCAN_PASS 1 and 2 */
    GLint block_n, block_cap, block_base;       /* uniform locations */
    GLint add_n, add_base;
    GLuint sums[SL_GPU_SCAN_LEVELS];            /* block totals per level, owned */
    size_t sums_capacity[SL_GPU_SCAN_LEVELS];   /* entries of sums[level] */
    unsigned max_groups; /* groups per dispatch chunk; init: the driver's limit; tests may lower it */
} sl_gpu_scan;

/* Compiles the programs. SL_ERR_GPU (with the info log) on failure; *s is
 * then deinit-safe. */
sl_status sl_gpu_scan_init(sl_gpu_scan *s, sl_err *err);
/* Deletes every GL name of *s and zeroes it; a zeroed struct is fine. */
void sl_gpu_scan_deinit(sl_gpu_scan *s);

/* out[i] = in[0] + ... + in[i-1] for i < n (out[0] = 0); out[n..] untouched.
 * in == out is allowed (in place); otherwise the buffers must not overlap.
 * Both hold at least n u32 (not checked). n = 0 does nothing. Ends with a
 * shader-storage barrier, so later dispatches see out. SL_ERR_GPU when a GL
 * call failed (sl_gl_check_errors: it also reports errors raised before the
 * call and not yet drained). */
sl_status sl_gpu_scan_u32(sl_gpu_scan *s, GLuint in, GLuint out, uint32_t n, sl_err *err);
/* The same of min(in[i], cap) (voxel_lines: lines kept per voxel);
 * cap = UINT32_MAX is sl_gpu_scan_u32. */
sl_status sl_gpu_scan_u32_capped(sl_gpu_scan *s, GLuint in, GLuint out, uint32_t n, uint32_t cap, sl_err *err);

#endif
