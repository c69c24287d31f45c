/* voxelize_gpu.c — the voxel model built with compute shaders (Kanzler et al., Sec. 3.3).
 *
 * Five passes of voxelize_gpu.comp.glsl: count pieces per curve, emit
 * (voxel, code) items in curve order, voxel histogram, scatter item indices
 * into per-voxel segments, and per voxel: sort by item index, apply the cap,
 * bit-pack and sum lengths. The exclusive scans between passes (over curves;
 * over voxels, uncapped and capped) run on the GPU (gpu/sl_gpu_scan.h);
 * counts are read back only for statistics and the CPU copy of the headers.
 * With a colour attribute the per-vertex normalized values (the one division
 * of the attribute byte's definition, voxel_grid.h) are computed here with
 * sl_voxel_attr_normalize and uploaded as doubles; the shader interpolates
 * and rounds them exactly as voxelize_cpu.c. The result is read back into a
 * CPU sl_voxel_grid equal to sl_voxel_grid_build's, attribute bytes included
 * (tests/render/voxel_lines/voxel_gpu_build.c checks it), except that
 * `degenerate` is not counted. Render thread only (needs the GL context).
 */
#include "voxel_gpu.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../gpu/sl_gpu.h"
#include "../gpu/sl_gpu_scan.h"

#define PASSES 5

static GLuint ssbo(size_t bytes, const void *data)
{
    GLuint b;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(bytes ? bytes : 4), data, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    if (!data) {
        const GLuint zero = 0;
        glClearNamedBufferData(b, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    }
    return b;
}

/* Exclusive scan of n uints of `in` (each capped to cap) into a new buffer
 * (*out; the caller deletes it, also on failure) with the shared GPU scan. */
static sl_status scan_into_new(sl_gpu_scan *scan, GLuint in, size_t n, uint32_t cap, GLuint *out, sl_err *err)
{
    *out = ssbo(n * sizeof(uint32_t), NULL);
    return sl_gpu_scan_u32_capped(scan, in, *out, (uint32_t)n, cap, err);
}

/* One invocation per element 0..count-1, 64 per group. */
static void run(GLuint program, GLuint count, GLuint max_groups)
{
    glUseProgram(program);
    glUniform1ui(glGetUniformLocation(program, "u_count"), count);
    sl_gpu_dispatch_chunked(glGetUniformLocation(program, "u_group_base"), ((size_t)count + 63) / 64, max_groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

sl_status sl_voxel_grid_build_gpu(sl_voxel_grid *g, const sl_dataset *ds, const sl_voxel_grid_desc *desc,
                                  sl_err *err)
{
    return sl_voxel_grid_build_gpu_chunked(g, ds, desc, 0, err);
}

sl_status sl_voxel_grid_build_gpu_chunked(sl_voxel_grid *g, const sl_dataset *ds, const sl_voxel_grid_desc *desc,
                                          unsigned max_groups, sl_err *err)
{
    memset(g, 0, sizeof *g);
    /* Errors raised before this build are not ours: drain them so the check
     * at the end reports only this build's. */
    while (glGetError() != GL_NO_ERROR) {
    }
    unsigned limit = sl_gpu_max_groups();
    if (max_groups == 0 || max_groups > limit)
        max_groups = limit;
    double t0 = sl_clock_ms();
    sl_voxel_grid_desc d = desc ? *desc : (sl_voxel_grid_desc){0};
    if (d.quant == 0) d.quant = 32;
    if (d.padding < 0) d.padding = 1;
    if (d.max_per_voxel == 0) d.max_per_voxel = SL_VOXEL_COUNT_MAX;
    int k = sl_voxel_quant_bits(d.quant);
    if (k < 0)
        return sl_err_set(err, SL_ERR_INVALID, "face quantization %d must be a power of two in 2..256", d.quant);
    if (d.max_per_voxel < 1 || d.max_per_voxel > SL_VOXEL_COUNT_MAX)
        return sl_err_set(err, SL_ERR_INVALID, "max lines per voxel %d must be in 1..%d", d.max_per_voxel,
                          SL_VOXEL_COUNT_MAX);
    sl_status st = sl_voxel_frame_init(&g->frame, ds, d.resolution, d.padding, err);
    if (st != SL_OK)
        return st;
    const sl_lines *l = &ds->lines;
    g->quant = d.quant;
    g->quant_bits = k;
    g->line_bytes = sl_voxel_line_bytes(k);
    g->voxel_count = (size_t)g->frame.dims[0] * g->frame.dims[1] * g->frame.dims[2];
    g->attribute_index = d.attribute >= 0 && d.attribute < l->attribute_count ? d.attribute : -1;

    GLuint prog[PASSES] = {0};
    sl_gpu_scan scan = {0};
    GLuint buf[11] = {0};
    uint32_t *curve_counts = NULL, *voxel_counts = NULL, *line_starts = NULL;
    for (int p = 0; p < PASSES && st == SL_OK; p++) {
        char defines[64], label[32];
        snprintf(defines, sizeof defines, "#define VX_PASS %d\n", p + 1);
        snprintf(label, sizeof label, "voxelize_gpu_pass%d", p + 1);
        st = sl_gl_program_create(&(sl_program_desc){.compute = "voxel_lines/voxelize_gpu.comp.glsl",
                                                     .defines = defines, .label = label},
                                  &prog[p], err);
    }
    if (st == SL_OK)
        st = sl_gpu_scan_init(&scan, err);
    scan.max_groups = max_groups;
    if (st != SL_OK)
        goto fail;
    size_t curves = l->line_count;
    buf[0] = ssbo(l->vertex_count * 3 * sizeof(float), l->positions);
    buf[1] = ssbo((curves + 1) * sizeof(uint32_t), l->line_offsets);
    buf[2] = ssbo((curves + 1) * sizeof(uint32_t), NULL);
    if (g->attribute_index >= 0) {
        /* Step 1 of the attribute byte on the CPU (voxel_grid.h); bound at 10. */
        const sl_attribute *at = &l->attributes[g->attribute_index];
        double *norm = malloc((l->vertex_count ? l->vertex_count : 1) * sizeof *norm);
        if (!norm) {
            st = sl_err_set(err, SL_ERR_NOMEM, "GPU voxelization: out of memory for %zu attribute values",
                            l->vertex_count);
            goto fail;
        }
        sl_voxel_attr_normalize(at, at->values, l->vertex_count, norm);
        buf[10] = ssbo(l->vertex_count * sizeof *norm, norm);
        free(norm);
    } else {
        buf[10] = ssbo(sizeof(double), NULL); /* unread: u_has_attr = 0 */
    }
    for (int p = 0; p < PASSES; p++) {
        GLuint pr = prog[p];
        glUseProgram(pr);
        glUniform3d(glGetUniformLocation(pr, "u_lo"), g->frame.lo[0], g->frame.lo[1], g->frame.lo[2]);
        glUniform1d(glGetUniformLocation(pr, "u_h"), g->frame.h);
        glUniform3i(glGetUniformLocation(pr, "u_dims"), g->frame.dims[0], g->frame.dims[1], g->frame.dims[2]);
        glUniform1i(glGetUniformLocation(pr, "u_quant"), d.quant);
        glUniform1i(glGetUniformLocation(pr, "u_k"), k);
        glUniform1ui(glGetUniformLocation(pr, "u_cap"), (GLuint)d.max_per_voxel);
        glUniform1i(glGetUniformLocation(pr, "u_line_bits"), 8 * g->line_bytes);
        glUniform1i(glGetUniformLocation(pr, "u_has_attr"), g->attribute_index >= 0);
    }
    for (int b = 0; b < 3; b++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)b, buf[b]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 10, buf[10]);

    /* 1: pieces per curve; their exclusive scan (GPU) gives each curve's
     * first item. The counts are read back only for statistics. */
    run(prog[0], (GLuint)curves, max_groups);
    curve_counts = malloc((curves + 1) * sizeof *curve_counts);
    if (!curve_counts) {
        st = sl_err_set(err, SL_ERR_NOMEM, "GPU voxelization: out of memory");
        goto fail;
    }
    glGetNamedBufferSubData(buf[2], 0, (GLsizeiptr)((curves + 1) * sizeof(uint32_t)), curve_counts);
    size_t total = 0;
    for (size_t c = 0; c < curves; c++) {
        total += curve_counts[c];
        g->curves_without_pieces += curve_counts[c] == 0;
    }
    if (total > (size_t)SL_MAX_VERTICES * 8u) {
        st = sl_err_set(err, SL_ERR_LIMIT, "GPU voxelization: more than %u pieces", SL_MAX_VERTICES * 8u);
        goto fail;
    }
    GLuint curve_starts = 0;
    st = scan_into_new(&scan, buf[2], curves + 1, UINT32_MAX, &curve_starts, err);
    glDeleteBuffers(1, &buf[2]);
    buf[2] = curve_starts;
    if (st != SL_OK)
        goto fail;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buf[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buf[1]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buf[2]);
    g->pieces = total;
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    size_t biggest = total * 16u > (g->voxel_count + 1) * 4u ? total * 16u : (g->voxel_count + 1) * 4u;
    if (max_block > 0 && biggest > (size_t)max_block) {
        st = sl_err_set(err, SL_ERR_LIMIT,
                        "GPU voxelization: a %zu-byte buffer (%zu pieces, %zu voxels) exceeds the shader storage "
                        "block limit of %lld bytes; use the CPU build or a smaller grid",
                        biggest, total, g->voxel_count, (long long)max_block);
        goto fail;
    }

    /* 2: items in curve order; 3: voxel histogram. */
    buf[3] = ssbo(total * 4 * sizeof(uint32_t), NULL);
    buf[4] = ssbo((g->voxel_count + 1) * sizeof(uint32_t), NULL);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, buf[3]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, buf[4]);
    run(prog[1], (GLuint)curves, max_groups);
    glDeleteBuffers(1, &buf[10]); /* the attribute values are read by EMIT only */
    buf[10] = 0;
    run(prog[2], (GLuint)total, max_groups);
    voxel_counts = malloc(g->voxel_count * sizeof *voxel_counts);
    line_starts = malloc((g->voxel_count + 1) * sizeof *line_starts);
    g->offsets = malloc(g->voxel_count * sizeof *g->offsets);
    g->counts = malloc(g->voxel_count);
    g->density = malloc(g->voxel_count * sizeof *g->density);
    if (!voxel_counts || !line_starts || !g->offsets || !g->counts || !g->density) {
        st = sl_err_set(err, SL_ERR_NOMEM, "GPU voxelization of %zu voxels: out of memory", g->voxel_count);
        goto fail;
    }
    /* Headers: exclusive scans of the histogram, uncapped (segments) and
     * capped (line offsets), on the GPU. The counts are read back for the
     * CPU copy of the headers and the statistics. */
    glGetNamedBufferSubData(buf[4], 0, (GLsizeiptr)(g->voxel_count * sizeof(uint32_t)), voxel_counts);
    st = scan_into_new(&scan, buf[4], g->voxel_count + 1, UINT32_MAX, &buf[5], err);
    if (st == SL_OK)
        st = scan_into_new(&scan, buf[4], g->voxel_count + 1, (uint32_t)d.max_per_voxel, &buf[7], err);
    if (st != SL_OK)
        goto fail;
    glGetNamedBufferSubData(buf[7], 0, (GLsizeiptr)((g->voxel_count + 1) * sizeof(uint32_t)), line_starts);
    size_t s_kept = line_starts[g->voxel_count];
    for (size_t v = 0; v < g->voxel_count; v++) {
        uint32_t n = voxel_counts[v];
        g->offsets[v] = line_starts[v];
        if ((int)n > g->max_count)
            g->max_count = (int)n;
        uint32_t kept = n > (uint32_t)d.max_per_voxel ? (uint32_t)d.max_per_voxel : n;
        if (kept < n) {
            g->dropped_overflow += n - kept;
            g->capped_voxels++;
        }
        g->counts[v] = (uint8_t)kept;
    }
    g->line_count = s_kept;

    /* 4: scatter into segments; 5: sort, cap, pack, density. */
    const GLuint zero = 0;
    glClearNamedBufferData(buf[4], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    buf[6] = ssbo(total * sizeof(uint32_t), NULL);
    size_t word_count = (s_kept * (size_t)g->line_bytes + 8 + 3) / 4 + 3;
    buf[8] = ssbo(word_count * sizeof(uint32_t), NULL);
    buf[9] = ssbo(g->voxel_count * sizeof(float), NULL);
    for (int b = 5; b < 10; b++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)b, buf[b]);
    run(prog[3], (GLuint)total, max_groups);
    run(prog[4], (GLuint)g->voxel_count, max_groups);
    g->lines = calloc(word_count, sizeof(uint32_t));
    if (!g->lines) {
        st = sl_err_set(err, SL_ERR_NOMEM, "GPU voxelization: %zu lines do not fit in memory", s_kept);
        goto fail;
    }
    glGetNamedBufferSubData(buf[8], 0, (GLsizeiptr)(word_count * sizeof(uint32_t)), g->lines);
    glGetNamedBufferSubData(buf[9], 0, (GLsizeiptr)(g->voxel_count * sizeof(float)), g->density);
    /* Any failed GL call (a dispatch or buffer above a limit, out of memory)
     * means some pass did not run: the result would be garbage. */
    GLenum gl_error = glGetError();
    if (gl_error != GL_NO_ERROR) {
        st = sl_err_set(err, SL_ERR_GPU,
                        "GPU voxelization of %zu voxels and %zu pieces failed with GL error 0x%04x "
                        "(work-group limit %u per dispatch); use voxelize = cpu or a smaller grid",
                        g->voxel_count, total, (unsigned)gl_error, max_groups);
        while (glGetError() != GL_NO_ERROR) {
        }
        goto fail;
    }
    /* The CPU layout keeps 8 zero bytes after the last line. */
    memset(g->lines + s_kept * (size_t)g->line_bytes, 0, word_count * 4 - s_kept * (size_t)g->line_bytes);
    g->build_ms = sl_clock_ms() - t0;
    st = SL_OK;
    goto done;
fail:
    sl_voxel_grid_deinit(g);
done:
    for (int p = 0; p < PASSES; p++)
        if (prog[p])
            glDeleteProgram(prog[p]);
    sl_gpu_scan_deinit(&scan);
    for (int b = 0; b < 11; b++)
        if (buf[b])
            glDeleteBuffers(1, &buf[b]);
    free(curve_counts);
    free(voxel_counts);
    free(line_starts);
    return st;
}
