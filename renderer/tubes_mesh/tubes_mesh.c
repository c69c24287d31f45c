/* tubes_mesh.c — technique `tubes_mesh`: rasterized tubes swept along polylines.
 *
 * The tessellation baseline of the spline-tube (Russig et al.) and voxel-line
 * (Kanzler et al.) papers, and the first thing a user sees. prepare builds
 * the mesh on the CPU (lines/tube_mesh.c) and uploads it once; the radius
 * and every shading parameter are uniforms, so only `sides`, `caps` and
 * `radius_attribute` (per-vertex radii |value| from an attribute, baked into
 * the mesh like the data's own radii) re-prepare. One indexed draw per frame. `opacity` (shared by name with
 * voxel_lines and lines_oit) is 1 = opaque; below 1 the front halves of the
 * tubes are blended in draw order without sorting and without depth writes —
 * order-dependent and only approximate where tubes overlap (lines_oit is the
 * sorted reference). Render thread only.
 */
#include <stdlib.h>
#include <string.h>

#include "../line_style/sl_line_style.h"
#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../lines/sl_line_gpu.h"
#include "../lines/sl_lines_prep.h"
#include "../lines/sl_tube_mesh.h"

static const sl_param_def tubes_mesh_params[] = {
    SL_LINE_STYLE_PARAMS,
    SL_LINE_STYLE_RADIUS_ATTRIBUTE_PARAM,
    {"sides", SL_PARAM_INT, 6, 30, {12}, NULL, "", "vertices per cross-section", SL_INVALIDATE_PREPARED},
    {"caps", SL_PARAM_BOOL, 0, 1, {1}, NULL, "", "close tube ends with flat caps", SL_INVALIDATE_PREPARED},
    {"opacity", SL_PARAM_FLOAT, 0.0, 1.0, {1.0}, NULL, "",
     "1 = opaque; below 1 the tubes' front halves are blended in draw order (unsorted, no depth writes: "
     "order-dependent; lines_oit sorts)", SL_INVALIDATE_FRAME},
};

typedef struct tubes_mesh_state {
    const sl_dataset *dataset;  /* borrowed */
    GLuint program, vao, vbo, ibo, camera_ubo;
    sl_line_colors colors;      /* colormap texture + the chosen attribute's per-vertex values (SSBO 1) */
    GLsizei index_count;
    size_t gpu_bytes;
    size_t triangles;
    sl_prepare_stats prep;      /* mesh build (CPU) and upload times */
} tubes_mesh_state;

static void tubes_mesh_release(void *opaque)
{
    tubes_mesh_state *s = opaque;
    if (!s)
        return;
    if (s->program) glDeleteProgram(s->program);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->vbo) glDeleteBuffers(1, &s->vbo);
    if (s->ibo) glDeleteBuffers(1, &s->ibo);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    sl_line_colors_deinit(&s->colors);
    free(s);
}

static sl_status tubes_mesh_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params,
                                    void **out, sl_err *err)
{
    (void)gpu;
    *out = NULL;
    tubes_mesh_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    s->dataset = ds;
    sl_status st = sl_line_style_check(params, ds, err);
    if (st != SL_OK) {
        free(s);
        return st;
    }
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    double t_build = sl_clock_ms();
    sl_lines lines = ds->lines; /* a view: only the radii may differ */
    float *attribute_radii = NULL;
    if (style.radius_attribute >= 0) {
        attribute_radii = malloc((ds->lines.vertex_count ? ds->lines.vertex_count : 1) * sizeof *attribute_radii);
        if (!attribute_radii) {
            free(s);
            return sl_err_set(err, SL_ERR_NOMEM, "tubes_mesh: out of memory for %zu radii", ds->lines.vertex_count);
        }
        sl_lines_attribute_radii(&ds->lines, style.radius_attribute, attribute_radii, 1);
        lines.radii = attribute_radii;
    }
    sl_tube_mesh mesh;
    st = sl_tube_mesh_build(&lines, sl_params_int(params, "sides"), sl_params_bool(params, "caps"), &mesh, err);
    free(attribute_radii);
    if (st != SL_OK) {
        free(s);
        return st;
    }
    s->prep.preprocess_ms = sl_clock_ms() - t_build;
    st = sl_gl_program_create(&(sl_program_desc){
        .vertex = "tubes_mesh/tubes_mesh.vert.glsl",
        .fragment = "tubes_mesh/tubes_mesh.frag.glsl",
        .label = "tubes_mesh"}, &s->program, err);
    if (st != SL_OK) {
        sl_tube_mesh_deinit(&mesh);
        tubes_mesh_release(s);
        return st;
    }
    double t_upload = sl_clock_ms();
    glCreateBuffers(1, &s->vbo);
    /* Empty meshes still get a (1-element) buffer so the VAO is complete. */
    glNamedBufferStorage(s->vbo, (GLsizeiptr)((mesh.vertex_count ? mesh.vertex_count : 1) * sizeof(sl_tube_vertex)),
                         mesh.vertex_count ? mesh.vertices : NULL, 0);
    glCreateBuffers(1, &s->ibo);
    glNamedBufferStorage(s->ibo, (GLsizeiptr)((mesh.index_count ? mesh.index_count : 1) * sizeof(uint32_t)),
                         mesh.index_count ? mesh.indices : NULL, 0);
    glCreateVertexArrays(1, &s->vao);
    glVertexArrayVertexBuffer(s->vao, 0, s->vbo, 0, sizeof(sl_tube_vertex));
    glVertexArrayElementBuffer(s->vao, s->ibo);
    const GLuint offsets[5] = {offsetof(sl_tube_vertex, centre), offsetof(sl_tube_vertex, offset),
                               offsetof(sl_tube_vertex, normal), offsetof(sl_tube_vertex, radius),
                               offsetof(sl_tube_vertex, source)};
    const GLint sizes[5] = {3, 3, 3, 1, 1};
    for (GLuint a = 0; a < 5; a++) {
        glEnableVertexArrayAttrib(s->vao, a);
        if (a == 4)
            glVertexArrayAttribIFormat(s->vao, a, 1, GL_UNSIGNED_INT, offsets[a]);
        else
            glVertexArrayAttribFormat(s->vao, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
        glVertexArrayAttribBinding(s->vao, a, 0);
    }
    s->index_count = (GLsizei)mesh.index_count;
    s->triangles = mesh.index_count / 3;
    size_t mesh_bytes = mesh.vertex_count * sizeof(sl_tube_vertex) + mesh.index_count * sizeof(uint32_t);
    sl_tube_mesh_deinit(&mesh);
    st = sl_line_colors_init(&s->colors, ds->lines.vertex_count, 1, "tubes_mesh", err);
    if (st != SL_OK) {
        tubes_mesh_release(s);
        return st;
    }
    s->gpu_bytes = mesh_bytes + sl_line_colors_bytes(&s->colors);
    glFinish();
    s->prep.upload_ms = sl_clock_ms() - t_upload;
    st = sl_gl_check_errors("tubes_mesh: uploading the mesh", err);
    if (st != SL_OK) {
        tubes_mesh_release(s);
        return st;
    }
    *out = s;
    return SL_OK;
}

static sl_status tubes_mesh_render(void *opaque, const sl_view *view, const sl_params *params,
                                   sl_target *target, sl_render_stats *stats, sl_err *err)
{
    (void)target;
    tubes_mesh_state *s = opaque;
    sl_status st = sl_line_style_check(params, s->dataset, err);
    if (st != SL_OK)
        return st;
    sl_line_style style;
    sl_line_style_read(params, s->dataset, &style);
    sl_line_colors_update(&s->colors, &s->dataset->lines, &style);
    sl_line_colors_bind(&s->colors, 0, 1);
    sl_camera_ubo_update(&s->camera_ubo, view);
    glUseProgram(s->program);
    sl_line_style_uniforms(s->program, &style, 0);
    float opacity = (float)sl_params_float(params, "opacity");
    int blend = opacity < 1.0f;
    glUniform1f(glGetUniformLocation(s->program, "u_opacity"), opacity);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    /* Translucent: premultiplied colour over what is there, in draw order;
     * no depth writes, so farther tubes are not hidden by nearer ones. */
    glDepthMask(blend ? GL_FALSE : GL_TRUE);
    if (blend) {
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    } else {
        glDisable(GL_BLEND);
    }
    glDisable(GL_CULL_FACE); /* caps and mantles are seen from inside too */
    glBindVertexArray(s->vao);
    glDrawElements(GL_TRIANGLES, s->index_count, GL_UNSIGNED_INT, NULL);
    glBindVertexArray(0);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    stats->primitives = (double)s->triangles;
    return SL_OK;
}

static void tubes_mesh_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const tubes_mesh_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

static size_t tubes_mesh_gpu_bytes(const void *opaque)
{
    const tubes_mesh_state *s = opaque;
    return s ? s->gpu_bytes : 0;
}

const sl_technique sl_tubes_mesh_technique = {
    .name = "tubes_mesh",
    .description = "rasterized tubes swept along polylines (tessellation baseline)",
    .dataset_kinds = SL_DATASET_LINES,
    .params = tubes_mesh_params,
    .param_count = (int)(sizeof tubes_mesh_params / sizeof tubes_mesh_params[0]),
    .prepare = tubes_mesh_prepare,
    .render = tubes_mesh_render,
    .release = tubes_mesh_release,
    .gpu_bytes = tubes_mesh_gpu_bytes,
    .prepare_stats = tubes_mesh_prepare_stats,
};
