/* volume_dvr.c — technique `volume_dvr`: GPU ray-marched direct volume rendering.
 *
 * Emission–absorption compositing, maximum intensity projection and a
 * shaded first-hit isosurface of one scalar volume (vector fields: their
 * magnitude), one full-screen ray-march pass (volume_dvr.frag.glsl) over the
 * shared volume preparation of renderer/volume/ (3D texture, baked transfer
 * function, min-max bricks). prepare uploads the volume and builds the brick
 * grid once; every parameter is FRAME level: a new transfer function
 * re-bakes the 1D TF texture and rebuilds the brick mask (a mode or
 * isovalue change only the mask), a camera move uploads nothing (counted in
 * sl_volume_counters). The model the frames follow is stated in README.md
 * (checked against tests/support/volume_reference.h). Render thread only.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../core/sl_colormap.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../volume/sl_volume.h"

static const char *const mode_names[] = {"composite", "mip", "iso", NULL};
static const char *const interpolation_names[] = {"linear", "nearest", NULL};
static const char *const gradient_names[] = {"on_the_fly", "texture", NULL};

static const sl_param_def volume_dvr_params[] = {
    {"transfer_function", SL_PARAM_TRANSFER, 0, 0, {0, SL_TF_AUTO_OPACITY, 0}, NULL, "data",
     "colour and opacity per data value: points [[value, r, g, b, a], ...] or {colormap, opacity ramp, range}; "
     "default viridis over the value range with an opacity ramp chosen from the histogram", SL_INVALIDATE_FRAME},
    {"mode", SL_PARAM_ENUM, 0, 0, {0}, mode_names, "",
     "composite (emission-absorption), mip (maximum intensity), iso (first crossing of isovalue, shaded)",
     SL_INVALIDATE_FRAME},
    {"isovalue", SL_PARAM_FLOAT, -1e30, 1e30, {0.5}, NULL, "data", "iso mode: the surface's value",
     SL_INVALIDATE_FRAME},
    {"step", SL_PARAM_FLOAT, 0.01, 16.0, {0.5}, NULL, "voxel",
     "sampling distance in units of the smallest voxel spacing (opacity is corrected for it)", SL_INVALIDATE_FRAME},
    {"jitter", SL_PARAM_BOOL, 0, 1, {1}, NULL, "", "per-pixel random start within a step (against wood-grain)",
     SL_INVALIDATE_FRAME},
    {"alpha_threshold", SL_PARAM_FLOAT, 0.01, 1.0, {0.99}, NULL, "", "composite: stop a ray at this opacity",
     SL_INVALIDATE_FRAME},
    {"interpolation", SL_PARAM_ENUM, 0, 0, {0}, interpolation_names, "", "trilinear or nearest voxel",
     SL_INVALIDATE_FRAME},
    {"shading", SL_PARAM_BOOL, 0, 1, {0}, NULL, "",
     "composite: Blinn-Phong with the gradient (central differences) as normal", SL_INVALIDATE_FRAME},
    {"gradient", SL_PARAM_ENUM, 0, 0, {0}, gradient_names, "",
     "shading normals: central differences per sample (6 fetches) or a precomputed gradient texture (1 fetch, "
     "4 bytes per voxel, built once when first used)", SL_INVALIDATE_FRAME},
    {"empty_space_skipping", SL_PARAM_BOOL, 0, 1, {1}, NULL, "",
     "jump over 8^3 bricks that cannot contribute (same image)", SL_INVALIDATE_FRAME},
    {"clip_min", SL_PARAM_VEC3, 0.0, 1.0, {0, 0, 0}, NULL, "normalized", "clip box corner, 0..1 of the volume box",
     SL_INVALIDATE_FRAME},
    {"clip_max", SL_PARAM_VEC3, 0.0, 1.0, {1, 1, 1}, NULL, "normalized", "clip box corner, 0..1 of the volume box",
     SL_INVALIDATE_FRAME},
    {"light_direction", SL_PARAM_VEC3, -1.0, 1.0, {0.3, 0.5, 1.0}, NULL, "eye space",
     "direction towards the light: x right, y up, z towards the viewer", SL_INVALIDATE_FRAME},
    {"ambient", SL_PARAM_FLOAT, 0.0, 1.0, {0.25}, NULL, "", "ambient light", SL_INVALIDATE_FRAME},
    {"diffuse", SL_PARAM_FLOAT, 0.0, 1.0, {0.75}, NULL, "", "Lambert diffuse weight", SL_INVALIDATE_FRAME},
    {"specular", SL_PARAM_FLOAT, 0.0, 1.0, {0.3}, NULL, "", "Blinn-Phong specular weight", SL_INVALIDATE_FRAME},
    {"shininess", SL_PARAM_FLOAT, 1.0, 512.0, {32}, NULL, "", "Blinn-Phong exponent", SL_INVALIDATE_FRAME},
};

enum { MODE_COMPOSITE, MODE_MIP, MODE_ISO };

/* Shader variants: mode x shading x gradient source (volume_dvr.frag.glsl's
 * SL_MODE, SL_SHADING, SL_GRADIENT_TEX); mip never shades. */
#define PROGRAM_VARIANTS 12
static int variant_of(int mode, int shading, int gradient_tex)
{
    return mode + 3 * (shading != 0) + 6 * (shading && gradient_tex);
}

typedef struct volume_dvr_state {
    const sl_dataset *dataset;     /* borrowed */
    sl_volume_geometry geom;
    sl_volume_texture volume;
    sl_volume_bricks bricks;
    GLuint programs[PROGRAM_VARIANTS]; /* by variant_of(); compiled on first use, 0 until then */
    GLuint vao, camera_ubo, tf_tex, rows_buf;
    GLuint gradient_tex;           /* built at the first frame that shades with it, or 0 */
    int rows_capacity;             /* pixel rows rows_buf holds */
    sl_volume_tf_table *table;     /* owned; the baked loaded TF */
    sl_transfer_function tf_loaded;
    int tf_valid;
    int mask_rule;                 /* sl_volume_mask_rule of the mask, or -1 */
    double mask_iso;
    size_t visible_bricks;
    size_t gpu_bytes;
    sl_prepare_stats prep;
} volume_dvr_state;

static void volume_dvr_release(void *opaque)
{
    volume_dvr_state *s = opaque;
    if (!s)
        return;
    sl_volume_texture_destroy(&s->volume);
    sl_volume_bricks_destroy(&s->bricks);
    for (int i = 0; i < PROGRAM_VARIANTS; i++)
        if (s->programs[i])
            glDeleteProgram(s->programs[i]);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    if (s->tf_tex) glDeleteTextures(1, &s->tf_tex);
    if (s->rows_buf) glDeleteBuffers(1, &s->rows_buf);
    if (s->gradient_tex) glDeleteTextures(1, &s->gradient_tex);
    free(s->table);
    free(s);
}

/* The program of a variant, compiled the first time it is asked for
 * (about 0.1-0.3 s on llvmpipe; the composite one at prepare). */
static sl_status program_for(volume_dvr_state *s, int variant, GLuint *out, sl_err *err)
{
    if (!s->programs[variant]) {
        int mode = variant % 3, shading = variant >= 3, gradient_tex = variant >= 6;
        char defines[128], label[48];
        snprintf(defines, sizeof defines, "#define SL_MODE %d\n#define SL_SHADING %d\n#define SL_GRADIENT_TEX %d\n",
                 mode, shading, gradient_tex);
        snprintf(label, sizeof label, "volume_dvr (variant %d)", variant);
        sl_status st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                               .fragment = "volume_dvr/volume_dvr.frag.glsl",
                                                               .defines = defines, .label = label},
                                            &s->programs[variant], err);
        if (st != SL_OK)
            return st;
    }
    *out = s->programs[variant];
    return SL_OK;
}

static sl_status volume_dvr_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out,
                                    sl_err *err)
{
    (void)gpu;
    (void)params;
    *out = NULL;
    volume_dvr_state *s = calloc(1, sizeof *s);
    if (!s || !(s->table = malloc(sizeof *s->table))) {
        free(s);
        return sl_err_set(err, SL_ERR_NOMEM, "volume_dvr: out of memory");
    }
    s->dataset = ds;
    s->mask_rule = -1;
    sl_volume_geometry_init(ds, &s->geom);
    GLuint program = 0;
    sl_status st = program_for(s, variant_of(MODE_COMPOSITE, 0, 0), &program, err);
    if (st != SL_OK)
        goto fail;
    double t_upload = sl_clock_ms();
    if ((st = sl_volume_texture_create(&ds->volume, &s->volume, err)) != SL_OK)
        goto fail;
    double t_bricks = sl_clock_ms();
    if ((st = sl_volume_bricks_create(&ds->volume, &s->bricks, err)) != SL_OK)
        goto fail;
    s->prep.preprocess_ms = sl_clock_ms() - t_bricks; /* includes the (small) brick uploads */
    if ((st = sl_volume_tf_texture_create(&s->tf_tex, err)) != SL_OK)
        goto fail;
    glCreateVertexArrays(1, &s->vao);
    glFinish();
    s->prep.upload_ms = sl_clock_ms() - t_upload - s->prep.preprocess_ms;
    if ((st = sl_gl_check_errors("volume_dvr: preparing", err)) != SL_OK)
        goto fail;
    s->gpu_bytes = s->volume.bytes + s->bricks.bytes + SL_VOLUME_TF_TEXELS * 16;
    *out = s;
    return SL_OK;
fail:
    sl_err_prefix(err, "volume_dvr");
    volume_dvr_release(s);
    return st;
}

/* Re-bakes the TF when it changed and rebuilds the brick mask when its
 * rule (mode), the TF (composite) or the isovalue (iso) changed. */
static void update_tf_and_mask(volume_dvr_state *s, const sl_params *params, int mode, double iso)
{
    const sl_transfer_function *tf = sl_params_transfer(params, "transfer_function");
    int tf_changed = !s->tf_valid || !sl_transfer_function_equal(tf, &s->tf_loaded);
    if (tf_changed) {
        sl_volume_tf_points pts;
        sl_volume_tf_resolve(tf, &s->dataset->volume, &pts);
        sl_volume_tf_bake(&pts, s->table);
        sl_volume_tf_texture_upload(s->tf_tex, s->table);
        s->tf_loaded = *tf;
        s->tf_valid = 1;
    }
    int rule = mode == MODE_COMPOSITE ? SL_VOLUME_MASK_TF : mode == MODE_ISO ? SL_VOLUME_MASK_ISO
                                                                              : SL_VOLUME_MASK_FINITE;
    if (rule != s->mask_rule || (rule == SL_VOLUME_MASK_TF && tf_changed) ||
        (rule == SL_VOLUME_MASK_ISO && iso != s->mask_iso)) {
        s->visible_bricks = sl_volume_bricks_update_mask(&s->bricks, (sl_volume_mask_rule)rule, s->table, iso);
        s->mask_rule = rule;
        s->mask_iso = iso;
    }
}

static void set1i(GLuint p, const char *name, int v) { glUniform1i(glGetUniformLocation(p, name), v); }
static void set1f(GLuint p, const char *name, double v) { glUniform1f(glGetUniformLocation(p, name), (float)v); }
static void set3f(GLuint p, const char *name, const double v[3])
{
    glUniform3f(glGetUniformLocation(p, name), (float)v[0], (float)v[1], (float)v[2]);
}

static sl_status volume_dvr_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                                   sl_render_stats *stats, sl_err *err)
{
    (void)target;
    volume_dvr_state *s = opaque;
    const sl_volume_geometry *g = &s->geom;
    int mode = sl_params_choice(params, "mode");
    double iso = sl_params_float(params, "isovalue");
    update_tf_and_mask(s, params, mode, iso);
    int shading = (sl_params_bool(params, "shading") && mode == MODE_COMPOSITE) || mode == MODE_ISO;
    int gradient_tex = shading && sl_params_choice(params, "gradient") == 1;
    if (gradient_tex && !s->gradient_tex) {
        size_t bytes = 0;
        sl_status st = sl_volume_gradient_create(&s->dataset->volume, &s->gradient_tex, &bytes, err);
        if (st != SL_OK)
            return st;
        s->gpu_bytes += bytes;
    }
    sl_volume_texture_set_filter(&s->volume, sl_params_choice(params, "interpolation") == 0);

    if (view->height > s->rows_capacity) {
        if (s->rows_buf)
            glDeleteBuffers(1, &s->rows_buf);
        glCreateBuffers(1, &s->rows_buf);
        glNamedBufferStorage(s->rows_buf, (GLsizeiptr)view->height * 2 * sizeof(GLuint), NULL,
                             GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
        s->rows_capacity = view->height;
    }
    glClearNamedBufferData(s->rows_buf, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);

    /* Voxel coordinates: (world - volume origin) / spacing. */
    double eye_v[3], inv_spacing[3], lo[3], hi[3];
    const double eye[3] = {view->camera.eye.x, view->camera.eye.y, view->camera.eye.z};
    const double org[3] = {g->origin.x, g->origin.y, g->origin.z};
    float clip_min[3], clip_max[3];
    sl_params_vec3(params, "clip_min", clip_min);
    sl_params_vec3(params, "clip_max", clip_max);
    for (int a = 0; a < 3; a++) {
        eye_v[a] = (eye[a] - org[a]) / g->spacing[a];
        inv_spacing[a] = 1.0 / g->spacing[a];
        double span = g->box_hi[a] - g->box_lo[a];
        lo[a] = g->box_lo[a] + clip_min[a] * span;
        hi[a] = g->box_lo[a] + clip_max[a] * span;
    }
    /* Interactive frames (a camera drag) sample half as densely; the
     * opacity correction keeps their look, only finer detail is lost. */
    double step = sl_params_float(params, "step");
    if (view->quality == SL_QUALITY_INTERACTIVE)
        step = fmin(2.0 * step, 16.0);
    const double bg[3] = {view->background[0], view->background[1], view->background[2]};
    /* Light: eye space (x right, y up, z towards the viewer) to world. */
    float l[3];
    sl_params_vec3(params, "light_direction", l);
    double ll = sqrt((double)l[0] * l[0] + (double)l[1] * l[1] + (double)l[2] * l[2]);
    double le[3] = {0.0, 0.0, 1.0};
    if (ll > 0.0)
        for (int c = 0; c < 3; c++)
            le[c] = l[c] / ll;
    sl_vec3 lw = sl_v3_add(sl_v3_add(sl_v3_scale(view->right, le[0]), sl_v3_scale(view->upv, le[1])),
                           sl_v3_scale(view->forward, -le[2]));
    const double light[3] = {lw.x, lw.y, lw.z};

    sl_camera_ubo_update(&s->camera_ubo, view);
    GLuint p = 0;
    sl_status pst = program_for(s, variant_of(mode, shading, gradient_tex), &p, err);
    if (pst != SL_OK)
        return pst;
    glUseProgram(p);
    set3f(p, "u_eye_v", eye_v);
    set3f(p, "u_inv_spacing", inv_spacing);
    set3f(p, "u_box_lo", lo);
    set3f(p, "u_box_hi", hi);
    set1f(p, "u_dt", step * g->min_spacing);
    set1f(p, "u_step", step);
    set1f(p, "u_min_spacing", g->min_spacing);
    set1f(p, "u_iso", iso);
    set1f(p, "u_alpha_stop", sl_params_float(params, "alpha_threshold"));
    set1i(p, "u_jitter", sl_params_bool(params, "jitter"));
    set1i(p, "u_skipping", sl_params_bool(params, "empty_space_skipping"));
    glUniform3i(glGetUniformLocation(p, "u_brick_dims"), s->bricks.dims[0], s->bricks.dims[1], s->bricks.dims[2]);
    set3f(p, "u_background", bg);
    set3f(p, "u_light_world", light);
    glUniform4f(glGetUniformLocation(p, "u_material"), (float)sl_params_float(params, "ambient"),
                (float)sl_params_float(params, "diffuse"), (float)sl_params_float(params, "specular"),
                (float)sl_params_float(params, "shininess"));
    glUniform3f(glGetUniformLocation(p, "u_dims"), (float)g->dims[0], (float)g->dims[1], (float)g->dims[2]);
    glUniform2f(glGetUniformLocation(p, "u_value_map"), s->volume.value_scale, s->volume.value_offset);
    set1i(p, "u_nearest", sl_params_choice(params, "interpolation") == 1);
    glUniform2f(glGetUniformLocation(p, "u_tf_map"), (float)s->table->lo,
                (float)((SL_VOLUME_TF_TEXELS - 1) / (s->table->hi - s->table->lo)));
    set1i(p, "u_volume", 0);
    set1i(p, "u_tf", 1);
    set1i(p, "u_runs", 2);
    set1i(p, "u_minmax", 3);
    set1i(p, "u_gradient", 4);
    glBindTextureUnit(0, s->volume.tex);
    glBindTextureUnit(1, s->tf_tex);
    glBindTextureUnit(2, s->bricks.runs_tex);
    glBindTextureUnit(3, s->bricks.minmax_tex);
    glBindTextureUnit(4, gradient_tex ? s->gradient_tex : s->volume.tex);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, s->rows_buf);
    /* Every pixel the ray reaches writes its final colour and its depth
     * (0 = nothing): no blending, depth always written. */
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(s->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDepthFunc(GL_GREATER);
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
    stats->primitives = (double)view->width * view->height;
    stats->samples = taken;
    stats->samples_skipped = skipped;
    stats->culled = (double)(s->bricks.dims[0] * s->bricks.dims[1] * s->bricks.dims[2]) - (double)s->visible_bricks;
    return SL_OK;
}

static void volume_dvr_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const volume_dvr_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

static size_t volume_dvr_gpu_bytes(const void *opaque)
{
    const volume_dvr_state *s = opaque;
    return s ? s->gpu_bytes : 0;
}

const sl_technique sl_volume_dvr_technique = {
    .name = "volume_dvr",
    .description = "GPU ray-marched direct volume rendering: composite, MIP, shaded isosurface",
    .dataset_kinds = SL_DATASET_VOLUME | SL_DATASET_VECTORS,
    .params = volume_dvr_params,
    .param_count = (int)(sizeof volume_dvr_params / sizeof volume_dvr_params[0]),
    .prepare = volume_dvr_prepare,
    .render = volume_dvr_render,
    .release = volume_dvr_release,
    .gpu_bytes = volume_dvr_gpu_bytes,
    .prepare_stats = volume_dvr_prepare_stats,
};
