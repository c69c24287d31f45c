/* ribbons_gpu.c — GL objects and per-chunk draw ranges of the four `ribbons` pipelines (see ribbons_gpu.h).
 *
 * Index patterns and the mesh come from the one topology of ribbons_mesh.c.
 * The geometry shader's output limit: 21 components per emitted vertex
 * (gl_Position 4 + the 17 floats of ribbons_vertex.glsl); an invocation of c
 * quads emits 2 (c + 1) vertices, so the smallest invocation count I whose
 * c = ceil(N / I) fits GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS and
 * GL_MAX_GEOMETRY_OUTPUT_VERTICES is compiled in (RB_GS_INVOCATIONS,
 * RB_GS_COLUMNS). Render thread only.
 */
#include "ribbons_gpu.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ribbons_mesh.h"
#include "../core/sl_clock.h"
#include "../gpu/sl_gpu.h"

#define RB_GS_COMPONENTS 21

static GLuint buffer_create(rb_gpu *g, size_t bytes, const void *data)
{
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(bytes ? bytes : 4), bytes ? data : NULL, 0);
    g->buffers[g->buffer_count++] = b;
    g->buffer_bytes += bytes ? bytes : 4;
    return b;
}

static void point_buffers_create(rb_gpu *g, const sl_ribbons_points *pts)
{
    const float *arrays[3] = {pts->pos_radius, pts->normal_twist, pts->tangent_slope};
    for (int i = 0; i < 3; i++)
        g->point_buffers[i] = buffer_create(g, pts->count * 4 * sizeof(float), arrays[i]);
}

/* A u16 pattern: `segments` ring-to-ring strips of `columns` quads (N slots
 * per ring), then with caps the start and the end cap fan of ring 0. */
static sl_status pattern_create(rb_gpu *g, int N, int columns, unsigned segments, int caps, GLuint *ibo,
                                uintptr_t cap_offsets[2], sl_err *err)
{
    size_t cap = caps ? 3u * (size_t)(N - 2) : 0, count = 6u * (size_t)columns * segments + 2 * cap;
    uint32_t *wide = malloc(count * sizeof *wide);
    uint16_t *idx = malloc(count * sizeof *idx);
    if (!wide || !idx) {
        free(wide);
        free(idx);
        return sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory for the index pattern");
    }
    size_t k = 0;
    for (unsigned s = 0; s < segments; s++)
        k += sl_ribbons_quad_indices(s * (uint32_t)N, (s + 1) * (uint32_t)N, N, columns, wide + k);
    if (caps) {
        cap_offsets[0] = k * sizeof *idx;
        k += sl_ribbons_cap_indices(0, N, 0, wide + k);
        cap_offsets[1] = k * sizeof *idx;
        k += sl_ribbons_cap_indices(0, N, 1, wide + k);
    }
    for (size_t i = 0; i < k; i++)
        idx[i] = (uint16_t)wide[i];
    *ibo = buffer_create(g, k * sizeof *idx, idx);
    free(wide);
    free(idx);
    return SL_OK;
}

/* Cap ranges of the pattern scheme: basevertex = the ring's first vertex. */
static void pattern_caps(rb_gpu *g, size_t c, const sl_line_chunk *ch, unsigned caps, const uintptr_t offsets[2])
{
    GLsizei count = 3 * (g->sides - 2);
    if (caps & SL_RIBBONS_CAP_START)
        g->caps[2 * c] = (rb_range){count, (GLint)(ch->first_point * (uint32_t)g->sides), offsets[0]};
    if (caps & SL_RIBBONS_CAP_END)
        g->caps[2 * c + 1] =
            (rb_range){count, (GLint)((ch->first_point + ch->segments) * (uint32_t)g->sides), offsets[1]};
}

static void pass_init(rb_pass *p, GLuint program, GLuint vao, GLenum mode, GLenum index_type, int cap)
{
    p->program = program;
    p->vao = vao;
    p->mode = mode;
    p->index_type = index_type;
    p->cap = cap;
    p->cull_faces = 1;
}

static sl_status program_add(rb_gpu *g, const sl_program_desc *desc, GLuint *out, sl_err *err)
{
    GLuint p = 0;
    double t0 = sl_clock_ms();
    sl_status st = sl_gl_program_create(desc, &p, err);
    g->compile_ms += sl_clock_ms() - t0;
    if (st == SL_OK)
        g->programs[g->program_count++] = p;
    *out = p;
    return st;
}

static sl_status pull_program(rb_gpu *g, GLuint *out, sl_err *err)
{
    return program_add(g, &(sl_program_desc){.vertex = "ribbons/ribbons_pull.vert.glsl",
                                             .fragment = "ribbons/ribbons.frag.glsl", .label = "ribbons"},
                       out, err);
}

/* Smallest invocation count whose strips fit the geometry shader limits. */
static sl_status gs_split(int N, int *invocations, int *columns, sl_err *err)
{
    GLint total = 0, max_vertices = 0, max_invocations = 0;
    glGetIntegerv(GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS, &total);
    glGetIntegerv(GL_MAX_GEOMETRY_OUTPUT_VERTICES, &max_vertices);
    glGetIntegerv(GL_MAX_GEOMETRY_SHADER_INVOCATIONS, &max_invocations);
    for (int I = 1; I <= N && I <= max_invocations; I++) {
        int c = (N + I - 1) / I, v = 2 * (c + 1);
        if (v * RB_GS_COMPONENTS <= total && v <= max_vertices) {
            *columns = c;
            *invocations = (N + c - 1) / c; /* no empty invocation */
            return SL_OK;
        }
    }
    return sl_err_set(err, SL_ERR_LIMIT,
                      "ribbons: pipeline geometry cannot emit a ring of %d sides (GL limits: %d output components, "
                      "%d vertices, %d invocations); lower 'sides' or use pipeline pulling",
                      N, (int)total, (int)max_vertices, (int)max_invocations);
}

static sl_status build_pulling(rb_gpu *g, const sl_ribbons_points *pts, const sl_lines *l,
                               const sl_line_chunk *chunks, size_t chunk_count, sl_err *err)
{
    const int N = g->sides;
    GLuint program, ibo;
    uintptr_t cap_offsets[2] = {0, 0};
    sl_status st = pull_program(g, &program, err);
    if (st == SL_OK)
        st = pattern_create(g, N, N, RB_CHUNK_SEGMENTS, 1, &ibo, cap_offsets, err);
    if (st != SL_OK)
        return st;
    point_buffers_create(g, pts);
    glCreateVertexArrays(1, &g->vaos[0]);
    glVertexArrayElementBuffer(g->vaos[0], ibo);
    pass_init(&g->passes[0], program, g->vaos[0], GL_TRIANGLES, GL_UNSIGNED_SHORT, 0);
    pass_init(&g->passes[1], program, g->vaos[0], GL_TRIANGLES, GL_UNSIGNED_SHORT, 1);
    for (size_t c = 0; c < chunk_count; c++) {
        const sl_line_chunk *ch = &chunks[c];
        g->mantle[c] = (rb_range){(GLsizei)(6u * (unsigned)N * ch->segments), (GLint)(ch->first_point * (uint32_t)N), 0};
        pattern_caps(g, c, ch, sl_ribbons_chunk_caps(l, ch), cap_offsets);
    }
    return SL_OK;
}

static sl_status build_flat(rb_gpu *g, const sl_ribbons_points *pts, const sl_line_chunk *chunks,
                            size_t chunk_count, sl_err *err)
{
    GLuint program, ibo;
    uintptr_t unused[2];
    sl_status st = pull_program(g, &program, err);
    if (st == SL_OK)
        st = pattern_create(g, 2, 1, RB_CHUNK_SEGMENTS, 0, &ibo, unused, err);
    if (st != SL_OK)
        return st;
    point_buffers_create(g, pts);
    glCreateVertexArrays(1, &g->vaos[0]);
    glVertexArrayElementBuffer(g->vaos[0], ibo);
    pass_init(&g->passes[0], program, g->vaos[0], GL_TRIANGLES, GL_UNSIGNED_SHORT, 0);
    g->passes[0].cull_faces = 0; /* two-sided */
    for (size_t c = 0; c < chunk_count; c++)
        g->mantle[c] = (rb_range){(GLsizei)(6u * chunks[c].segments), (GLint)(chunks[c].first_point * 2u), 0};
    return SL_OK;
}

static sl_status build_geometry(rb_gpu *g, const sl_ribbons_points *pts, const sl_lines *l,
                                const sl_line_chunk *chunks, size_t chunk_count, sl_err *err)
{
    const int N = g->sides;
    sl_status st = gs_split(N, &g->gs_invocations, &g->gs_columns, err);
    if (st != SL_OK)
        return st;
    char defines[96];
    snprintf(defines, sizeof defines, "#define RB_GS_INVOCATIONS %d\n#define RB_GS_COLUMNS %d\n", g->gs_invocations,
             g->gs_columns);
    GLuint gs_program, cap_program, cap_ibo;
    uintptr_t cap_offsets[2] = {0, 0};
    st = program_add(g, &(sl_program_desc){.vertex = "ribbons/ribbons_geom.vert.glsl",
                                           .geometry = "ribbons/ribbons.geom.glsl",
                                           .fragment = "ribbons/ribbons.frag.glsl", .defines = defines,
                                           .label = "ribbons (geometry)"},
                     &gs_program, err);
    if (st == SL_OK)
        st = pull_program(g, &cap_program, err);
    if (st == SL_OK)
        st = pattern_create(g, N, N, 0, 1, &cap_ibo, cap_offsets, err);
    if (st != SL_OK)
        return st;
    double t0 = sl_clock_ms();
    size_t segments = 0;
    for (size_t c = 0; c < chunk_count; c++)
        segments += chunks[c].segments;
    uint32_t *pairs = malloc((segments ? segments : 1) * 2 * sizeof *pairs);
    if (!pairs)
        return sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory for %zu segment pairs", segments);
    size_t k = 0;
    for (size_t c = 0; c < chunk_count; c++) {
        const sl_line_chunk *ch = &chunks[c];
        g->mantle[c] = (rb_range){(GLsizei)(2u * ch->segments), 0, k * sizeof *pairs};
        for (uint32_t s = 0; s < ch->segments; s++) {
            pairs[k++] = ch->first_point + s;
            pairs[k++] = ch->first_point + s + 1;
        }
        pattern_caps(g, c, ch, sl_ribbons_chunk_caps(l, ch), cap_offsets);
    }
    g->cpu_ms = sl_clock_ms() - t0;
    GLuint pair_ibo = buffer_create(g, k * sizeof *pairs, pairs);
    free(pairs);
    point_buffers_create(g, pts);
    glCreateVertexArrays(2, g->vaos);
    glVertexArrayElementBuffer(g->vaos[0], pair_ibo);
    glVertexArrayElementBuffer(g->vaos[1], cap_ibo);
    pass_init(&g->passes[0], gs_program, g->vaos[0], GL_LINES, GL_UNSIGNED_INT, 0);
    g->passes[0].clockwise = 1; /* the strip reverses the pattern's winding (ribbons.geom.glsl) */
    pass_init(&g->passes[1], cap_program, g->vaos[1], GL_TRIANGLES, GL_UNSIGNED_SHORT, 1);
    return SL_OK;
}

static sl_status build_mesh(rb_gpu *g, const sl_ribbons_points *pts, const sl_lines *l,
                            const sl_line_chunk *chunks, size_t chunk_count, sl_err *err)
{
    const int N = g->sides;
    GLuint program;
    sl_status st = program_add(g, &(sl_program_desc){.vertex = "ribbons/ribbons_mesh.vert.glsl",
                                                     .fragment = "ribbons/ribbons.frag.glsl",
                                                     .label = "ribbons (mesh)"},
                               &program, err);
    if (st != SL_OK)
        return st;
    sl_ribbons_mesh m;
    double t0 = sl_clock_ms();
    st = sl_ribbons_mesh_build(pts, l, chunks, chunk_count, N, &m, err);
    g->cpu_ms = sl_clock_ms() - t0;
    if (st != SL_OK)
        return st;
    const GLsizei cap = 3 * (N - 2);
    for (size_t c = 0; c < chunk_count; c++) {
        const sl_line_chunk *ch = &chunks[c];
        size_t first = m.chunk_first[c], mantle = 6u * (size_t)N * ch->segments;
        unsigned caps = sl_ribbons_chunk_caps(l, ch);
        g->mantle[c] = (rb_range){(GLsizei)mantle, 0, first * sizeof *m.indices};
        first += mantle;
        if (caps & SL_RIBBONS_CAP_START) {
            g->caps[2 * c] = (rb_range){cap, 0, first * sizeof *m.indices};
            first += (size_t)cap;
        }
        if (caps & SL_RIBBONS_CAP_END)
            g->caps[2 * c + 1] = (rb_range){cap, 0, first * sizeof *m.indices};
    }
    GLuint vbo = buffer_create(g, m.vertex_count * sizeof *m.vertices, m.vertices);
    GLuint ibo = buffer_create(g, m.index_count * sizeof *m.indices, m.indices);
    sl_ribbons_mesh_deinit(&m);
    GLuint vao;
    glCreateVertexArrays(1, &vao);
    g->vaos[0] = vao;
    glVertexArrayVertexBuffer(vao, 0, vbo, 0, (GLsizei)sizeof(sl_ribbons_mesh_vertex));
    glVertexArrayElementBuffer(vao, ibo);
    const GLuint offsets[3] = {offsetof(sl_ribbons_mesh_vertex, pos_radius),
                               offsetof(sl_ribbons_mesh_vertex, normal_twist),
                               offsetof(sl_ribbons_mesh_vertex, tangent_slope)};
    for (GLuint a = 0; a < 3; a++) {
        glEnableVertexArrayAttrib(vao, a);
        glVertexArrayAttribFormat(vao, a, 4, GL_FLOAT, GL_FALSE, offsets[a]);
        glVertexArrayAttribBinding(vao, a, 0);
    }
    glEnableVertexArrayAttrib(vao, 3);
    glVertexArrayAttribIFormat(vao, 3, 2, GL_UNSIGNED_INT, offsetof(sl_ribbons_mesh_vertex, point));
    glVertexArrayAttribBinding(vao, 3, 0);
    pass_init(&g->passes[0], program, vao, GL_TRIANGLES, GL_UNSIGNED_INT, 0);
    pass_init(&g->passes[1], program, vao, GL_TRIANGLES, GL_UNSIGNED_INT, 1);
    return SL_OK;
}

sl_status rb_gpu_build(rb_gpu *g, rb_pipeline pipeline, int sides, const sl_ribbons_points *pts, const sl_lines *l,
                       const sl_line_chunk *chunks, size_t chunk_count, sl_err *err)
{
    memset(g, 0, sizeof *g);
    g->pipeline = pipeline;
    g->sides = pipeline == RB_PIPELINE_FLAT ? 2 : sides;
    /* Pattern draws address vertex point * N through basevertex and gl_VertexID (GLint). */
    if (pipeline != RB_PIPELINE_MESH && pts->count > (size_t)INT32_MAX / (size_t)g->sides)
        return sl_err_set(err, SL_ERR_LIMIT,
                          "ribbons: %zu points x %d ring vertices exceed the 2^31 vertex ids of pipeline %s; lower "
                          "'sides'", pts->count, g->sides, pipeline == RB_PIPELINE_FLAT ? "flat" : "pulling/geometry");
    for (int j = 0; j < g->sides; j++) {
        double phi = pipeline == RB_PIPELINE_FLAT ? M_PI * (2 * j - 1) / 2.0 : 2.0 * M_PI * j / g->sides;
        g->ring[2 * j] = pipeline == RB_PIPELINE_FLAT ? 0.0f : (float)cos(phi);
        g->ring[2 * j + 1] = (float)sin(phi);
    }
    size_t n = chunk_count ? chunk_count : 1;
    g->mantle = calloc(n, sizeof *g->mantle);
    g->caps = calloc(2 * n, sizeof *g->caps);
    g->triangles = calloc(n, sizeof *g->triangles);
    int ok = g->mantle && g->caps && g->triangles;
    for (int p = 0; p < 2 && ok; p++) {
        size_t m = p ? 2 * n : n;
        g->passes[p].counts = malloc(m * sizeof *g->passes[p].counts);
        g->passes[p].bases = malloc(m * sizeof *g->passes[p].bases);
        g->passes[p].offsets = malloc(m * sizeof *g->passes[p].offsets);
        ok = g->passes[p].counts && g->passes[p].bases && g->passes[p].offsets;
    }
    if (!ok) {
        rb_gpu_release(g);
        return sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory for %zu chunks", chunk_count);
    }
    sl_status st;
    switch (pipeline) {
    case RB_PIPELINE_GEOMETRY: st = build_geometry(g, pts, l, chunks, chunk_count, err); break;
    case RB_PIPELINE_MESH: st = build_mesh(g, pts, l, chunks, chunk_count, err); break;
    case RB_PIPELINE_FLAT: st = build_flat(g, pts, chunks, chunk_count, err); break;
    default: st = build_pulling(g, pts, l, chunks, chunk_count, err); break;
    }
    if (st == SL_OK)
        st = sl_gl_check_errors("ribbons: uploading the geometry", err);
    if (st != SL_OK) {
        rb_gpu_release(g);
        return st;
    }
    /* Triangles per chunk: two per quad (N quads a segment; flat one), N - 2 per cap. */
    const int quads = pipeline == RB_PIPELINE_FLAT ? 1 : g->sides;
    for (size_t c = 0; c < chunk_count; c++)
        g->triangles[c] = 2.0 * quads * chunks[c].segments +
                          (g->sides - 2) * (double)((g->caps[2 * c].count > 0) + (g->caps[2 * c + 1].count > 0));
    return SL_OK;
}

static void pass_add(rb_pass *p, const rb_range *r)
{
    if (!p->program || r->count == 0)
        return;
    p->counts[p->drawcount] = r->count;
    p->bases[p->drawcount] = r->base;
    p->offsets[p->drawcount++] = (const void *)r->offset;
}

void rb_gpu_add_chunk(rb_gpu *g, size_t c)
{
    pass_add(&g->passes[0], &g->mantle[c]);
    pass_add(&g->passes[1], &g->caps[2 * c]);
    pass_add(&g->passes[1], &g->caps[2 * c + 1]);
}

void rb_gpu_draw(const rb_gpu *g)
{
    for (GLuint i = 0; i < 3; i++)
        if (g->point_buffers[i])
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2 + i, g->point_buffers[i]);
    for (int i = 0; i < 2; i++) {
        const rb_pass *p = &g->passes[i];
        if (!p->program || p->drawcount == 0)
            continue;
        glUseProgram(p->program);
        glUniform1i(glGetUniformLocation(p->program, "u_cap"), p->cap);
        if (p->cull_faces) {
            glEnable(GL_CULL_FACE);
            glCullFace(GL_BACK);
        } else {
            glDisable(GL_CULL_FACE);
        }
        glFrontFace(p->clockwise ? GL_CW : GL_CCW);
        glBindVertexArray(p->vao);
        glMultiDrawElementsBaseVertex(p->mode, p->counts, p->index_type, p->offsets, p->drawcount, p->bases);
    }
    glBindVertexArray(0);
    glDisable(GL_CULL_FACE);
    glFrontFace(GL_CCW);
}

void rb_gpu_release(rb_gpu *g)
{
    for (int i = 0; i < g->program_count; i++)
        glDeleteProgram(g->programs[i]);
    for (int i = 0; i < 2; i++)
        if (g->vaos[i])
            glDeleteVertexArrays(1, &g->vaos[i]);
    if (g->buffer_count)
        glDeleteBuffers(g->buffer_count, g->buffers);
    free(g->mantle);
    free(g->caps);
    free(g->triangles);
    for (int i = 0; i < 2; i++) {
        free(g->passes[i].counts);
        free(g->passes[i].bases);
        free(g->passes[i].offsets);
    }
    memset(g, 0, sizeof *g);
}
