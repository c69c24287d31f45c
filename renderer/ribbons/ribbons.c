/* ribbons.c — technique `ribbons`: elliptic ribbons, silhouette-point halos and twist lines.
 *
 * Neuhauser, Wang, Kern, Westermann, "Efficient high-quality rendering of
 * ribbons and twisted lines": generalized cylinders of elliptic profile
 * (Sec. 3.1) drawn by programmable pulling (Sec. 5): three std430 buffers of
 * per-point data (ribbons_prep.c) and one u16 chunk-pattern index buffer of
 * K segments (plus the two caps) drawn per chunk with
 * glMultiDrawElementsBaseVertex; the vertex shader derives point and ring
 * from gl_VertexID. Only `pulling` exists so far (geometry, mesh and flat
 * are not listed until they work). Width, min_pixels widening (Sec. 7.2),
 * halos (Sec. 3.2), twist lines (Sec. 4), the depth cue and the whole line
 * style are uniforms; per frame only the chunk culling and the multi-draw
 * arrays in client memory are rebuilt — no GL buffer is written on a camera
 * move. Render thread only. Plan: docs/ribbons_plan.md §1, §3.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ribbons_prep.h"
#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../line_style/sl_line_style.h"
#include "../lines/sl_line_gpu.h"
#include "../lines/sl_lines_prep.h"

#define RB_CHUNK_SEGMENTS 64u   /* K: 65 rings of <= 32 vertices fit u16 indices */
#define RB_MAX_SIDES 32

static const char *const rb_frame_names[] = {"auto", "transport", "helicity", "data", NULL};
static const char *const rb_pipeline_names[] = {"pulling", NULL};
static const char *const rb_halo_space_names[] = {"object", "screen", NULL};

static const sl_param_def ribbons_params[] = {
    SL_LINE_STYLE_PARAMS,
    SL_LINE_STYLE_RADIUS_ATTRIBUTE_PARAM,
    {"width_ratio", SL_PARAM_FLOAT, 0.0, 1.0, {0.25}, NULL, "",
     "w: semi-minor / semi-major axis of the elliptic profile; 1 = circular tube", SL_INVALIDATE_FRAME},
    {"min_thickness", SL_PARAM_FLOAT, 0.0, 1.0, {0.15}, NULL, "",
     "floor of w (fraction of the semi-major axis): a ribbon never vanishes edge-on", SL_INVALIDATE_FRAME},
    {"min_pixels", SL_PARAM_FLOAT, 0.0, 16.0, {1}, NULL, "px",
     "the full on-screen thickness never falls below this many pixels (widens w); 0 = off", SL_INVALIDATE_FRAME},
    {"frame", SL_PARAM_ENUM, 0, 0, {0}, rb_frame_names, "",
     "ribbon orientation: auto = data normals, else helicity, else transport; transport = parallel transport; "
     "helicity = normals rotated by the accumulated helicity; data = the dataset's normals", SL_INVALIDATE_PREPARED},
    {"pipeline", SL_PARAM_ENUM, 0, 0, {0}, rb_pipeline_names, "",
     "how the geometry is made: pulling = vertex shader fetches points from storage buffers", SL_INVALIDATE_PREPARED},
    {"sides", SL_PARAM_INT, 3, RB_MAX_SIDES, {8}, NULL, "", "vertices per elliptic cross-section", SL_INVALIDATE_PREPARED},
    {"halo", SL_PARAM_BOOL, 0, 1, {1}, NULL, "", "silhouette-point halos", SL_INVALIDATE_FRAME},
    {"halo_width", SL_PARAM_FLOAT, 0.0, 64.0, {0.1}, NULL, "",
     "outline width: a fraction of the half-chord (halo_space object) or pixels (screen)", SL_INVALIDATE_FRAME},
    {"halo_space", SL_PARAM_ENUM, 0, 0, {0}, rb_halo_space_names, "",
     "unit of halo_width: object = fraction of the cross-section, screen = pixels", SL_INVALIDATE_FRAME},
    {"halo_color", SL_PARAM_VEC3, 0.0, 1.0, {0, 0, 0}, NULL, "rgb", "halo colour", SL_INVALIDATE_FRAME},
    {"twist_lines", SL_PARAM_INT, 0, 32, {0}, NULL, "", "k twist lines around each ribbon; 0 = off",
     SL_INVALIDATE_FRAME},
    {"twist_width", SL_PARAM_FLOAT, 0.0, 2.0, {0.15}, NULL, "",
     "twist line width across the line, in units of the radius", SL_INVALIDATE_FRAME},
    {"twist_scale", SL_PARAM_FLOAT, -1e6, 1e6, {1}, NULL, "",
     "f: radians of twist per unit of accumulated helicity x length; its useful size depends on the data",
     SL_INVALIDATE_FRAME},
    {"depth_cue", SL_PARAM_FLOAT, 0.0, 1.0, {0}, NULL, "",
     "desaturation at the far end of the data; 0 = off", SL_INVALIDATE_FRAME},
    {"frustum_culling", SL_PARAM_BOOL, 0, 1, {1}, NULL, "",
     "skip chunks of segments outside the view (off: for tests and benchmarks)", SL_INVALIDATE_FRAME},
};

typedef struct rb_draw { /* one visible chunk, for the sort */
    double key;
    uint32_t chunk;
} rb_draw;

typedef struct ribbons_state {
    const sl_dataset *dataset;  /* borrowed */
    GLuint program, vao, ibo, camera_ubo, points[3];
    sl_line_colors colors;      /* colormap texture + colour scalars (SSBO 1) */
    sl_ribbons_frame frame;
    int sides;
    float ring[2 * RB_MAX_SIDES];
    sl_line_chunk *chunks;      /* owned */
    size_t chunk_count;
    uint8_t *chunk_caps;        /* per chunk: bit 0 start cap, bit 1 end cap */
    rb_draw *order;             /* per-frame scratch, chunk_count entries */
    GLsizei *counts, *cap_counts;
    GLint *bases, *cap_bases;
    const void **offsets, **cap_offsets;
    size_t cap_start_offset, cap_end_offset; /* bytes into ibo */
    float max_data_radius;      /* largest |radius| in the points; < 0 none */
    int has_default_radius;     /* some point uses the `radius` uniform */
    size_t gpu_bytes;
    sl_prepare_stats prep;
} ribbons_state;

static void ribbons_release(void *opaque)
{
    ribbons_state *s = opaque;
    if (!s)
        return;
    if (s->program) glDeleteProgram(s->program);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->ibo) glDeleteBuffers(1, &s->ibo);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    for (int i = 0; i < 3; i++)
        if (s->points[i]) glDeleteBuffers(1, &s->points[i]);
    sl_line_colors_deinit(&s->colors);
    free(s->chunks);
    free(s->chunk_caps);
    free(s->order);
    free(s->counts);
    free(s->cap_counts);
    free(s->bases);
    free(s->cap_bases);
    free(s->offsets);
    free(s->cap_offsets);
    free(s);
}

/* The mantle pattern for K segments followed by the start and end caps. */
static uint16_t *pattern_build(int N, size_t *count)
{
    size_t mantle = 6u * (size_t)N * RB_CHUNK_SEGMENTS, cap = 3u * (size_t)(N - 2);
    *count = mantle + 2 * cap;
    uint16_t *idx = malloc(*count * sizeof *idx);
    if (!idx)
        return NULL;
    size_t k = 0;
    for (unsigned s = 0; s < RB_CHUNK_SEGMENTS; s++)
        for (int j = 0; j < N; j++) {
            unsigned j1 = (unsigned)(j + 1) % (unsigned)N, a = s * (unsigned)N, c = (s + 1) * (unsigned)N;
            const unsigned tri[6] = {a + (unsigned)j, a + j1, c + (unsigned)j, c + (unsigned)j, a + j1, c + j1};
            for (int q = 0; q < 6; q++)
                idx[k++] = (uint16_t)tri[q];
        }
    for (int j = 1; j <= N - 2; j++) { /* start cap faces -t */
        idx[k++] = 0;
        idx[k++] = (uint16_t)(j + 1);
        idx[k++] = (uint16_t)j;
    }
    for (int j = 1; j <= N - 2; j++) {
        idx[k++] = 0;
        idx[k++] = (uint16_t)j;
        idx[k++] = (uint16_t)(j + 1);
    }
    return idx;
}

static sl_status ribbons_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out,
                                 sl_err *err)
{
    (void)gpu;
    *out = NULL;
    sl_status st = sl_line_style_check(params, ds, err);
    if (st != SL_OK)
        return st;
    sl_ribbons_frame frame;
    st = sl_ribbons_frame_resolve(ds, (sl_ribbons_frame)sl_params_choice(params, "frame"), &frame, err);
    if (st != SL_OK)
        return st;
    ribbons_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory");
    s->dataset = ds;
    s->frame = frame;
    s->sides = sl_params_int(params, "sides");
    for (int j = 0; j < s->sides; j++) {
        double phi = 2.0 * M_PI * j / s->sides;
        s->ring[2 * j] = (float)cos(phi);
        s->ring[2 * j + 1] = (float)sin(phi);
    }
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    const sl_lines *l = &ds->lines;
    double t_build = sl_clock_ms();
    sl_ribbons_points pts;
    st = sl_ribbons_points_init(&pts, l, frame, style.radius_attribute, err);
    if (st != SL_OK) {
        free(s);
        return st;
    }
    st = sl_lines_chunks_build(l, RB_CHUNK_SEGMENTS, &s->chunks, &s->chunk_count, err);
    size_t n = s->chunk_count ? s->chunk_count : 1;
    if (st == SL_OK) {
        s->chunk_caps = calloc(n, 1);
        s->order = malloc(n * sizeof *s->order);
        s->counts = malloc(n * sizeof *s->counts);
        s->bases = malloc(n * sizeof *s->bases);
        s->offsets = malloc(n * sizeof *s->offsets);
        s->cap_counts = malloc(2 * n * sizeof *s->cap_counts);
        s->cap_bases = malloc(2 * n * sizeof *s->cap_bases);
        s->cap_offsets = malloc(2 * n * sizeof *s->cap_offsets);
        if (!s->chunk_caps || !s->order || !s->counts || !s->bases || !s->offsets || !s->cap_counts ||
            !s->cap_bases || !s->cap_offsets)
            st = sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory for %zu chunks", s->chunk_count);
    }
    if (st != SL_OK) {
        sl_ribbons_points_deinit(&pts);
        ribbons_release(s);
        return st;
    }
    for (size_t c = 0; c < s->chunk_count; c++) {
        const sl_line_chunk *ch = &s->chunks[c];
        if (ch->first_point == l->line_offsets[ch->line])
            s->chunk_caps[c] |= 1;
        if (ch->first_point + ch->segments + 1 == l->line_offsets[ch->line + 1])
            s->chunk_caps[c] |= 2;
    }
    s->max_data_radius = -1.0f;
    for (size_t i = 0; i < pts.count; i++) {
        float r = pts.pos_radius[4 * i + 3];
        if (r < 0.0f)
            s->has_default_radius = 1;
        else if (r > s->max_data_radius)
            s->max_data_radius = r;
    }
    s->prep.preprocess_ms = sl_clock_ms() - t_build;
    st = sl_gl_program_create(&(sl_program_desc){
        .vertex = "ribbons/ribbons_pull.vert.glsl",
        .fragment = "ribbons/ribbons.frag.glsl",
        .label = "ribbons"}, &s->program, err);
    if (st != SL_OK) {
        sl_ribbons_points_deinit(&pts);
        ribbons_release(s);
        return st;
    }
    double t_upload = sl_clock_ms();
    size_t pattern_count = 0;
    uint16_t *pattern = pattern_build(s->sides, &pattern_count);
    if (!pattern) {
        sl_ribbons_points_deinit(&pts);
        ribbons_release(s);
        return sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory for the index pattern");
    }
    size_t cap = 3u * (size_t)(s->sides - 2);
    s->cap_start_offset = (pattern_count - 2 * cap) * sizeof(uint16_t);
    s->cap_end_offset = (pattern_count - cap) * sizeof(uint16_t);
    glCreateBuffers(1, &s->ibo);
    glNamedBufferStorage(s->ibo, (GLsizeiptr)(pattern_count * sizeof *pattern), pattern, 0);
    free(pattern);
    const float *arrays[3] = {pts.pos_radius, pts.normal_twist, pts.tangent_slope};
    size_t bytes = (pts.count ? pts.count : 1) * 4 * sizeof(float);
    glCreateBuffers(3, s->points);
    for (int i = 0; i < 3; i++)
        glNamedBufferStorage(s->points[i], (GLsizeiptr)bytes, pts.count ? arrays[i] : NULL, 0);
    sl_ribbons_points_deinit(&pts);
    glCreateVertexArrays(1, &s->vao);
    glVertexArrayElementBuffer(s->vao, s->ibo);
    st = sl_line_colors_init(&s->colors, l->vertex_count, 1, "ribbons", err);
    if (st != SL_OK) {
        ribbons_release(s);
        return st;
    }
    s->gpu_bytes = 3 * bytes + pattern_count * sizeof(uint16_t) + sl_line_colors_bytes(&s->colors);
    glFinish();
    s->prep.upload_ms = sl_clock_ms() - t_upload;
    st = sl_gl_check_errors("ribbons: uploading the points", err);
    if (st != SL_OK) {
        ribbons_release(s);
        return st;
    }
    *out = s;
    return SL_OK;
}

static int draw_cmp(const void *a, const void *b)
{
    const rb_draw *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->chunk < y->chunk ? -1 : x->chunk > y->chunk;
}

static GLint uniform(GLuint program, const char *name)
{
    return glGetUniformLocation(program, name);
}

static sl_status ribbons_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                                sl_render_stats *stats, sl_err *err)
{
    (void)target;
    ribbons_state *s = opaque;
    sl_status st = sl_line_style_check(params, s->dataset, err);
    if (st != SL_OK)
        return st;
    sl_line_style style;
    sl_line_style_read(params, s->dataset, &style);
    const int N = s->sides;

    /* Chunks: cull (optionally) and sort front to back by box centre. */
    double r_max = s->has_default_radius ? style.radius : 0.0;
    if (s->max_data_radius >= 0.0f)
        r_max = fmax(r_max, (double)s->max_data_radius * style.radius_scale);
    int cull = sl_params_bool(params, "frustum_culling");
    sl_vec3 e = sl_v3_sub(view->camera.eye, view->origin);
    const double eye[3] = {e.x, e.y, e.z};
    size_t visible = 0;
    double tri_all = 0.0;
    for (size_t c = 0; c < s->chunk_count; c++) {
        const sl_line_chunk *ch = &s->chunks[c];
        double tri = 2.0 * N * ch->segments + (N - 2) * (double)((s->chunk_caps[c] & 1) + (s->chunk_caps[c] >> 1));
        tri_all += tri;
        if (cull && !sl_lines_box_visible(view, view->origin, ch->lo, ch->hi, r_max))
            continue;
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = 0.5 * ((double)ch->lo[k] + ch->hi[k]) - eye[k];
        s->order[visible++] = (rb_draw){d[0] * d[0] + d[1] * d[1] + d[2] * d[2], (uint32_t)c};
    }
    qsort(s->order, visible, sizeof *s->order, draw_cmp);
    size_t caps = 0;
    double tri_drawn = 0.0;
    for (size_t v = 0; v < visible; v++) {
        uint32_t c = s->order[v].chunk;
        const sl_line_chunk *ch = &s->chunks[c];
        s->counts[v] = (GLsizei)(6u * (unsigned)N * ch->segments);
        s->bases[v] = (GLint)(ch->first_point * (uint32_t)N);
        s->offsets[v] = NULL;
        tri_drawn += 2.0 * N * ch->segments;
        if (s->chunk_caps[c] & 1) {
            s->cap_counts[caps] = 3 * (N - 2);
            s->cap_bases[caps] = (GLint)(ch->first_point * (uint32_t)N);
            s->cap_offsets[caps++] = (const void *)(uintptr_t)s->cap_start_offset;
        }
        if (s->chunk_caps[c] & 2) {
            s->cap_counts[caps] = 3 * (N - 2);
            s->cap_bases[caps] = (GLint)((ch->first_point + ch->segments) * (uint32_t)N);
            s->cap_offsets[caps++] = (const void *)(uintptr_t)s->cap_end_offset;
        }
    }
    tri_drawn += (double)caps * (N - 2);

    sl_line_colors_update(&s->colors, &s->dataset->lines, &style);
    sl_line_colors_bind(&s->colors, 0, 1);
    for (GLuint i = 0; i < 3; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2 + i, s->points[i]);
    sl_camera_ubo_update(&s->camera_ubo, view);
    GLuint p = s->program;
    glUseProgram(p);
    sl_line_style_uniforms(p, &style, 0);
    glUniform1ui(uniform(p, "u_sides"), (GLuint)N);
    glUniform2fv(uniform(p, "u_ring"), N, s->ring);
    glUniform1f(uniform(p, "u_cos_pi_n"), (float)cos(M_PI / N));
    glUniform1f(uniform(p, "u_halo_min"), (float)(1.0 - cos(M_PI / N)));
    glUniform1f(uniform(p, "u_width_ratio"), (float)sl_params_float(params, "width_ratio"));
    glUniform1f(uniform(p, "u_min_thickness"), (float)sl_params_float(params, "min_thickness"));
    glUniform1f(uniform(p, "u_min_pixels"), (float)sl_params_float(params, "min_pixels"));
    glUniform1f(uniform(p, "u_twist_scale"), (float)sl_params_float(params, "twist_scale"));
    glUniform1i(uniform(p, "u_rotate"), s->frame == SL_RIBBONS_FRAME_HELICITY);
    glUniform1i(uniform(p, "u_twist_lines"), sl_params_int(params, "twist_lines"));
    glUniform1f(uniform(p, "u_twist_width"), (float)sl_params_float(params, "twist_width"));
    glUniform1i(uniform(p, "u_halo"), sl_params_bool(params, "halo"));
    glUniform1i(uniform(p, "u_halo_screen"), sl_params_choice(params, "halo_space") == 1);
    glUniform1f(uniform(p, "u_halo_width"), (float)sl_params_float(params, "halo_width"));
    float halo_color[3];
    sl_params_vec3(params, "halo_color", halo_color);
    glUniform3fv(uniform(p, "u_halo_color"), 1, halo_color);
    glUniform1f(uniform(p, "u_depth_cue"), (float)sl_params_float(params, "depth_cue"));
    /* Depth cue range: the eye distances of the data's bounding sphere. */
    sl_vec3 centre = sl_v3_scale(sl_v3_add(s->dataset->bounds_min, s->dataset->bounds_max), 0.5);
    double radius = 0.5 * sl_v3_length(sl_v3_sub(s->dataset->bounds_max, s->dataset->bounds_min));
    double dist = sl_v3_length(sl_v3_sub(centre, view->camera.eye));
    glUniform2f(uniform(p, "u_depth_range"), (float)fmax(dist - radius, 0.0), (float)(dist + radius));

    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glEnable(GL_CULL_FACE); /* closed surfaces (caps always on) */
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glBindVertexArray(s->vao);
    if (visible) {
        glUniform1i(uniform(p, "u_cap"), 0);
        glMultiDrawElementsBaseVertex(GL_TRIANGLES, s->counts, GL_UNSIGNED_SHORT, s->offsets, (GLsizei)visible,
                                      s->bases);
    }
    if (caps && N > 2) {
        glUniform1i(uniform(p, "u_cap"), 1);
        glMultiDrawElementsBaseVertex(GL_TRIANGLES, s->cap_counts, GL_UNSIGNED_SHORT, s->cap_offsets,
                                      (GLsizei)caps, s->cap_bases);
    }
    glBindVertexArray(0);
    glDisable(GL_CULL_FACE);
    stats->primitives = tri_drawn;
    stats->culled = tri_all - tri_drawn;
    return SL_OK;
}

static void ribbons_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const ribbons_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

static size_t ribbons_gpu_bytes(const void *opaque)
{
    const ribbons_state *s = opaque;
    return s ? s->gpu_bytes : 0;
}

const sl_technique sl_ribbons_technique = {
    .name = "ribbons",
    .description = "elliptic ribbons with silhouette-point halos and twist lines by programmable pulling "
                   "(Neuhauser et al.)",
    .dataset_kinds = SL_DATASET_LINES,
    .params = ribbons_params,
    .param_count = (int)(sizeof ribbons_params / sizeof ribbons_params[0]),
    .prepare = ribbons_prepare,
    .render = ribbons_render,
    .release = ribbons_release,
    .gpu_bytes = ribbons_gpu_bytes,
    .prepare_stats = ribbons_prepare_stats,
};
