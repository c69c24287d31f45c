/* lr_lookup_gpu.c — the flattened GPU form of an sl_lr_lookup (layout in
 * sl_lr_lookup.h, read by lr_lookup.glsl): three SSBOs at bindings 10..12,
 * the heads also as a 3D texture on unit 8, and the uniforms of a program.
 * Planes go to the float at or above their double value and the domain
 * inwards, which keeps float queries exact.
 * Render thread only (GL).
 */
#include "sl_lr_lookup.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../gpu/sl_gpu.h"

static float float_up(double s)
{
    float f = (float)s;
    if ((double)f < s)
        f = nextafterf(f, INFINITY);
    return f;
}

static float float_down(double s)
{
    float f = (float)s;
    if ((double)f > s)
        f = nextafterf(f, -INFINITY);
    return f;
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static GLuint make_buffer(const void *data, size_t bytes)
{
    static const uint32_t zero[4] = {0, 0, 0, 0};
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(bytes ? bytes : sizeof zero), bytes ? data : zero, 0);
    return b;
}

sl_status sl_lr_lookup_gpu_init(sl_lr_lookup_gpu *g, const sl_lr_lookup *lk, int heads_texture, sl_err *err)
{
    memset(g, 0, sizeof *g);
    g->kind = lk->kind;
    for (int d = 0; d < 3; d++) {
        g->n[d] = lk->n[d] > 0 ? lk->n[d] : 1;
        g->lo[d] = float_up(lk->lo[d]);
        g->hi[d] = float_down(lk->hi[d]);
        g->origin[d] = (float)lk->lo[d];
        g->scale[d] = (float)(g->n[d] / (lk->hi[d] - lk->lo[d]));
    }
    uint32_t *heads = NULL, *nodes = NULL;
    float *planes = NULL;
    size_t nh = 0, nn = 0, np = 0;
    if (lk->kind == SL_LR_LOOKUP_OCTREE) {
        nh = 1;
        nn = 11 * lk->oct_count;
        heads = malloc(sizeof *heads);
        nodes = malloc(nn * sizeof *nodes + 4);
        if (heads && nodes) {
            heads[0] = lk->oct_root;
            for (size_t i = 0; i < lk->oct_count; i++) {
                for (int d = 0; d < 3; d++)
                    nodes[11 * i + (size_t)d] = float_bits(float_up(lk->oct[i].mid[d]));
                memcpy(&nodes[11 * i + 3], lk->oct[i].child, 8 * sizeof(uint32_t));
            }
        }
    } else {
        nh = (size_t)lk->n[0] * (size_t)lk->n[1] * (size_t)lk->n[2];
        np = (size_t)(lk->n[0] + lk->n[1] + lk->n[2] + 3);
        nn = 2 * lk->node_count;
        if (lk->node_count >= 0x3FFFFFFFu)
            return sl_err_set(err, SL_ERR_LIMIT, "element look-up: %zu k-d nodes exceed the GPU form's 2^30",
                              lk->node_count);
        heads = malloc(nh * sizeof *heads);
        nodes = malloc(nn * sizeof *nodes + 4);
        planes = malloc(np * sizeof *planes);
        if (heads && nodes && planes) {
            memcpy(heads, lk->heads, nh * sizeof *heads);
            size_t k = 0;
            for (int d = 0; d < 3; d++)
                for (int c = 0; c <= lk->n[d]; c++)
                    planes[k++] = float_up(lk->planes[d][c]);
            for (size_t i = 0; i < lk->node_count; i++) {
                const sl_lr_kdnode *n = &lk->nodes[i];
                uint32_t index = n->index == UINT32_MAX ? 0x3FFFFFFFu : n->index;
                nodes[2 * i] = n->axis << 30 | index;
                nodes[2 * i + 1] = float_bits(n->axis == 3 ? 0.0f : float_up(n->split));
            }
        }
    }
    if (!heads || !nodes || (np && !planes)) {
        free(heads);
        free(nodes);
        free(planes);
        return sl_err_set(err, SL_ERR_NOMEM, "element look-up: out of memory for the GPU form");
    }
    g->heads = make_buffer(heads, nh * sizeof *heads);
    g->nodes = make_buffer(nodes, nn * sizeof *nodes);
    g->planes = make_buffer(planes, np * sizeof *planes);
    g->bytes = (nh + nn + np) * 4;
    if (heads_texture && lk->kind != SL_LR_LOOKUP_OCTREE) {
        GLint max3d = 0;
        glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
        if (g->n[0] <= max3d && g->n[1] <= max3d && g->n[2] <= max3d) {
            glCreateTextures(GL_TEXTURE_3D, 1, &g->heads_texture);
            glTextureStorage3D(g->heads_texture, 1, GL_R32UI, g->n[0], g->n[1], g->n[2]);
            glTextureParameteri(g->heads_texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(g->heads_texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
            glTextureSubImage3D(g->heads_texture, 0, 0, 0, 0, g->n[0], g->n[1], g->n[2], GL_RED_INTEGER,
                                GL_UNSIGNED_INT, heads);
        }
    }
    free(heads);
    free(nodes);
    free(planes);
    sl_status st = sl_gl_check_errors("uploading the element look-up", err);
    if (st != SL_OK)
        sl_lr_lookup_gpu_deinit(g);
    return st;
}

void sl_lr_lookup_gpu_bind(const sl_lr_lookup_gpu *g, unsigned int program)
{
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SL_LR_LOOKUP_BINDING_HEADS, g->heads);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SL_LR_LOOKUP_BINDING_NODES, g->nodes);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SL_LR_LOOKUP_BINDING_PLANES, g->planes);
    glUniform3i(glGetUniformLocation(program, "lr_lookup_n"), g->n[0], g->n[1], g->n[2]);
    glUniform3fv(glGetUniformLocation(program, "lr_lookup_lo"), 1, g->lo);
    glUniform3fv(glGetUniformLocation(program, "lr_lookup_hi"), 1, g->hi);
    glUniform3fv(glGetUniformLocation(program, "lr_lookup_origin"), 1, g->origin);
    glUniform3fv(glGetUniformLocation(program, "lr_lookup_scale"), 1, g->scale);
    glUniform1i(glGetUniformLocation(program, "lr_lookup_kind"), (GLint)g->kind); /* -1 location when #defined */
    glBindTextureUnit(SL_LR_LOOKUP_UNIT_HEADS, g->heads_texture);
    glUniform1i(glGetUniformLocation(program, "lr_lookup_heads_tex"), SL_LR_LOOKUP_UNIT_HEADS);
}

void sl_lr_lookup_gpu_deinit(sl_lr_lookup_gpu *g)
{
    GLuint b[3] = {g->heads, g->nodes, g->planes};
    glDeleteBuffers(3, b);
    if (g->heads_texture)
        glDeleteTextures(1, &g->heads_texture);
    memset(g, 0, sizeof *g);
}

const char *sl_lr_lookup_glsl_define(sl_lr_lookup_kind kind)
{
    switch (kind) {
    case SL_LR_LOOKUP_TEXTURE: return "#define LR_LOOKUP_KIND 1\n";
    case SL_LR_LOOKUP_OCTREE: return "#define LR_LOOKUP_KIND 2\n";
    case SL_LR_LOOKUP_KDTREE: return "#define LR_LOOKUP_KIND 3\n";
    case SL_LR_LOOKUP_KDFOREST: return "#define LR_LOOKUP_KIND 4\n";
    default: return "";
    }
}
