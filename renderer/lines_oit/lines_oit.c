/* lines_oit.c — technique `lines_oit`: transparent rasterized tubes with
 * per-pixel linked lists and per-pixel sorting, the transparency baseline of
 * Kanzler et al. (TVCG 2018, Sec. 5.3 and Table 2; lists after Yang et al.).
 *
 * prepare builds the swept tube mesh once (lines/sl_tube_mesh.h, no caps, the
 * front half of each tube is stored, so each tube crossing a pixel gives one
 * fragment). render: pass 1 rasterizes all tubes and appends every fragment
 * to its pixel's list in a node pool; pass 2 sorts each list by depth and
 * blends front to back. The pool starts at 8 nodes per pixel and grows (the
 * frame is re-rendered) up to `fragment_memory_mb`; beyond it fragments are
 * dropped and their pixels drawn white, lists longer than 512 red (Fig. 17) —
 * the frame never fails for lack of list memory. Render thread only.
 */
#include <stdlib.h>
#include <string.h>

#include "../line_style/sl_line_style.h"
#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../lines/sl_line_gpu.h"
#include "../lines/sl_tube_mesh.h"

#define NODE_BYTES 12u
#define NIL 0x7fffffffu

static const char *const opacity_tf_choices[] = {"constant", "ramp", NULL};

static const sl_param_def lines_oit_params[] = {
    SL_LINE_STYLE_PARAMS,
    {"opacity", SL_PARAM_FLOAT, 0.0, 1.0, {0.25}, NULL, "", "per-line opacity", SL_INVALIDATE_FRAME},
    {"opacity_transfer", SL_PARAM_ENUM, 0, 0, {0}, opacity_tf_choices, "",
     "constant: every line has `opacity`; ramp: opacity x the colormap coordinate (as voxel_lines)",
     SL_INVALIDATE_FRAME},
    {"sides", SL_PARAM_INT, 3, 30, {8}, NULL, "", "vertices per tube cross-section (paper: 8)",
     SL_INVALIDATE_PREPARED},
    {"fragment_memory_mb", SL_PARAM_FLOAT, 0.01, 8192, {512}, NULL, "MB",
     "cap on the fragment list pool; pixels that lose fragments are drawn white", SL_INVALIDATE_FRAME},
    {"alpha_threshold", SL_PARAM_FLOAT, 0.5, 1.0, {1.0}, NULL, "",
     "stop blending a pixel at this opacity (1: exact reference; voxel_lines defaults to 0.99)",
     SL_INVALIDATE_FRAME},
};

typedef struct lines_oit_state {
    const sl_dataset *dataset;  /* borrowed */
    GLuint collect, resolve, vao, vbo, ibo, empty_vao, camera_ubo;
    sl_line_colors colors;      /* colormap texture + per-vertex colour scalars (SSBO 1) */
    GLuint heads_tex, counter_buf, nodes_buf;
    int heads_w, heads_h;
    size_t capacity;            /* nodes in nodes_buf */
    GLsizei index_count;
    size_t mesh_bytes, triangles;
    size_t last_fragments;      /* fragments of the last frame (stored or not) */
    sl_prepare_stats prep;      /* mesh build (CPU) and upload times */
} lines_oit_state;

static void lines_oit_release(void *opaque)
{
    lines_oit_state *s = opaque;
    if (!s)
        return;
    GLuint programs[2] = {s->collect, s->resolve};
    for (int i = 0; i < 2; i++)
        if (programs[i])
            glDeleteProgram(programs[i]);
    GLuint bufs[5] = {s->vbo, s->ibo, s->camera_ubo, s->counter_buf, s->nodes_buf};
    for (int i = 0; i < 5; i++)
        if (bufs[i])
            glDeleteBuffers(1, &bufs[i]);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->empty_vao) glDeleteVertexArrays(1, &s->empty_vao);
    sl_line_colors_deinit(&s->colors);
    if (s->heads_tex) glDeleteTextures(1, &s->heads_tex);
    free(s);
}

static sl_status lines_oit_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out,
                                   sl_err *err)
{
    (void)gpu;
    *out = NULL;
    lines_oit_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    s->dataset = ds;
    sl_status st = sl_line_style_check(params, ds, err);
    if (st != SL_OK) {
        free(s);
        return st;
    }
    sl_tube_mesh mesh;
    double t_build = sl_clock_ms();
    st = sl_tube_mesh_build(&ds->lines, sl_params_int(params, "sides"), 0, &mesh, err);
    if (st != SL_OK) {
        free(s);
        return st;
    }
    s->prep.preprocess_ms = sl_clock_ms() - t_build;
    st = sl_gl_program_create(&(sl_program_desc){.vertex = "lines_oit/lines_oit.vert.glsl",
                                                 .fragment = "lines_oit/lines_oit_collect.frag.glsl",
                                                 .label = "lines_oit_collect"},
                              &s->collect, err);
    if (st == SL_OK)
        st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                     .fragment = "lines_oit/lines_oit_resolve.frag.glsl",
                                                     .label = "lines_oit_resolve"},
                                  &s->resolve, err);
    if (st != SL_OK) {
        sl_tube_mesh_deinit(&mesh);
        lines_oit_release(s);
        return st;
    }
    double t_upload = sl_clock_ms();
    glCreateBuffers(1, &s->vbo);
    glNamedBufferStorage(s->vbo, (GLsizeiptr)((mesh.vertex_count ? mesh.vertex_count : 1) * sizeof(sl_tube_vertex)),
                         mesh.vertex_count ? mesh.vertices : NULL, 0);
    glCreateBuffers(1, &s->ibo);
    glNamedBufferStorage(s->ibo, (GLsizeiptr)((mesh.index_count ? mesh.index_count : 1) * sizeof(uint32_t)),
                         mesh.index_count ? mesh.indices : NULL, 0);
    glCreateVertexArrays(1, &s->vao);
    glVertexArrayVertexBuffer(s->vao, 0, s->vbo, 0, sizeof(sl_tube_vertex));
    glVertexArrayElementBuffer(s->vao, s->ibo);
    glEnableVertexArrayAttrib(s->vao, 0);
    glVertexArrayAttribFormat(s->vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(sl_tube_vertex, centre));
    glVertexArrayAttribBinding(s->vao, 0, 0);
    glEnableVertexArrayAttrib(s->vao, 1);
    glVertexArrayAttribFormat(s->vao, 1, 3, GL_FLOAT, GL_FALSE, offsetof(sl_tube_vertex, offset));
    glVertexArrayAttribBinding(s->vao, 1, 0);
    glEnableVertexArrayAttrib(s->vao, 2);
    glVertexArrayAttribFormat(s->vao, 2, 3, GL_FLOAT, GL_FALSE, offsetof(sl_tube_vertex, normal));
    glVertexArrayAttribBinding(s->vao, 2, 0);
    glEnableVertexArrayAttrib(s->vao, 4);
    glVertexArrayAttribIFormat(s->vao, 4, 1, GL_UNSIGNED_INT, offsetof(sl_tube_vertex, source));
    glVertexArrayAttribBinding(s->vao, 4, 0);
    glCreateVertexArrays(1, &s->empty_vao);
    glCreateBuffers(1, &s->counter_buf);
    glNamedBufferStorage(s->counter_buf, sizeof(GLuint), NULL, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    s->index_count = (GLsizei)mesh.index_count;
    s->triangles = mesh.index_count / 3;
    s->mesh_bytes = mesh.vertex_count * sizeof(sl_tube_vertex) + mesh.index_count * sizeof(uint32_t);
    sl_tube_mesh_deinit(&mesh);
    st = sl_line_colors_init(&s->colors, ds->lines.vertex_count, 1, "lines_oit", err);
    if (st != SL_OK) {
        lines_oit_release(s);
        return st;
    }
    s->mesh_bytes += sl_line_colors_bytes(&s->colors); /* colour scalars and the colormap texture */
    glFinish();
    s->prep.upload_ms = sl_clock_ms() - t_upload;
    st = sl_gl_check_errors("lines_oit: uploading the mesh", err);
    if (st != SL_OK) {
        lines_oit_release(s);
        return st;
    }
    *out = s;
    return SL_OK;
}

/* The per-pixel heads and the node pool at this size; SL_ERR_GPU when GL could not allocate them. */
static sl_status ensure_pool(lines_oit_state *s, int w, int h, size_t nodes, sl_err *err)
{
    if (s->heads_w != w || s->heads_h != h) {
        if (s->heads_tex)
            glDeleteTextures(1, &s->heads_tex);
        glCreateTextures(GL_TEXTURE_2D, 1, &s->heads_tex);
        glTextureStorage2D(s->heads_tex, 1, GL_R32UI, w, h);
        s->heads_w = w;
        s->heads_h = h;
    }
    if (nodes != s->capacity) {
        if (s->nodes_buf)
            glDeleteBuffers(1, &s->nodes_buf);
        glCreateBuffers(1, &s->nodes_buf);
        glNamedBufferStorage(s->nodes_buf, (GLsizeiptr)(nodes * NODE_BYTES), NULL, 0);
        s->capacity = nodes;
    }
    sl_status st = sl_gl_check_errors("lines_oit: fragment lists", err);
    if (st != SL_OK)
        s->heads_w = s->heads_h = 0, s->capacity = 0; /* allocate again next frame */
    return st;
}

static void draw_lists(lines_oit_state *s, const sl_params *params, const sl_line_style *style)
{
    const GLuint nil = NIL, zero = 0;
    glClearTexImage(s->heads_tex, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &nil);
    glNamedBufferSubData(s->counter_buf, 0, sizeof zero, &zero);
    float opacity = (float)sl_params_float(params, "opacity");
    GLuint p = s->collect;
    glUseProgram(p);
    sl_line_style_uniforms(p, style, 0);
    glUniform1ui(glGetUniformLocation(p, "u_capacity"), (GLuint)s->capacity);
    glUniform1f(glGetUniformLocation(p, "u_opacity"), opacity);
    glUniform1i(glGetUniformLocation(p, "u_opacity_ramp"),
                style->attribute >= 0 && sl_params_choice(params, "opacity_transfer") == 1);
    sl_line_colors_bind(&s->colors, 0, 1);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->nodes_buf);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, 0, s->counter_buf);
    glBindImageTexture(0, s->heads_tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    /* On a multisampled target a triangle makes a fragment wherever it covers any
     * sample, so every pixel an inner mesh edge (or a silhouette) passes through
     * would get one node from each triangle: the same tube crossing stored twice
     * and tubes widened by up to half a pixel. Single-sample rasterization (pixel
     * centre) gives one node per crossing, as in a single-sample frame. */
    glDisable(GL_MULTISAMPLE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glBindVertexArray(s->vao);
    glDrawElements(GL_TRIANGLES, s->index_count, GL_UNSIGNED_INT, NULL);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glEnable(GL_MULTISAMPLE);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT |
                    GL_ATOMIC_COUNTER_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    GLuint used = 0;
    glGetNamedBufferSubData(s->counter_buf, 0, sizeof used, &used);
    s->last_fragments = used;
}

static void resolve(lines_oit_state *s, const sl_params *params)
{
    GLuint p = s->resolve;
    glUseProgram(p);
    glUniform1f(glGetUniformLocation(p, "u_alpha_stop"), (float)sl_params_float(params, "alpha_threshold"));
    glBindImageTexture(0, s->heads_tex, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->nodes_buf);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glBindVertexArray(s->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
}

static sl_status lines_oit_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                                  sl_render_stats *stats, sl_err *err)
{
    (void)target;
    lines_oit_state *s = opaque;
    sl_status st = sl_line_style_check(params, s->dataset, err);
    if (st != SL_OK)
        return st;
    sl_line_style style;
    sl_line_style_read(params, s->dataset, &style);
    sl_line_colors_update(&s->colors, &s->dataset->lines, &style);
    size_t cap_nodes = (size_t)(sl_params_float(params, "fragment_memory_mb") * 1024.0 * 1024.0 / NODE_BYTES);
    if (cap_nodes < 1)
        cap_nodes = 1;
    size_t want = s->capacity ? s->capacity : (size_t)view->width * view->height * 8u;
    if (want > cap_nodes)
        want = cap_nodes;
    st = ensure_pool(s, view->width, view->height, want, err);
    if (st != SL_OK)
        return st;
    sl_camera_ubo_update(&s->camera_ubo, view);
    draw_lists(s, params, &style);
    if (s->last_fragments > s->capacity && s->capacity < cap_nodes) {
        /* Grow to what this frame needs (plus a margin) and draw again. */
        size_t need = s->last_fragments + s->last_fragments / 4;
        if ((st = ensure_pool(s, view->width, view->height, need < cap_nodes ? need : cap_nodes, err)) != SL_OK)
            return st;
        draw_lists(s, params, &style);
    }
    resolve(s, params);
    stats->primitives = (double)s->triangles;
    return SL_OK;
}

static void lines_oit_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const lines_oit_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

static size_t lines_oit_gpu_bytes(const void *opaque)
{
    const lines_oit_state *s = opaque;
    if (!s)
        return 0;
    return s->mesh_bytes + s->capacity * NODE_BYTES + (size_t)s->heads_w * s->heads_h * 4u;
}

const sl_technique sl_lines_oit_technique = {
    .name = "lines_oit",
    .description = "transparent rasterized tubes, per-pixel linked lists sorted per pixel (baseline of Kanzler et al. 2018)",
    .dataset_kinds = SL_DATASET_LINES,
    .params = lines_oit_params,
    .param_count = (int)(sizeof lines_oit_params / sizeof lines_oit_params[0]),
    .prepare = lines_oit_prepare,
    .render = lines_oit_render,
    .release = lines_oit_release,
    .gpu_bytes = lines_oit_gpu_bytes,
    .prepare_stats = lines_oit_prepare_stats,
};
