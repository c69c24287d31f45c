/* lr_volume.c — technique `lr_volume`: direct volume rendering of an
 * LR-spline volume (issue 15; Fuchs, Barrowclough, Hjelmervik, Dahl).
 *
 * prepare converts every element to its Bézier block (lrspline/lr_bezier.c)
 * and uploads the blocks and the element look-up (lr_bezier_gpu.c; the
 * dataset model's own index when it is the kind asked for), and
 * builds a proxy of the volume's values for the transfer function (value
 * range and histogram of a 48^3 lattice of exact values, so "auto" opacity
 * and colormap ranges resolve as for volume_dvr, through the shared
 * renderer/volume/ code). render: one full-screen pass of lr_volume.frag.glsl
 * (the model: README.md); the transfer function is baked into volume_dvr's
 * table and texture (re-baked only when it changes, with the per-element
 * visibility of the hulls). Scalar volumes, and vector volumes (dim 3) by
 * their magnitude. With `streamlines` (vector volumes) the lines traced from
 * a seed box over these same blocks are drawn first as tubes
 * (lr_volume_streamlines.c), their depth is copied, and the rays end there
 * and are blended over them (premultiplied, ONE, ONE_MINUS_SRC_ALPHA);
 * without, the shader composites the background itself. PREPARED level: the
 * look-up and what shapes the lines (prepare traces when `streamlines` is
 * on; turned on later, the next render traces once); FRAME: the rest.
 * Render thread only.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../flow/flow_gpu.h"
#include "../gpu/sl_gpu.h"
#include "../lrspline/sl_lr.h"
#include "../lrspline/sl_lr_bezier.h"
#include "../core/sl_colormap.h"
#include "../volume/sl_volume.h"
#include "lr_volume_streamlines.h"

/* On by default, as volume_dvr's: at equal samples it trades the rings of a
 * coarse step for fine noise (README.md "Wood-grain", bench-lr-volume). */
#define JITTER_DEFAULT 1

static const char *const mode_names[] = {"composite", "mip", NULL};
static const char *const step_mode_names[] = {"adaptive", "uniform", NULL};
/* In the order of sl_lr_lookup_kind. */
static const char *const lookup_names[] = {"auto", "texture", "octree", "kdtree", "kdforest", NULL};

static const char *const tube_backends[] = {"auto", "gl", "embree", NULL};

static const sl_param_def lr_volume_params[] = {
    {"transfer_function", SL_PARAM_TRANSFER, 0, 0, {0, SL_TF_AUTO_OPACITY, 0}, NULL, "data",
     "colour and opacity per data value (vectors: of the magnitude), as volume_dvr's; opacity per smallest "
     "element side", SL_INVALIDATE_FRAME},
    {"mode", SL_PARAM_ENUM, 0, 0, {0}, mode_names, "", "composite (emission-absorption), mip (maximum intensity)",
     SL_INVALIDATE_FRAME},
    {"step_mode", SL_PARAM_ENUM, 0, 0, {0}, step_mode_names, "",
     "adaptive: step = smallest side of the element at the sample / 2^step_depth (paper Eq. 4); "
     "uniform: step x the smallest element side everywhere", SL_INVALIDATE_FRAME},
    {"step", SL_PARAM_FLOAT, 0.01, 16.0, {0.5}, NULL, "element",
     "uniform: sampling distance in units of the smallest element side (opacity is corrected for it)",
     SL_INVALIDATE_FRAME},
    {"step_depth", SL_PARAM_INT, 0, 10, {1}, NULL, "", "adaptive: d of the step min side / 2^d", SL_INVALIDATE_FRAME},
    {"alpha_threshold", SL_PARAM_FLOAT, 0.01, 1.0, {0.99}, NULL, "", "composite: stop a ray at this opacity",
     SL_INVALIDATE_FRAME},
    {"shading", SL_PARAM_BOOL, 0, 1, {1}, NULL, "",
     "composite: colour times max(0.4, |l.n|), n the exact unit gradient, l the view ray (paper)",
     SL_INVALIDATE_FRAME},
    {"jitter", SL_PARAM_BOOL, 0, 1, {JITTER_DEFAULT}, NULL, "",
     "sample each segment at a per-pixel offset (a fixed hash of the pixel, so frames repeat) instead of its "
     "midpoint: wood-grain becomes fine noise at the same sample count", SL_INVALIDATE_FRAME},
    {"empty_space_skipping", SL_PARAM_BOOL, 0, 1, {1}, NULL, "",
     "jump over elements whose value hull (convex hull of the Bézier coefficients) cannot contribute (same image)",
     SL_INVALIDATE_FRAME},
    {"lookup", SL_PARAM_ENUM, 0, 0, {0}, lookup_names, "",
     "element look-up (paper 3.2): auto = texture where the knots lie on a regular grid, else the k-d forest; "
     "octree needs dyadic knots (refused otherwise)", SL_INVALIDATE_PREPARED},
    {"forest_blocks", SL_PARAM_INT, 0, 128, {0}, NULL, "",
     "kdforest: blocks per direction (0: the default, 32)", SL_INVALIDATE_PREPARED},
    {"streamlines", SL_PARAM_BOOL, 0, 1, {0}, NULL, "",
     "vector volumes: streamlines from the seed box, traced on the GPU and drawn as tubes coloured by speed, "
     "the volume composited in front of them", SL_INVALIDATE_FRAME},
    {"seed_min", SL_PARAM_VEC3, 0.0, 1.0, {0.1, 0.1, 0.1}, NULL, "domain",
     "streamlines: one corner of the seed box, in fractions of the domain", SL_INVALIDATE_PREPARED},
    {"seed_max", SL_PARAM_VEC3, 0.0, 1.0, {0.9, 0.9, 0.9}, NULL, "domain",
     "streamlines: the opposite corner of the seed box", SL_INVALIDATE_PREPARED},
    {"seed_count", SL_PARAM_INT, 1, 4096, {64}, NULL, "",
     "streamlines: seeds in the box (Halton points, deterministic)", SL_INVALIDATE_PREPARED},
    {"solver", SL_PARAM_ENUM, 0, 0, {SL_FLOW_RK4}, sl_flow_solver_names, "",
     "streamlines: Runge-Kutta method; he, bs and rkf45 adapt their step to flow_tol, the others take the "
     "paper's heuristic step", SL_INVALIDATE_PREPARED},
    {"flow_step", SL_PARAM_FLOAT, 0.01, 16.0, {1.0}, NULL, "element",
     "streamlines, fixed-step solvers: h = flow_step x the element's smallest side / 2^degree (paper Eq. 4)",
     SL_INVALIDATE_PREPARED},
    {"flow_tol", SL_PARAM_FLOAT, 1e-12, 1.0, {1e-6}, NULL, "world",
     "streamlines, adaptive solvers: largest error of a step (embedded pair)", SL_INVALIDATE_PREPARED},
    {"t_max", SL_PARAM_FLOAT, 1e-6, 1e6, {10.0}, NULL, "time", "streamlines: integration time per line",
     SL_INVALIDATE_PREPARED},
    {"max_samples", SL_PARAM_INT, 2, 100000, {2000}, NULL, "", "streamlines: samples per line at most",
     SL_INVALIDATE_PREPARED},
    {"precision", SL_PARAM_ENUM, 0, 0, {SL_FLOW_MIXED}, sl_flow_precision_names, "",
     "streamlines: single, mixed (double update, float spline) or double (paper 5.6)", SL_INVALIDATE_PREPARED},
    {"tube_radius", SL_PARAM_FLOAT, 0.0, 0.1, {0.003}, NULL, "domain diagonal",
     "streamlines: tube radius as a fraction of the domain's diagonal; 0 = the tubes' automatic radius "
     "(1/300 of the lines' bounding radius)", SL_INVALIDATE_FRAME},
    {"tube_colormap", SL_PARAM_ENUM, 0, 0, {0}, sl_colormap_names, "", "streamlines: colormap of the speed",
     SL_INVALIDATE_FRAME},
    {"tube_backend", SL_PARAM_ENUM, 0, 0, {0}, tube_backends, "",
     "streamlines: the tubes' backend (auto: embree on a software GL device, gl on a GPU; gl; embree)",
     SL_INVALIDATE_PREPARED},
};

enum { UNIT_TF = 1, UNIT_OPAQUE_DEPTH = 2, ROWS_BINDING = 5, VISIBLE_BINDING = 4, PROXY_N = 48, MAX_STEPS = 1 << 16 };

typedef struct lr_volume_state {
    const sl_lr_volume *lr;        /* borrowed from the dataset */
    sl_lr_bezier bz;
    sl_lr_bezier_gpu blocks;
    GLuint programs[2];            /* per mode, compiled on first use */
    GLuint vao, camera_ubo, tf_tex, rows_buf, visible_buf;
    int rows_capacity;
    sl_volume proxy;               /* value range and histogram only (no voxels) */
    sl_volume_tf_table *table;
    sl_transfer_function tf_loaded;
    int tf_emission_absorption;    /* composite (1) or mip (0): the automatic ramp differs */
    int tf_valid;
    size_t visible_elements;
    double ref;                    /* the smallest element side (world) */
    lrv_streamlines streamlines;   /* traced in prepare, or at the first frame that asks */
    size_t gpu_bytes;              /* without the blocks (blocks.bytes grows with their double copies) */
    sl_prepare_stats prep;
} lr_volume_state;

static void lr_volume_release(void *opaque)
{
    lr_volume_state *s = opaque;
    if (!s)
        return;
    for (int i = 0; i < 2; i++)
        if (s->programs[i])
            glDeleteProgram(s->programs[i]);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    if (s->tf_tex) glDeleteTextures(1, &s->tf_tex);
    if (s->rows_buf) glDeleteBuffers(1, &s->rows_buf);
    if (s->visible_buf) glDeleteBuffers(1, &s->visible_buf);
    lrv_streamlines_deinit(&s->streamlines);
    sl_lr_bezier_release(&s->blocks);
    sl_lr_bezier_free(&s->bz);
    free(s->table);
    free(s);
}

/* The proxy's value range and histogram from an exact lattice of PROXY_N^3
 * points over the domain (each point evaluated in the element the rule
 * gives it, found per element from index ranges), plus the model's own
 * value_min/max sample. */
static sl_status build_proxy(lr_volume_state *s, sl_err *err)
{
    const sl_lr_volume *lr = s->lr;
    size_t n = (size_t)PROXY_N * PROXY_N * PROXY_N;
    float *v = malloc(sizeof(float) * n);
    if (!v)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the value proxy");
    for (size_t i = 0; i < n; i++)
        v[i] = NAN;
    double x[3][PROXY_N];
    for (int a = 0; a < 3; a++)
        for (int i = 0; i < PROXY_N; i++)
            x[a][i] = i == PROXY_N - 1 ? lr->domain_hi[a]
                                       : lr->domain_lo[a] + (lr->domain_hi[a] - lr->domain_lo[a]) * i / (PROXY_N - 1);
    for (size_t e = 0; e < lr->element_count; e++) {
        const sl_lr_element *el = &lr->elements[e];
        int b[3], f[3];
        for (int a = 0; a < 3; a++) {
            b[a] = 0;
            while (b[a] < PROXY_N && x[a][b[a]] < el->lo[a])
                b[a]++;
            f[a] = b[a];
            while (f[a] < PROXY_N && (x[a][f[a]] < el->hi[a] || (el->hi[a] == lr->domain_hi[a] && x[a][f[a]] == el->hi[a])))
                f[a]++;
        }
        for (int k = b[2]; k < f[2]; k++)
            for (int j = b[1]; j < f[1]; j++)
                for (int i = b[0]; i < f[0]; i++) {
                    double p[3] = {x[0][i], x[1][j], x[2][k]}, val[3];
                    sl_lr_bezier_eval(&s->bz, e, p, val, NULL);
                    double m = lr->dim == 1 ? val[0] : sqrt(val[0] * val[0] + val[1] * val[1] + val[2] * val[2]);
                    v[((size_t)k * PROXY_N + (size_t)j) * PROXY_N + (size_t)i] = (float)m;
                }
    }
    sl_volume *pv = &s->proxy;
    memset(pv, 0, sizeof *pv);
    /* No voxels: dims and spacing describe the domain in cells of side
     * s->ref, the length opacity is per here, which is all the automatic
     * ramp's optical-depth bound reads of them (sl_volume_tf_ramp_depth). */
    pv->components = 1;
    pv->type = SL_VOXEL_F32;
    for (int a = 0; a < 3; a++) {
        double cells = (lr->domain_hi[a] - lr->domain_lo[a]) / s->ref;
        pv->dims[a] = cells < 1.0 ? 1 : cells > 1e6 ? 1000000 : (int)lround(cells);
        pv->spacing[a] = s->ref;
    }
    double lo = lr->value_min, hi = lr->value_max;
    for (size_t i = 0; i < n; i++)
        if (isfinite(v[i])) {
            lo = fmin(lo, v[i]);
            hi = fmax(hi, v[i]);
        }
    pv->value_min = lo;
    pv->value_max = hi;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(v[i]))
            continue;
        int bin = hi > lo ? (int)floor((v[i] - lo) / (hi - lo) * SL_VOLUME_HISTOGRAM_BINS) : 0;
        bin = bin < 0 ? 0 : bin >= SL_VOLUME_HISTOGRAM_BINS ? SL_VOLUME_HISTOGRAM_BINS - 1 : bin;
        pv->histogram[bin]++;
        pv->finite_count++;
    }
    free(v);
    return SL_OK;
}

static sl_status lr_volume_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out,
                                   sl_err *err)
{
    *out = NULL;
    if (ds->kind != SL_DATASET_LR || !ds->lr)
        return sl_err_set(err, SL_ERR_INVALID, "lr_volume: the dataset is not an LR-spline volume");
    lr_volume_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "lr_volume: out of memory");
    s->lr = ds->lr;
    lrv_streamlines_init(&s->streamlines, gpu, ds, &s->bz, &s->blocks);
    s->ref = fmin(fmin(ds->lr->min_side[0], ds->lr->min_side[1]), ds->lr->min_side[2]);
    double t_pre = sl_clock_ms();
    sl_status st = sl_lr_bezier_build(s->lr, (sl_lr_lookup_kind)sl_params_choice(params, "lookup"),
                                      sl_params_int(params, "forest_blocks"), &s->bz, err);
    if (st == SL_OK)
        st = build_proxy(s, err);
    if (st == SL_OK && !(s->table = malloc(sizeof *s->table)))
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the transfer function table");
    s->prep.preprocess_ms = sl_clock_ms() - t_pre;
    double t_up = sl_clock_ms();
    if (st == SL_OK)
        st = sl_lr_bezier_upload(&s->bz, 0, &s->blocks, err);
    if (st == SL_OK)
        st = sl_volume_tf_texture_create(&s->tf_tex, err);
    if (st == SL_OK) {
        glCreateBuffers(1, &s->visible_buf);
        glNamedBufferStorage(s->visible_buf, (GLsizeiptr)(sizeof(GLuint) * s->bz.element_count), NULL,
                             GL_DYNAMIC_STORAGE_BIT);
        glCreateVertexArrays(1, &s->vao);
        glFinish();
        st = sl_gl_check_errors("lr_volume: preparing", err);
    }
    s->prep.upload_ms = sl_clock_ms() - t_up;
    if (st != SL_OK) {
        sl_err_prefix(err, "lr_volume");
        lr_volume_release(s);
        return st;
    }
    s->gpu_bytes = SL_VOLUME_TF_TEXELS * 16 + sizeof(GLuint) * s->bz.element_count;
    sl_prepare_stats_add(&s->prep, "elements", (double)s->bz.element_count);
    sl_prepare_stats_add(&s->prep, "block_bytes", (double)s->blocks.bytes);
    sl_prepare_stats_add(&s->prep, "min_side", s->ref);
    if (sl_params_bool(params, "streamlines")) {
        const lrv_streamlines *l = &s->streamlines;
        if ((st = lrv_streamlines_trace(&s->streamlines, params, err)) != SL_OK) {
            lr_volume_release(s);
            return st;
        }
        sl_prepare_stats_add(&s->prep, "streamlines", (double)l->line_count);
        sl_prepare_stats_add(&s->prep, "streamline_samples", (double)l->sample_count);
        sl_prepare_stats_add(&s->prep, "streamline_trace_ms", l->trace_ms);
        sl_prepare_stats_add(&s->prep, "streamline_compute_ms", l->compute_ms);
        sl_prepare_stats_add(&s->prep, "streamline_tubes_ms", l->tubes_ms);
    }
    *out = s;
    return SL_OK;
}

static sl_status program_for(lr_volume_state *s, int mode, GLuint *out, sl_err *err)
{
    if (!s->programs[mode]) {
        char defines[256], label[32];
        int used = snprintf(defines, sizeof defines, "#define LR_MODE %d\n", mode);
        sl_lr_bezier_defines(&s->bz, 0, defines + used, sizeof defines - (size_t)used);
        snprintf(label, sizeof label, "lr_volume (mode %d)", mode);
        sl_status st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                               .fragment = "lr_volume/lr_volume.frag.glsl",
                                                               .defines = defines, .label = label},
                                            &s->programs[mode], err);
        if (st != SL_OK)
            return st;
    }
    *out = s->programs[mode];
    return SL_OK;
}

/* Re-bakes the transfer function and the per-element visibility when it changed. */
static void update_tf(lr_volume_state *s, const sl_transfer_function *tf, int emission_absorption)
{
    if (s->tf_valid && sl_transfer_function_equal(tf, &s->tf_loaded) &&
        (!tf->auto_opacity || emission_absorption == s->tf_emission_absorption))
        return;
    sl_volume_tf_points pts;
    sl_volume_tf_resolve(tf, &s->proxy, emission_absorption, &pts);
    s->tf_emission_absorption = emission_absorption;
    sl_volume_tf_bake(&pts, s->table);
    sl_volume_tf_texture_upload(s->tf_tex, s->table);
    GLuint *vis = malloc(sizeof(GLuint) * s->bz.element_count);
    s->visible_elements = 0;
    if (vis) {
        for (size_t e = 0; e < s->bz.element_count; e++) {
            vis[e] = (GLuint)sl_volume_tf_table_visible(s->table, s->bz.hull_min[e], s->bz.hull_max[e]);
            s->visible_elements += vis[e];
        }
        glNamedBufferSubData(s->visible_buf, 0, (GLsizeiptr)(sizeof(GLuint) * s->bz.element_count), vis);
        free(vis);
    } else { /* no scratch: every element visible (same image, no skipping) */
        GLuint one = 1;
        glClearNamedBufferData(s->visible_buf, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &one);
        s->visible_elements = s->bz.element_count;
    }
    s->tf_loaded = *tf;
    s->tf_valid = 1;
}

static sl_status lr_volume_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                                  sl_render_stats *stats, sl_err *err)
{
    lr_volume_state *s = opaque;
    int mode = sl_params_choice(params, "mode");
    GLuint p = 0;
    sl_status st = program_for(s, mode, &p, err);
    if (st != SL_OK)
        return st;
    /* Streamlines first: the tubes' depth ends the rays, which blend over them.
     * Turned on after the prepare (FRAME level), this frame traces once. */
    int over = sl_params_bool(params, "streamlines");
    if (over && !s->streamlines.traced) {
        double t0 = sl_clock_ms();
        if ((st = lrv_streamlines_trace(&s->streamlines, params, err)) != SL_OK)
            return st;
        stats->rebuild_ms = sl_clock_ms() - t0;
    }
    if (over && (st = lrv_streamlines_draw(&s->streamlines, view, params, target, stats, err)) != SL_OK)
        return st;
    update_tf(s, sl_params_transfer(params, "transfer_function"), mode == 0);
    if (view->height > s->rows_capacity) {
        if (s->rows_buf)
            glDeleteBuffers(1, &s->rows_buf);
        glCreateBuffers(1, &s->rows_buf);
        glNamedBufferStorage(s->rows_buf, (GLsizeiptr)view->height * 2 * sizeof(GLuint), NULL,
                             GL_DYNAMIC_STORAGE_BIT);
        s->rows_capacity = view->height;
    }
    glClearNamedBufferData(s->rows_buf, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    /* Interactive frames sample half as densely (as volume_dvr). */
    double step = sl_params_float(params, "step");
    int depth = sl_params_int(params, "step_depth");
    if (view->quality == SL_QUALITY_INTERACTIVE) {
        step = fmin(2.0 * step, 16.0);
        depth = depth > 0 ? depth - 1 : 0;
    }
    sl_camera_ubo_update(&s->camera_ubo, view);
    glUseProgram(p);
    sl_lr_bezier_set_uniforms(p, &s->bz);
    sl_lr_bezier_bind(&s->blocks, p);
    glUniform3f(glGetUniformLocation(p, "u_background"), view->background[0], view->background[1],
                view->background[2]);
    glUniform1i(glGetUniformLocation(p, "u_adaptive"), sl_params_choice(params, "step_mode") == 0);
    glUniform1f(glGetUniformLocation(p, "u_adapt"), (float)ldexp(1.0, -depth));
    glUniform1f(glGetUniformLocation(p, "u_dt"), (float)(step * s->ref));
    glUniform1f(glGetUniformLocation(p, "u_ref"), (float)s->ref);
    glUniform1f(glGetUniformLocation(p, "u_alpha_stop"), (float)sl_params_float(params, "alpha_threshold"));
    glUniform1i(glGetUniformLocation(p, "u_shading"), sl_params_bool(params, "shading"));
    glUniform1i(glGetUniformLocation(p, "u_skipping"), sl_params_bool(params, "empty_space_skipping"));
    glUniform1i(glGetUniformLocation(p, "u_max_steps"), MAX_STEPS);
    glUniform1i(glGetUniformLocation(p, "u_jitter"), sl_params_bool(params, "jitter"));
    glUniform2f(glGetUniformLocation(p, "u_tf_map"), (float)s->table->lo,
                (float)((SL_VOLUME_TF_TEXELS - 1) / (s->table->hi - s->table->lo)));
    glUniform1i(glGetUniformLocation(p, "u_tf"), UNIT_TF);
    glBindTextureUnit(UNIT_TF, s->tf_tex);
    glUniform1i(glGetUniformLocation(p, "u_over_target"), over);
    glUniform1i(glGetUniformLocation(p, "u_opaque_depth"), UNIT_OPAQUE_DEPTH);
    glBindTextureUnit(UNIT_OPAQUE_DEPTH, over ? s->streamlines.depth.texture : 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ROWS_BINDING, s->rows_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VISIBLE_BINDING, s->visible_buf);
    if (over) {
        glEnable(GL_BLEND);
        glBlendEquation(GL_FUNC_ADD);
        glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    } else {
        glDisable(GL_BLEND);
    }
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(s->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDepthFunc(GL_GREATER);
    glDisable(GL_BLEND);
    glBindTextureUnit(UNIT_OPAQUE_DEPTH, 0);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    GLuint *rows = malloc((size_t)view->height * 2 * sizeof *rows);
    double taken = 0.0, skipped = 0.0;
    if (rows) {
        glGetNamedBufferSubData(s->rows_buf, 0, (GLsizeiptr)view->height * 2 * sizeof *rows, rows);
        for (int y = 0; y < view->height; y++) {
            taken += rows[2 * y];
            skipped += rows[2 * y + 1];
        }
        free(rows);
    }
    stats->primitives += (double)view->width * view->height;
    stats->samples = taken;
    stats->samples_skipped = skipped;
    stats->culled = (double)(s->bz.element_count - s->visible_elements);
    return SL_OK;
}

static void lr_volume_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const lr_volume_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

static size_t lr_volume_gpu_bytes(const void *opaque)
{
    const lr_volume_state *s = opaque;
    return s ? s->gpu_bytes + s->blocks.bytes + lrv_streamlines_gpu_bytes(&s->streamlines) : 0;
}

const sl_technique sl_lr_volume_technique = {
    .name = "lr_volume",
    .description = "direct volume rendering of LR-spline volumes, exact Bézier evaluation per sample, "
                   "adaptive step (Fuchs, Barrowclough, Hjelmervik, Dahl)",
    .dataset_kinds = SL_DATASET_LR,
    .params = lr_volume_params,
    .param_count = (int)(sizeof lr_volume_params / sizeof lr_volume_params[0]),
    .prepare = lr_volume_prepare,
    .render = lr_volume_render,
    .release = lr_volume_release,
    .gpu_bytes = lr_volume_gpu_bytes,
    .prepare_stats = lr_volume_prepare_stats,
};
