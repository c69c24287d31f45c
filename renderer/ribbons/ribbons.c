/* ribbons.c — technique `ribbons`: elliptic ribbons, silhouette-point halos and twist lines.
 *
 * Neuhauser, Wang, Kern, Westermann, "Efficient high-quality rendering of
 * ribbons and twisted lines": generalized cylinders of elliptic profile
 * (Sec. 3.1). `pipeline` picks how the geometry is made (Sec. 5;
 * ribbons_gpu.c builds each): pulling (default; per-point storage buffers
 * and one u16 chunk pattern drawn per chunk with basevertex), geometry
 * (geometry-shader extrusion per segment), mesh (a static CPU-built mesh,
 * the memory-hungry baseline) and flat (two-sided twisting flat quads that
 * vanish edge-on, the vtkRibbonFilter look). All four share the packed points
 * (ribbons_prep.c), the chunks of sl_lines_chunks_build, the per-frame
 * chunk culling and front-to-back sort here, ribbons_ring.glsl and the one
 * ribbons.frag.glsl. Width, min_pixels widening (Sec. 7.2), halos (Sec.
 * 3.2), twist lines (Sec. 4), the depth cue and the whole line style are
 * uniforms; per frame only the multi-draw arrays in client memory are
 * rebuilt — no GL buffer is written on a camera move. Render thread only.
 * Plan: docs/ribbons_plan.md §1, §3.
 */
#include <math.h>
#include <stdlib.h>

#include "ribbons_gpu.h"
#include "ribbons_prep.h"
#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../line_style/sl_line_style.h"
#include "../lines/sl_line_gpu.h"
#include "../lines/sl_lines_prep.h"

static const char *const rb_frame_names[] = {"auto", "transport", "helicity", "data", NULL};
static const char *const rb_pipeline_names[] = {"pulling", "geometry", "mesh", "flat", NULL};
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
     "how the geometry is made: pulling = vertex shader fetches points from storage buffers; geometry = geometry "
     "shader extrudes each segment; mesh = static triangle mesh built on the CPU (memory-hungry baseline); "
     "flat = two-sided twisting flat quads, no widening, caps or twist lines (they vanish edge-on, like VTK's "
     "ribbon filter)", SL_INVALIDATE_PREPARED},
    {"sides", SL_PARAM_INT, 3, RB_MAX_SIDES, {8}, NULL, "", "vertices per elliptic cross-section (flat: unused)", SL_INVALIDATE_PREPARED},
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
    GLuint camera_ubo;
    rb_gpu gpu;                 /* the pipeline's programs, buffers and per-chunk ranges */
    sl_line_colors colors;      /* colormap texture + colour scalars (SSBO 1) */
    sl_ribbons_frame frame;
    sl_line_chunk *chunks;      /* owned */
    size_t chunk_count;
    rb_draw *order;             /* per-frame scratch, chunk_count entries */
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
    rb_gpu_release(&s->gpu);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    sl_line_colors_deinit(&s->colors);
    free(s->chunks);
    free(s->order);
    free(s);
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
    if (st == SL_OK) {
        s->order = malloc((s->chunk_count ? s->chunk_count : 1) * sizeof *s->order);
        if (!s->order)
            st = sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory for %zu chunks", s->chunk_count);
    }
    if (st != SL_OK) {
        sl_ribbons_points_deinit(&pts);
        ribbons_release(s);
        return st;
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
    double t_upload = sl_clock_ms();
    st = rb_gpu_build(&s->gpu, (rb_pipeline)sl_params_choice(params, "pipeline"), sl_params_int(params, "sides"),
                      &pts, l, s->chunks, s->chunk_count, err);
    sl_ribbons_points_deinit(&pts);
    if (st == SL_OK)
        st = sl_line_colors_init(&s->colors, l->vertex_count, 1, "ribbons", err);
    if (st != SL_OK) {
        ribbons_release(s);
        return st;
    }
    s->gpu_bytes = s->gpu.buffer_bytes + sl_line_colors_bytes(&s->colors);
    glFinish();
    /* The mesh (or pair) building is CPU preprocessing; compiles are neither. */
    s->prep.preprocess_ms += s->gpu.cpu_ms;
    s->prep.upload_ms = sl_clock_ms() - t_upload - s->gpu.cpu_ms - s->gpu.compile_ms;
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

/* The per-frame loop of every pipeline: each chunk's box, grown by the
 * largest radius, against the frustum (unless culling is off), the visible
 * ones sorted front to back by box centre and their ranges appended to the
 * pipeline's multi-draw arrays (client memory). Triangle counts to stats. */
static void chunks_select(ribbons_state *s, const sl_view *view, double r_max, int cull, sl_render_stats *stats)
{
    sl_vec3 e = sl_v3_sub(view->camera.eye, view->origin);
    const double eye[3] = {e.x, e.y, e.z};
    size_t visible = 0;
    double tri_all = 0.0, tri_drawn = 0.0;
    for (size_t c = 0; c < s->chunk_count; c++) {
        const sl_line_chunk *ch = &s->chunks[c];
        tri_all += s->gpu.triangles[c];
        if (cull && !sl_lines_box_visible(view, view->origin, ch->lo, ch->hi, r_max))
            continue;
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = 0.5 * ((double)ch->lo[k] + ch->hi[k]) - eye[k];
        s->order[visible++] = (rb_draw){d[0] * d[0] + d[1] * d[1] + d[2] * d[2], (uint32_t)c};
    }
    qsort(s->order, visible, sizeof *s->order, draw_cmp);
    s->gpu.passes[0].drawcount = s->gpu.passes[1].drawcount = 0;
    for (size_t v = 0; v < visible; v++) {
        rb_gpu_add_chunk(&s->gpu, s->order[v].chunk);
        tri_drawn += s->gpu.triangles[s->order[v].chunk];
    }
    stats->primitives = tri_drawn;
    stats->culled = tri_all - tri_drawn;
}

/* The uniforms of ribbons_vertex.glsl, ribbons_ring.glsl and ribbons.frag.glsl on program p. */
static void uniforms_set(const ribbons_state *s, GLuint p, const sl_view *view, const sl_params *params,
                         const sl_line_style *style)
{
    const rb_gpu *g = &s->gpu;
    const int N = g->sides, flat = g->pipeline == RB_PIPELINE_FLAT;
    glUseProgram(p);
    sl_line_style_uniforms(p, style, 0);
    glUniform1ui(glGetUniformLocation(p, "u_sides"), (GLuint)N);
    glUniform2fv(glGetUniformLocation(p, "u_ring"), N, g->ring);
    glUniform1f(glGetUniformLocation(p, "u_cos_pi_n"), (float)cos(M_PI / N));
    glUniform1i(glGetUniformLocation(p, "u_flat"), flat);
    /* flat: no widening (ring cos = 0 anyway) and a halo band of exactly halo_width. */
    glUniform1f(glGetUniformLocation(p, "u_halo_min"), flat ? 0.0f : (float)(1.0 - cos(M_PI / N)));
    glUniform1f(glGetUniformLocation(p, "u_width_ratio"), flat ? 0.0f : (float)sl_params_float(params, "width_ratio"));
    glUniform1f(glGetUniformLocation(p, "u_min_thickness"),
                flat ? 0.0f : (float)sl_params_float(params, "min_thickness"));
    glUniform1f(glGetUniformLocation(p, "u_min_pixels"), flat ? 0.0f : (float)sl_params_float(params, "min_pixels"));
    glUniform1f(glGetUniformLocation(p, "u_twist_scale"), (float)sl_params_float(params, "twist_scale"));
    glUniform1i(glGetUniformLocation(p, "u_rotate"), s->frame == SL_RIBBONS_FRAME_HELICITY);
    glUniform1i(glGetUniformLocation(p, "u_twist_lines"), sl_params_int(params, "twist_lines"));
    glUniform1f(glGetUniformLocation(p, "u_twist_width"), (float)sl_params_float(params, "twist_width"));
    glUniform1i(glGetUniformLocation(p, "u_halo"), sl_params_bool(params, "halo"));
    glUniform1i(glGetUniformLocation(p, "u_halo_screen"), sl_params_choice(params, "halo_space") == 1);
    glUniform1f(glGetUniformLocation(p, "u_halo_width"), (float)sl_params_float(params, "halo_width"));
    float halo_color[3];
    sl_params_vec3(params, "halo_color", halo_color);
    glUniform3fv(glGetUniformLocation(p, "u_halo_color"), 1, halo_color);
    glUniform1f(glGetUniformLocation(p, "u_depth_cue"), (float)sl_params_float(params, "depth_cue"));
    /* Depth cue range: the eye distances of the data's bounding sphere. */
    sl_vec3 centre = sl_v3_scale(sl_v3_add(s->dataset->bounds_min, s->dataset->bounds_max), 0.5);
    double radius = 0.5 * sl_v3_length(sl_v3_sub(s->dataset->bounds_max, s->dataset->bounds_min));
    double dist = sl_v3_length(sl_v3_sub(centre, view->camera.eye));
    glUniform2f(glGetUniformLocation(p, "u_depth_range"), (float)fmax(dist - radius, 0.0), (float)(dist + radius));
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
    double r_max = s->has_default_radius ? style.radius : 0.0;
    if (s->max_data_radius >= 0.0f)
        r_max = fmax(r_max, (double)s->max_data_radius * style.radius_scale);
    chunks_select(s, view, r_max, sl_params_bool(params, "frustum_culling"), stats);

    sl_line_colors_update(&s->colors, &s->dataset->lines, &style);
    sl_line_colors_bind(&s->colors, 0, 1);
    sl_camera_ubo_update(&s->camera_ubo, view);
    for (int i = 0; i < s->gpu.program_count; i++)
        uniforms_set(s, s->gpu.programs[i], view, params, &style);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    rb_gpu_draw(&s->gpu); /* face culling per pass: closed surfaces except flat */
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
