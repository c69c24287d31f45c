/* scan.c — the recursive driver of the exclusive u32 scan (sl_gpu_scan.h).
 *
 * Level 0 scans `in` into `out` in blocks of 4096 and writes the block totals
 * to sums[0]; level L+1 scans sums[L] in place the same way, until one block
 * remains; then each level adds its scanned block totals back, deepest
 * first. Every dispatch is chunked at max_groups (sl_gpu_dispatch_chunked).
 * Render thread only.
 */
#include "sl_gpu_scan.h"

#include <assert.h>
#include <string.h>

#define SCAN_BLOCK 4096u /* scan.comp.glsl */

sl_status sl_gpu_scan_init(sl_gpu_scan *s, sl_err *err)
{
    memset(s, 0, sizeof *s);
    sl_status st = sl_gl_program_create(&(sl_program_desc){.compute = "gpu/glsl/scan.comp.glsl",
                                                           .defines = "#define SCAN_PASS 1\n",
                                                           .label = "gpu scan blocks"},
                                        &s->block_program, err);
    if (st == SL_OK)
        st = sl_gl_program_create(&(sl_program_desc){.compute = "gpu/glsl/scan.comp.glsl",
                                                     .defines = "#define SCAN_PASS 2\n",
                                                     .label = "gpu scan add"},
                                  &s->add_program, err);
    if (st != SL_OK) {
        sl_gpu_scan_deinit(s);
        return st;
    }
    s->block_n = glGetUniformLocation(s->block_program, "u_n");
    s->block_cap = glGetUniformLocation(s->block_program, "u_cap");
    s->block_base = glGetUniformLocation(s->block_program, "u_group_base");
    s->add_n = glGetUniformLocation(s->add_program, "u_n");
    s->add_base = glGetUniformLocation(s->add_program, "u_group_base");
    s->max_groups = sl_gpu_max_groups();
    return SL_OK;
}

void sl_gpu_scan_deinit(sl_gpu_scan *s)
{
    if (s->block_program)
        glDeleteProgram(s->block_program);
    if (s->add_program)
        glDeleteProgram(s->add_program);
    for (int level = 0; level < SL_GPU_SCAN_LEVELS; level++)
        if (s->sums[level])
            glDeleteBuffers(1, &s->sums[level]);
    memset(s, 0, sizeof *s);
}

/* Makes sums[level] hold at least `entries` u32 (a new buffer, rounded up to
 * a power of two, when it is too small). */
static void reserve_sums(sl_gpu_scan *s, int level, size_t entries)
{
    if (s->sums_capacity[level] >= entries)
        return;
    size_t capacity = 64;
    while (capacity < entries)
        capacity *= 2;
    if (s->sums[level])
        glDeleteBuffers(1, &s->sums[level]);
    glCreateBuffers(1, &s->sums[level]);
    glNamedBufferStorage(s->sums[level], (GLsizeiptr)(capacity * sizeof(uint32_t)), NULL, 0);
    glObjectLabel(GL_BUFFER, s->sums[level], -1, "gpu scan block sums");
    s->sums_capacity[level] = capacity;
}

static void scan_level(sl_gpu_scan *s, int level, GLuint in, GLuint out, uint32_t n, uint32_t cap)
{
    assert(level < SL_GPU_SCAN_LEVELS);
    size_t blocks = ((size_t)n + SCAN_BLOCK - 1) / SCAN_BLOCK;
    reserve_sums(s, level, blocks);
    glUseProgram(s->block_program);
    glUniform1ui(s->block_n, n);
    glUniform1ui(s->block_cap, cap);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->sums[level]);
    sl_gpu_dispatch_chunked(s->block_base, blocks, s->max_groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    if (blocks <= 1)
        return;
    /* n < 2^32 gives at most 2^20, 2^8, 1 blocks: level 2 is one block. */
    scan_level(s, level + 1, s->sums[level], s->sums[level], (uint32_t)blocks, UINT32_MAX);
    glUseProgram(s->add_program);
    glUniform1ui(s->add_n, n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->sums[level]);
    sl_gpu_dispatch_chunked(s->add_base, blocks, s->max_groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

sl_status sl_gpu_scan_u32_capped(sl_gpu_scan *s, GLuint in, GLuint out, uint32_t n, uint32_t cap, sl_err *err)
{
    if (n == 0)
        return SL_OK;
    scan_level(s, 0, in, out, n, cap);
    return sl_gl_check_errors("GPU exclusive scan", err);
}

sl_status sl_gpu_scan_u32(sl_gpu_scan *s, GLuint in, GLuint out, uint32_t n, sl_err *err)
{
    return sl_gpu_scan_u32_capped(s, in, out, n, UINT32_MAX, err);
}
