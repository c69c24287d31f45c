/* tubes.c — technique `tubes`: raycast Hermite spline tubes (Russig, Salm, Gumhold,
 * "GPU-based Raycasting of Hermite Spline Tubes", 3.2).
 *
 * prepare builds Hermite nodes and segments (tubes_nodes.c) and uploads them
 * once; render is one indexed GL_LINES draw whose geometry shader emits each
 * quadratic sub-segment's oriented box and whose fragment shader finds the
 * nearest sphere-sweep entry. A camera move re-uploads nothing (an attribute
 * change refills the colour buffer; radius_attribute re-prepares). Beyond the
 * paper, occlusion_prepass (render_with_prepass) draws spheres inside the
 * sweep first so that early depth tests keep hidden boxes from the root search:
 * on llvmpipe a discard skips nothing, a fragment rejected before the shader
 * skips all of it. No transparency, no level of detail. Render thread (GL).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../line_style/sl_line_shade.h"
#include "../line_style/sl_line_style.h"
#include "../core/sl_backend.h"
#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../lines/sl_line_gpu.h"
#include "tubes_embree.h"
#include "tubes_nodes.h"

static const char *const root_methods[] = {"bisection", "illinois", "newton", NULL};
static const char *const tangent_modes[] = {"auto", "catmull_rom", "data_exact", NULL};
static const char *const prepass_modes[] = {"auto", "on", "off", NULL};
static const char *const backend_choices[] = {"auto", "gl", "embree", NULL};

/* The CPU execution for the backend rule (core/sl_backend.h). */
static void tubes_backend_cpu(sl_backend_cpu *out)
{
    *out = (sl_backend_cpu){.name = "embree", .built = sl_tubes_embree_available(),
                            .missing = "Debian libembree-dev (Embree 3.13)"};
}
enum { SL_TUBES_PREPASS_AUTO, SL_TUBES_PREPASS_ON, SL_TUBES_PREPASS_OFF };

/* auto: the pre-pass pays where tubes hide each other. Estimated depth
 * complexity = the tubes' projected area (2 r x length summed) over the
 * bounding sphere's disc; camera-independent for a view from outside. At
 * 1280x720 on llvmpipe (random_walk in a +-3 box): 0.7 lost (5.5 s vs 4.0
 * one pass), 2.1 won (8.9 vs 10.8), 4.2 won 3x, 7 won 4x. */
#define SL_TUBES_PREPASS_MIN_DEPTH_COMPLEXITY 1.2
/* ... and it costs a second box pass, which small images do not win back:
 * bundle (105k segments, far) 415 vs 366 ms one pass at 160x90, but 542 vs
 * 962 at 320x180 and 964 vs 2451 at 640x360. */
#define SL_TUBES_PREPASS_MIN_PIXELS 20000

static const sl_param_def tubes_params[] = {
    SL_LINE_STYLE_PARAMS,
    SL_LINE_STYLE_RADIUS_ATTRIBUTE_PARAM,
    SL_BACKEND_PARAM(backend_choices, "embree"),
    {"iterations", SL_PARAM_INT, 1, 64, {20}, NULL, "",
     "steps of every root search (the accuracy knob; gl only: embree's hits are refined in double)",
     SL_INVALIDATE_FRAME},
    {"root_method", SL_PARAM_ENUM, 0, 0, {1}, root_methods, "",
     "root search: bisection (as in the paper), Illinois regula falsi (default), or newton (safeguarded Newton; "
     "Illinois in a smoothing variable for the entry-distance derivative): fewer steps for the same error",
     SL_INVALIDATE_FRAME},
    {"tangents", SL_PARAM_ENUM, 0, 0, {0}, tangent_modes, "",
     "node tangents: auto (explicit Hermite data exactly, data tangent directions with Catmull-Rom length, else Catmull-Rom), catmull_rom, or the data's as they are", SL_INVALIDATE_PREPARED},
    {"frustum_culling", SL_PARAM_BOOL, 0, 1, {1}, NULL, "",
     "skip boxes outside the view frustum in the geometry shader", SL_INVALIDATE_FRAME},
    {"small_box_pixels", SL_PARAM_FLOAT, 0, 65536, {64}, NULL, "px",
     "a box whose projection spans at most this many pixels is drawn as one screen rectangle instead of its faces "
     "(4 vertices instead of up to 12; 0: always faces, as the paper)", SL_INVALIDATE_FRAME},
    {"occlusion_prepass", SL_PARAM_ENUM, 0, 0, {0}, prepass_modes, "",
     "occluder depth pre-pass (spheres inside the sweep), then early depth tests keep hidden boxes from the root "
     "search: two box passes instead of one, far fewer root searches where tubes hide each other; auto = on from "
     "20000 pixels up when the estimated depth complexity is at least 1.2 or the eye is inside the data's bounding "
     "sphere",
     SL_INVALIDATE_FRAME},
    {"silhouette_only", SL_PARAM_BOOL, 0, 1, {0}, NULL, "",
     "discard every fragment (measures the silhouette cost; draws nothing)", SL_INVALIDATE_FRAME},
};

typedef struct tubes_state {
    const sl_dataset *dataset;   /* borrowed */
    sl_tubes_nodes nodes;        /* CPU copy of the colour scalars (geometry freed after upload) */
    GLuint program, program_silhouette;      /* one pass (the paper's), and its silhouette experiment */
    GLuint program_prepass, program_depth, program_nearest, program_shade; /* occlusion_prepass passes */
    GLuint nearest_tex;          /* r32ui, nearest_w x nearest_h: nearest hit depth bits per pixel */
    int nearest_w, nearest_h;
    double length_sum, length_radius_sum; /* sum of segment chords; of chord x mean data radius (occlusion auto) */
    GLuint vao, node_vbo, color_vbo, ibo, camera_ubo, query;
    sl_line_colors colors;       /* the colormap texture only: colour scalars live in color_vbo */
    GLuint empty_vao;            /* no attributes: the pulling and full-screen passes */
    size_t gpu_bytes;
    sl_prepare_stats prep;      /* node build (CPU) and upload times */
    sl_backend backend;         /* the execution chosen at prepare */
    sl_tubes_embree *embree;    /* backend embree: the device and BVH */
    sl_host_frame host;         /* backend embree: the traced frame on its way into the target */
    int embree_attribute;       /* backend embree: the colour attribute in nodes.color (-2: none yet) */
} tubes_state;

static void tubes_release(void *opaque)
{
    tubes_state *s = opaque;
    if (!s)
        return;
    if (s->program) glDeleteProgram(s->program);
    if (s->program_silhouette) glDeleteProgram(s->program_silhouette);
    if (s->program_prepass) glDeleteProgram(s->program_prepass);
    if (s->program_depth) glDeleteProgram(s->program_depth);
    if (s->program_nearest) glDeleteProgram(s->program_nearest);
    if (s->program_shade) glDeleteProgram(s->program_shade);
    if (s->nearest_tex) glDeleteTextures(1, &s->nearest_tex);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->empty_vao) glDeleteVertexArrays(1, &s->empty_vao);
    if (s->node_vbo) glDeleteBuffers(1, &s->node_vbo);
    if (s->color_vbo) glDeleteBuffers(1, &s->color_vbo);
    if (s->ibo) glDeleteBuffers(1, &s->ibo);
    sl_line_colors_deinit(&s->colors);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    if (s->query) glDeleteQueries(1, &s->query);
    sl_tubes_embree_destroy(s->embree);
    sl_host_frame_deinit(&s->host);
    sl_tubes_nodes_deinit(&s->nodes);
    free(s);
}

/* Backend embree: the device and the BVH of the prepared radii; the nodes stay on the CPU
 * (colour scalars are refilled when the attribute changes). */
static sl_status prepare_embree(tubes_state *s, const sl_params *params, sl_err *err)
{
    sl_status st = sl_tubes_embree_create(&s->nodes, &s->embree, err);
    if (st != SL_OK)
        return st;
    sl_line_style style;
    sl_line_style_read(params, s->dataset, &style);
    double build_ms;
    if ((st = sl_tubes_embree_ensure(s->embree, style.radius, style.radius_scale, &build_ms, err)) != SL_OK)
        return st;
    sl_tubes_embree_stats es;
    sl_tubes_embree_stats_get(s->embree, &es);
    s->prep.preprocess_ms += build_ms;
    sl_prepare_stats_add(&s->prep, "embree.bvh_ms", build_ms);
    sl_prepare_stats_add(&s->prep, "embree.bvh_bytes", es.bvh_bytes);
    sl_prepare_stats_add(&s->prep, "embree.curves", (double)es.curves);
    sl_prepare_stats_add(&s->prep, "embree.spheres", (double)es.spheres);
    sl_prepare_stats_add(&s->prep, "embree.exact", (double)es.exact);
    free(s->nodes.geometry); /* the device keeps its own copy */
    s->nodes.geometry = NULL;
    free(s->nodes.segments);
    s->nodes.segments = NULL;
    s->embree_attribute = -2;
    return sl_gl_check_errors("tubes (embree): preparing", err); /* the frame still goes through GL */
}

static sl_status tubes_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out, sl_err *err)
{
    *out = NULL;
    if (ds->kind != SL_DATASET_LINES)
        return sl_err_set(err, SL_ERR_INVALID, "tubes renders line sets, not %s datasets", sl_dataset_kind_name(ds->kind));
    tubes_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    s->dataset = ds;
    sl_status st = sl_line_style_check(params, ds, err);
    if (st != SL_OK)
        goto fail;
    double t_build = sl_clock_ms();
    st = sl_tubes_nodes_build(&ds->lines, (sl_tubes_tangents)sl_params_choice(params, "tangents"), -1, &s->nodes, err);
    if (st != SL_OK)
        goto fail;
    sl_tubes_nodes_set_radii(&ds->lines, sl_params_attribute(params, "radius_attribute"), &s->nodes);
    for (size_t k = 0; k < s->nodes.segment_count; k++) {
        const float *a = s->nodes.geometry + (size_t)s->nodes.segments[2 * k] * SL_TUBES_NODE_FLOATS;
        const float *b = s->nodes.geometry + (size_t)s->nodes.segments[2 * k + 1] * SL_TUBES_NODE_FLOATS;
        double chord = sqrt((double)(b[0] - a[0]) * (b[0] - a[0]) + (double)(b[1] - a[1]) * (b[1] - a[1]) +
                            (double)(b[2] - a[2]) * (b[2] - a[2]));
        s->length_sum += chord;
        s->length_radius_sum += chord * 0.5 * fabs((double)a[3] + b[3]);
    }
    s->prep.preprocess_ms = sl_clock_ms() - t_build;
    sl_backend_cpu cpu;
    tubes_backend_cpu(&cpu);
    if ((st = sl_backend_decide("tubes", sl_params_choice(params, "backend"), sl_gpu_is_software(gpu), &cpu,
                                &s->backend, err)) != SL_OK)
        goto fail;
    if (s->backend == SL_BACKEND_CPU) {
        if ((st = prepare_embree(s, params, err)) != SL_OK)
            goto fail;
        *out = s;
        return SL_OK;
    }
    const struct { const char *label, *vertex, *fragment; GLuint *program; int boxes; } programs[] = {
        {"tubes", "tubes/tubes.vert.glsl", "tubes/tubes.frag.glsl", &s->program, 1},
        {"tubes_silhouette", "tubes/tubes.vert.glsl", "tubes/tubes_silhouette.frag.glsl", &s->program_silhouette, 1},
        {"tubes_prepass", "tubes/tubes_prepass.vert.glsl", "tubes/tubes_prepass.frag.glsl", &s->program_prepass, 0},
        {"tubes_depth", "tubes/tubes.vert.glsl", "tubes/tubes_depth.frag.glsl", &s->program_depth, 1},
        {"tubes_nearest_depth", "gpu/glsl/fullscreen_triangle.vert.glsl", "tubes/tubes_nearest_depth.frag.glsl",
         &s->program_nearest, 0},
        {"tubes_shade", "tubes/tubes.vert.glsl", "tubes/tubes_shade.frag.glsl", &s->program_shade, 1},
    };
    for (size_t k = 0; k < sizeof programs / sizeof programs[0]; k++)
        if ((st = sl_gl_program_create(&(sl_program_desc){.vertex = programs[k].vertex,
                                                          .geometry = programs[k].boxes ? "tubes/tubes.geom.glsl" : NULL,
                                                          .fragment = programs[k].fragment,
                                                          .label = programs[k].label},
                                       programs[k].program, err)) != SL_OK)
            goto fail;

    double t_upload = sl_clock_ms();
    size_t nn = s->nodes.node_count ? s->nodes.node_count : 1;
    size_t ns = s->nodes.segment_count ? s->nodes.segment_count : 1;
    glCreateBuffers(1, &s->node_vbo);
    glNamedBufferStorage(s->node_vbo, (GLsizeiptr)(nn * SL_TUBES_NODE_FLOATS * sizeof(float)),
                         s->nodes.node_count ? s->nodes.geometry : NULL, 0);
    glCreateBuffers(1, &s->color_vbo);
    glNamedBufferStorage(s->color_vbo, (GLsizeiptr)(nn * 2 * sizeof(float)), NULL, GL_DYNAMIC_STORAGE_BIT);
    glCreateBuffers(1, &s->ibo);
    glNamedBufferStorage(s->ibo, (GLsizeiptr)(ns * 2 * sizeof(uint32_t)),
                         s->nodes.segment_count ? s->nodes.segments : NULL, 0);
    glCreateVertexArrays(1, &s->empty_vao);
    glCreateVertexArrays(1, &s->vao);
    glVertexArrayVertexBuffer(s->vao, 0, s->node_vbo, 0, SL_TUBES_NODE_FLOATS * sizeof(float));
    glVertexArrayVertexBuffer(s->vao, 1, s->color_vbo, 0, 2 * sizeof(float));
    glVertexArrayElementBuffer(s->vao, s->ibo);
    for (GLuint a = 0; a < 3; a++)
        glEnableVertexArrayAttrib(s->vao, a);
    glVertexArrayAttribFormat(s->vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(s->vao, 1, 4, GL_FLOAT, GL_FALSE, 4 * sizeof(float));
    glVertexArrayAttribFormat(s->vao, 2, 2, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(s->vao, 0, 0);
    glVertexArrayAttribBinding(s->vao, 1, 0);
    glVertexArrayAttribBinding(s->vao, 2, 1);
    if ((st = sl_line_colors_init(&s->colors, s->nodes.node_count, 0, "tubes", err)) != SL_OK)
        goto fail;
    glGenQueries(1, &s->query);
    glFinish();
    s->prep.upload_ms = sl_clock_ms() - t_upload;
    if ((st = sl_gl_check_errors("tubes: uploading nodes and segments", err)) != SL_OK)
        goto fail;
    s->gpu_bytes = nn * (SL_TUBES_NODE_FLOATS + 2) * sizeof(float) + ns * 2 * sizeof(uint32_t) +
                   sl_line_colors_bytes(&s->colors);
    /* The geometry lives on the GPU now; keep only the colour scalars. */
    free(s->nodes.geometry);
    s->nodes.geometry = NULL;
    free(s->nodes.segments);
    s->nodes.segments = NULL;
    *out = s;
    return SL_OK;
fail:
    tubes_release(s);
    return st;
}

static void set_uniforms(GLuint program, const sl_line_style *style, const sl_params *params, int data_radii)
{
    glUseProgram(program);
    sl_line_style_uniforms(program, style, 0);
    glUniform1i(glGetUniformLocation(program, "u_data_radii"), data_radii);
    glUniform1i(glGetUniformLocation(program, "u_frustum_cull"), sl_params_bool(params, "frustum_culling"));
    glUniform1f(glGetUniformLocation(program, "u_rect_pixels"), (float)sl_params_float(params, "small_box_pixels"));
    glUniform1i(glGetUniformLocation(program, "u_iterations"), sl_params_int(params, "iterations"));
    glUniform1i(glGetUniformLocation(program, "u_method"), sl_params_choice(params, "root_method"));
}

/* (Re)creates the per-pixel nearest-hit image at the view's size. */
static sl_status ensure_nearest_image(tubes_state *s, int w, int h, sl_err *err)
{
    if (s->nearest_tex && s->nearest_w == w && s->nearest_h == h)
        return SL_OK;
    if (s->nearest_tex)
        glDeleteTextures(1, &s->nearest_tex);
    s->nearest_w = s->nearest_h = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &s->nearest_tex);
    glTextureStorage2D(s->nearest_tex, 1, GL_R32UI, w, h);
    sl_status st = sl_gl_check_errors("tubes: the nearest-hit image", err);
    if (st != SL_OK)
        return st;
    s->nearest_w = w;
    s->nearest_h = h;
    return SL_OK;
}

/* Draws every segment's boxes with the bound program; with stats, counts the
 * emitted triangles (2 per face) into it (waits for the query). */
static void draw_boxes(tubes_state *s, sl_render_stats *stats)
{
    glBindVertexArray(s->vao);
    if (stats)
        glBeginQuery(GL_PRIMITIVES_GENERATED, s->query);
    glDrawElements(GL_LINES, (GLsizei)(2 * s->nodes.segment_count), GL_UNSIGNED_INT, NULL);
    if (stats)
        glEndQuery(GL_PRIMITIVES_GENERATED);
    glBindVertexArray(0);
    if (stats) {
        GLuint triangles = 0;
        glGetQueryObjectuiv(s->query, GL_QUERY_RESULT, &triangles);
        stats->primitives = (double)triangles;
    }
}

/* occlusion_prepass: four passes into the bound target (depth cleared to 0 = nothing).
 * 1. tubes_prepass: inscribed squares, depth only: D never behind the nearest hit.
 * 2. tubes_depth: boxes with early tests GREATER against D (no writes): the hidden ones never
 *    reach the root search; the survivors' nearest hit depth goes to nearest_tex.
 * 3. tubes_nearest_depth: full-screen, depth := the nearest hit depth (ALWAYS).
 * 4. tubes_shade: boxes with early tests GEQUAL against it; the nearest hit shades.
 * With GL_MULTISAMPLE off, a multisampled target gets the single-sample frame in
 * every sample (per-sample early tests against a pixel-centre depth would drop
 * samples a box covers only partly); one pass does not anti-alias rims either. */
static sl_status render_with_prepass(tubes_state *s, const sl_view *view, const sl_params *params,
                                     const sl_line_style *style, sl_render_stats *stats, sl_err *err)
{
    sl_status st = ensure_nearest_image(s, view->width, view->height, err);
    if (st != SL_OK)
        return st;
    const GLuint zero = 0;
    glClearTexImage(s->nearest_tex, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_MULTISAMPLE);

    glUseProgram(s->program_prepass);
    sl_line_style_uniforms(s->program_prepass, style, 0);
    glUniform1i(glGetUniformLocation(s->program_prepass, "u_data_radii"), s->nodes.has_radii);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s->node_vbo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->ibo);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glBindVertexArray(s->empty_vao); /* programmable pulling: no attributes */
    glDrawArrays(GL_POINTS, 0, (GLsizei)(3 * s->nodes.segment_count));
    glBindVertexArray(0);
    glDisable(GL_PROGRAM_POINT_SIZE);

    set_uniforms(s->program_depth, style, params, s->nodes.has_radii);
    glBindImageTexture(0, s->nearest_tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glDepthMask(GL_FALSE);
    draw_boxes(s, stats);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

    glUseProgram(s->program_nearest);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glBindVertexArray(s->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);

    set_uniforms(s->program_shade, style, params, s->nodes.has_radii);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthFunc(GL_GEQUAL);
    glDepthMask(GL_FALSE);
    draw_boxes(s, NULL); /* the same triangles as pass 2: primitives counts one pass */
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT); /* before the next frame's clear of the image */
    glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
    glEnable(GL_MULTISAMPLE);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_GREATER);
    return SL_OK;
}

/* Whether this frame draws with the occlusion pre-pass (occlusion_prepass, auto rule above). */
static int use_prepass(const tubes_state *s, const sl_view *view, const sl_params *params, const sl_line_style *style)
{
    int mode = sl_params_choice(params, "occlusion_prepass");
    if (mode != SL_TUBES_PREPASS_AUTO || s->nodes.segment_count == 0)
        return mode == SL_TUBES_PREPASS_ON && s->nodes.segment_count > 0;
    if ((double)view->width * view->height < SL_TUBES_PREPASS_MIN_PIXELS)
        return 0;
    double bound = sl_dataset_radius(s->dataset);
    sl_vec3 centre = s->dataset->origin, eye = view->camera.eye;
    double dx = eye.x - centre.x, dy = eye.y - centre.y, dz = eye.z - centre.z;
    if (!(bound > 0.0) || dx * dx + dy * dy + dz * dz <= bound * bound)
        return 1;
    double weighted = s->nodes.has_radii ? style->radius_scale * s->length_radius_sum : style->radius * s->length_sum;
    return 2.0 * weighted / (SL_PI * bound * bound) >= SL_TUBES_PREPASS_MIN_DEPTH_COMPLEXITY;
}

/* Backend embree: trace on the CPU, then the frame's colour and depth into the target. */
static sl_status render_embree(tubes_state *s, const sl_view *view, const sl_params *params,
                               const sl_line_style *style, sl_render_stats *stats, sl_err *err)
{
    if (s->embree_attribute != style->attribute) {
        sl_tubes_nodes_set_color(&s->dataset->lines, style->attribute, &s->nodes);
        s->embree_attribute = style->attribute;
    }
    if (sl_params_bool(params, "silhouette_only")) /* a GL experiment: nothing to draw */
        return SL_OK;
    sl_line_shader shader;
    sl_line_shader_init(&shader, style, view);
    sl_status st = sl_tubes_embree_render(s->embree, view, &shader, s->nodes.color, style->radius,
                                          style->radius_scale, &s->host, &stats->rebuild_ms, err);
    if (st != SL_OK) {
        if (!strstr(err->message, "tubes"))
            sl_err_prefix(err, "tubes (embree)");
        return st;
    }
    sl_tubes_embree_stats es;
    sl_tubes_embree_stats_get(s->embree, &es);
    stats->primitives = es.rays;
    stats->threads = es.threads;
    if ((st = sl_host_frame_draw(&s->host, err)) != SL_OK)
        sl_err_prefix(err, "tubes (embree)");
    return st;
}

static sl_status tubes_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                              sl_render_stats *stats, sl_err *err)
{
    (void)target;
    tubes_state *s = opaque;
    sl_status st = sl_line_style_check(params, s->dataset, err);
    if (st != SL_OK)
        return st;
    sl_line_style style;
    sl_line_style_read(params, s->dataset, &style);
    sl_backend_cpu cpu;
    tubes_backend_cpu(&cpu);
    stats->backend = sl_backend_name(s->backend, &cpu);
    stats->culled = 0.0;
    if (s->backend == SL_BACKEND_CPU)
        return render_embree(s, view, params, &style, stats, err);
    if (sl_line_colors_update(&s->colors, &s->dataset->lines, &style)) {
        sl_tubes_nodes_set_color(&s->dataset->lines, style.attribute, &s->nodes);
        if (s->nodes.node_count)
            glNamedBufferSubData(s->color_vbo, 0, (GLsizeiptr)(s->nodes.node_count * 2 * sizeof(float)),
                                 s->nodes.color);
    }
    sl_camera_ubo_update(&s->camera_ubo, view);
    sl_line_colors_bind(&s->colors, 0, 0);
    int silhouette_only = sl_params_bool(params, "silhouette_only");
    if (!silhouette_only && use_prepass(s, view, params, &style))
        return render_with_prepass(s, view, params, &style, stats, err);
    set_uniforms(silhouette_only ? s->program_silhouette : s->program, &style, params, s->nodes.has_radii);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE); /* the geometry shader emits only faces towards the eye */
    draw_boxes(s, stats);
    return SL_OK;
}

static size_t tubes_gpu_bytes(const void *opaque)
{
    const tubes_state *s = opaque;
    return s ? s->gpu_bytes + (size_t)s->nearest_w * (size_t)s->nearest_h * 4u + sl_host_frame_gpu_bytes(&s->host) : 0;
}

static void tubes_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const tubes_state *st = opaque;
    *out = st ? st->prep : (sl_prepare_stats){0};
}

const sl_technique sl_tubes_technique = {
    .name = "tubes",
    .description = "raycast Hermite spline tubes (Russig, Salm, Gumhold: GPU-based Raycasting of Hermite Spline Tubes)",
    .dataset_kinds = SL_DATASET_LINES,
    .params = tubes_params,
    .param_count = (int)(sizeof tubes_params / sizeof tubes_params[0]),
    .prepare = tubes_prepare,
    .render = tubes_render,
    .release = tubes_release,
    .gpu_bytes = tubes_gpu_bytes,
    .prepare_stats = tubes_prepare_stats,
    .backend_cpu = tubes_backend_cpu,
};
