/* volume_march.c — the shared ray marcher: descriptor → uniforms → one full-screen pass.
 *
 * What volume_dvr and particles both draw (sl_volume.h: the contract; the
 * model in volume_dvr/README.md). The marcher keeps what a frame would
 * otherwise redo: programs per variant (compiled on first use, about
 * 0.1-0.3 s each on llvmpipe), the TF texture re-baked only when the
 * transfer function differs from the one loaded, and the brick mask rebuilt
 * only when its rule, the TF or the isovalue changed (counted in
 * sl_volume_counters). A camera move uploads nothing but the camera block.
 * Not here: the volume texture, bricks and gradient texture (the caller's,
 * built once), parameters of a technique, blending with marks drawn later.
 * Render thread only.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../gpu/sl_gpu.h"
#include "sl_volume.h"

/* Texture units and the counters' SSBO binding (volume_march*.glsl). */
enum { UNIT_VOLUME, UNIT_TF, UNIT_RUNS, UNIT_MINMAX, UNIT_GRADIENT, ROWS_BINDING, UNIT_OPAQUE_DEPTH };

/* mip never shades; the 12 plain variants come first (volume_dvr's). */
static int variant_of(sl_volume_march_mode mode, int shading, int gradient_tex, int focus)
{
    return (int)mode + 3 * (shading != 0) + 6 * (shading && gradient_tex) + 12 * (focus != 0);
}

static sl_status program_for(sl_volume_marcher *m, int variant, GLuint *out, sl_err *err)
{
    if (!m->programs[variant]) {
        int mode = variant % 3, shading = variant % 12 >= 3, gradient_tex = variant % 12 >= 6, focus = variant >= 12;
        char defines[160], label[48];
        snprintf(defines, sizeof defines,
                 "#define SL_MODE %d\n#define SL_SHADING %d\n#define SL_GRADIENT_TEX %d\n#define SL_FOCUS %d\n", mode,
                 shading, gradient_tex, focus);
        snprintf(label, sizeof label, "volume_march (variant %d)", variant);
        sl_status st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                               .fragment = "volume/volume_march.frag.glsl",
                                                               .defines = defines, .label = label},
                                            &m->programs[variant], err);
        if (st != SL_OK)
            return st;
    }
    *out = m->programs[variant];
    return SL_OK;
}

void sl_volume_marcher_deinit(sl_volume_marcher *m)
{
    if (!m)
        return;
    for (int i = 0; i < SL_VOLUME_MARCH_VARIANTS; i++)
        if (m->programs[i])
            glDeleteProgram(m->programs[i]);
    if (m->vao) glDeleteVertexArrays(1, &m->vao);
    if (m->camera_ubo) glDeleteBuffers(1, &m->camera_ubo);
    if (m->tf_tex) glDeleteTextures(1, &m->tf_tex);
    if (m->rows_buf) glDeleteBuffers(1, &m->rows_buf);
    free(m->table);
    memset(m, 0, sizeof *m);
    m->mask_rule = -1;
}

sl_status sl_volume_marcher_init(sl_volume_marcher *m, const sl_volume *data, sl_err *err)
{
    memset(m, 0, sizeof *m);
    m->mask_rule = -1;
    m->data = data;
    if (!(m->table = malloc(sizeof *m->table)))
        return sl_err_set(err, SL_ERR_NOMEM, "volume marcher: out of memory");
    GLuint program = 0;
    sl_status st = program_for(m, variant_of(SL_VOLUME_MARCH_COMPOSITE, 0, 0, 0), &program, err);
    if (st == SL_OK)
        st = sl_volume_tf_texture_create(&m->tf_tex, err);
    if (st != SL_OK) {
        sl_volume_marcher_deinit(m);
        return st;
    }
    glCreateVertexArrays(1, &m->vao);
    m->bytes = SL_VOLUME_TF_TEXELS * 16;
    return SL_OK;
}

/* Re-bakes the TF when it changed and rebuilds the brick mask when its
 * rule (mode), the TF (composite) or the isovalue (iso) changed. */
static void update_tf_and_mask(sl_volume_marcher *m, sl_volume_bricks *b, const sl_volume_march_desc *d)
{
    int emission_absorption = d->mode == SL_VOLUME_MARCH_COMPOSITE; /* the automatic ramp differs */
    int tf_changed = !m->tf_valid || !sl_transfer_function_equal(d->tf, &m->tf_loaded) ||
                     (d->tf->auto_opacity && emission_absorption != m->tf_emission_absorption);
    if (tf_changed) {
        sl_volume_tf_points pts;
        sl_volume_tf_resolve(d->tf, m->data, emission_absorption, &pts);
        m->tf_emission_absorption = emission_absorption;
        sl_volume_tf_bake(&pts, m->table);
        sl_volume_tf_texture_upload(m->tf_tex, m->table);
        m->tf_loaded = *d->tf;
        m->tf_valid = 1;
    }
    int rule = d->mode == SL_VOLUME_MARCH_COMPOSITE ? SL_VOLUME_MASK_TF
               : d->mode == SL_VOLUME_MARCH_ISO     ? SL_VOLUME_MASK_ISO
                                                    : SL_VOLUME_MASK_FINITE;
    if (rule != m->mask_rule || (rule == SL_VOLUME_MASK_TF && tf_changed) ||
        (rule == SL_VOLUME_MASK_ISO && d->iso != m->mask_iso)) {
        m->visible_bricks = sl_volume_bricks_update_mask(b, (sl_volume_mask_rule)rule, m->table, d->iso);
        m->mask_rule = rule;
        m->mask_iso = d->iso;
    }
}

/* The per-row counters (taken, skipped), zeroed for this frame. */
static void prepare_rows(sl_volume_marcher *m, int height)
{
    if (height > m->rows_capacity) {
        if (m->rows_buf)
            glDeleteBuffers(1, &m->rows_buf);
        glCreateBuffers(1, &m->rows_buf);
        glNamedBufferStorage(m->rows_buf, (GLsizeiptr)height * 2 * sizeof(GLuint), NULL,
                             GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
        m->rows_capacity = height;
    }
    glClearNamedBufferData(m->rows_buf, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
}

static void read_rows(const sl_volume_marcher *m, int height, double *taken, double *skipped)
{
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    GLuint *rows = malloc((size_t)height * 2 * sizeof *rows);
    *taken = *skipped = 0.0;
    if (!rows)
        return;
    glGetNamedBufferSubData(m->rows_buf, 0, (GLsizeiptr)height * 2 * sizeof *rows, rows);
    for (int y = 0; y < height; y++) {
        *taken += rows[2 * y];
        *skipped += rows[2 * y + 1];
    }
    free(rows);
}

static void set1i(GLuint p, const char *name, int v) { glUniform1i(glGetUniformLocation(p, name), v); }
static void set1f(GLuint p, const char *name, double v) { glUniform1f(glGetUniformLocation(p, name), (float)v); }
static void set3f(GLuint p, const char *name, const double v[3])
{
    glUniform3f(glGetUniformLocation(p, name), (float)v[0], (float)v[1], (float)v[2]);
}

/* The light: eye space (x right, y up, z towards the viewer) to world, unit. */
static void light_to_world(const sl_view *view, const double dir[3], double out[3])
{
    double ll = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double le[3] = {0.0, 0.0, 1.0};
    if (ll > 0.0)
        for (int c = 0; c < 3; c++)
            le[c] = dir[c] / ll;
    sl_vec3 lw = sl_v3_add(sl_v3_add(sl_v3_scale(view->right, le[0]), sl_v3_scale(view->upv, le[1])),
                           sl_v3_scale(view->forward, -le[2]));
    out[0] = lw.x;
    out[1] = lw.y;
    out[2] = lw.z;
}

sl_status sl_volume_marcher_draw(sl_volume_marcher *m, const sl_volume_texture *vol, sl_volume_bricks *b,
                                 const sl_volume_geometry *g, const sl_view *view, const sl_volume_march_desc *d,
                                 sl_render_stats *stats, sl_err *err)
{
    if ((unsigned)d->mode > SL_VOLUME_MARCH_ISO || !d->tf || !(d->step >= 0.0) || !(d->focus.radius >= 0.0))
        return sl_err_set(err, SL_ERR_INVALID,
                          "volume marcher: bad descriptor (mode %d, tf %s, step %g, focus radius %g)", (int)d->mode,
                          d->tf ? "set" : "missing", d->step, d->focus.radius);
    update_tf_and_mask(m, b, d);
    int iso = d->mode == SL_VOLUME_MARCH_ISO;
    int shading = (d->shading && d->mode == SL_VOLUME_MARCH_COMPOSITE) || iso;
    int gradient_tex = shading && d->gradient_tex != 0;
    int focus = d->focus.radius > 0.0;
    GLuint p = 0;
    sl_status st = program_for(m, variant_of(d->mode, shading, gradient_tex, focus), &p, err);
    if (st != SL_OK)
        return st;
    sl_volume_texture_set_filter(vol, !d->nearest);
    prepare_rows(m, view->height);

    /* Voxel coordinates: (world - volume origin) / spacing. */
    double eye_v[3], inv_spacing[3], lo[3], hi[3];
    const double eye[3] = {view->camera.eye.x, view->camera.eye.y, view->camera.eye.z};
    const double org[3] = {g->origin.x, g->origin.y, g->origin.z};
    for (int a = 0; a < 3; a++) {
        eye_v[a] = (eye[a] - org[a]) / g->spacing[a];
        inv_spacing[a] = 1.0 / g->spacing[a];
        double span = g->box_hi[a] - g->box_lo[a];
        lo[a] = d->clip ? g->box_lo[a] + d->clip_min[a] * span : g->box_lo[a];
        hi[a] = d->clip ? g->box_lo[a] + d->clip_max[a] * span : g->box_hi[a];
    }
    /* Interactive frames (a camera drag) sample half as densely; the
     * opacity correction keeps their look, only finer detail is lost. */
    double step = d->step > 0.0 ? d->step : 0.5;
    if (view->quality == SL_QUALITY_INTERACTIVE)
        step = fmin(2.0 * step, 16.0);
    const double bg[3] = {view->background[0], view->background[1], view->background[2]};
    double light[3];
    light_to_world(view, d->light_dir, light);
    static const double default_material[4] = {0.25, 0.75, 0.3, 32.0};
    const double *mat = d->material;
    if (mat[0] == 0.0 && mat[1] == 0.0 && mat[2] == 0.0 && mat[3] == 0.0)
        mat = default_material;

    sl_camera_ubo_update(&m->camera_ubo, view);
    glUseProgram(p);
    set3f(p, "u_eye_v", eye_v);
    set3f(p, "u_inv_spacing", inv_spacing);
    set3f(p, "u_box_lo", lo);
    set3f(p, "u_box_hi", hi);
    set1f(p, "u_dt", step * g->min_spacing);
    set1f(p, "u_step", step);
    set1f(p, "u_min_spacing", g->min_spacing);
    set1f(p, "u_iso", d->iso);
    set1f(p, "u_alpha_stop", d->alpha_stop > 0.0 ? d->alpha_stop : 0.99);
    set1i(p, "u_jitter", d->jitter != 0);
    set1i(p, "u_skipping", !d->no_skipping);
    glUniform3i(glGetUniformLocation(p, "u_brick_dims"), b->dims[0], b->dims[1], b->dims[2]);
    set3f(p, "u_background", bg);
    set3f(p, "u_light_world", light);
    glUniform4f(glGetUniformLocation(p, "u_material"), (float)mat[0], (float)mat[1], (float)mat[2], (float)mat[3]);
    glUniform3f(glGetUniformLocation(p, "u_dims"), (float)g->dims[0], (float)g->dims[1], (float)g->dims[2]);
    glUniform2f(glGetUniformLocation(p, "u_value_map"), vol->value_scale, vol->value_offset);
    set1i(p, "u_nearest", d->nearest != 0);
    glUniform2f(glGetUniformLocation(p, "u_tf_map"), (float)m->table->lo,
                (float)((SL_VOLUME_TF_TEXELS - 1) / (m->table->hi - m->table->lo)));
    set1i(p, "u_volume", UNIT_VOLUME);
    set1i(p, "u_tf", UNIT_TF);
    set1i(p, "u_runs", UNIT_RUNS);
    set1i(p, "u_minmax", UNIT_MINMAX);
    set1i(p, "u_gradient", UNIT_GRADIENT);
    glBindTextureUnit(UNIT_VOLUME, vol->tex);
    glBindTextureUnit(UNIT_TF, m->tf_tex);
    glBindTextureUnit(UNIT_RUNS, b->runs_tex);
    glBindTextureUnit(UNIT_MINMAX, b->minmax_tex);
    glBindTextureUnit(UNIT_GRADIENT, gradient_tex ? d->gradient_tex : vol->tex);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ROWS_BINDING, m->rows_buf);
    if (focus) {
        /* The sphere as eye - centre in world units (double here, so a far
         * origin costs no precision): t is the world distance along the
         * unit ray in voxel and world space alike (rd = d / spacing). */
        glUniform4f(glGetUniformLocation(p, "u_focus"), (float)(eye[0] - d->focus.centre[0]),
                    (float)(eye[1] - d->focus.centre[1]), (float)(eye[2] - d->focus.centre[2]),
                    (float)d->focus.radius);
        set1i(p, "u_opaque_depth", UNIT_OPAQUE_DEPTH);
        /* Name 0: an unbound unit reads 0 = no mark anywhere. */
        glBindTextureUnit(UNIT_OPAQUE_DEPTH, d->focus.opaque_depth_tex);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    } else {
        glDisable(GL_BLEND);
    }
    /* Every pixel the ray reaches writes its colour and its depth
     * (plain: final colour, depth 0 = nothing; focus: premultiplied over
     * the target, depth the nearer of mark and marcher). */
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(m->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDepthFunc(GL_GREATER);
    glDisable(GL_BLEND);
    double taken = 0.0, skipped = 0.0;
    read_rows(m, view->height, &taken, &skipped);
    stats->primitives = (double)view->width * view->height;
    stats->samples = taken;
    stats->samples_skipped = skipped;
    stats->culled = (double)(b->dims[0] * b->dims[1] * b->dims[2]) - (double)m->visible_bricks;
    return SL_OK;
}
