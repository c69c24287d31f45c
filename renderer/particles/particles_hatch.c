/* particles_hatch.c — the hatch cache and its drawing (particles_hatch.h).
 *
 * A set's strokes depend only on its particles and the key (mode,
 * direction, length, segments, cross on, cross angle, flat curvature, the
 * smoothing radius); tones, width, ink and visibility are per frame, so a
 * camera move only draws. The build is one compute dispatch over the alive
 * particles; the draw pulls 6 vertices per segment by gl_VertexID.
 * Render thread only.
 */
#include "particles_hatch.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

#include "../gpu/sl_gpu.h"
#include "particles_debug.h"
#include "particles_tf2d.h"

#define PT_HATCH_GROUP 64

static atomic_ulong hatch_builds;
static pt_debug_hatch_fn observer;
static void *observer_user;

void pt_debug_hatch_observe(pt_debug_hatch_fn fn, void *user)
{
    observer = fn;
    observer_user = user;
}

unsigned long pt_debug_hatch_builds(void)
{
    return atomic_load(&hatch_builds);
}

void pt_hatch_init(pt_hatch *h, const pt_field *field)
{
    memset(h, 0, sizeof *h);
    h->field = *field;
}

static sl_status ensure_programs(pt_hatch *h, sl_err *err)
{
    sl_status st = SL_OK;
    if (!h->build_program)
        st = sl_gl_program_create(&(sl_program_desc){.compute = "particles/particles_hatch.comp.glsl",
                                                     .label = "particles hatch strokes"},
                                  &h->build_program, err);
    if (st == SL_OK && !h->draw_program)
        st = sl_gl_program_create(&(sl_program_desc){.vertex = "particles/particles_stroke.vert.glsl",
                                                     .fragment = "particles/particles_stroke.frag.glsl",
                                                     .label = "particles hatches"},
                                  &h->draw_program, err);
    return st;
}

static void release_cache(pt_hatch_cache *c)
{
    if (c->strokes)
        glDeleteBuffers(1, &c->strokes);
    memset(c, 0, sizeof *c);
}

void pt_hatch_deinit(pt_hatch *h)
{
    for (int k = 0; k < PT_HATCH_SETS; k++)
        release_cache(&h->cache[k]);
    if (h->build_program)
        glDeleteProgram(h->build_program);
    if (h->draw_program)
        glDeleteProgram(h->draw_program);
    h->build_program = h->draw_program = 0;
}

static size_t stroke_bytes(const pt_hatch_cache *c)
{
    return (size_t)c->particles * (size_t)(1 + c->key.cross) * (size_t)(c->key.segments + 1) * 16;
}

size_t pt_hatch_bytes(const pt_hatch *h)
{
    size_t b = 0;
    for (int k = 0; k < PT_HATCH_SETS; k++)
        if (h->cache[k].strokes)
            b += stroke_bytes(&h->cache[k]);
    return b;
}

static pt_hatch_key make_key(const pt_hatch *h, const pt_set_view *sv, const sl_params *params)
{
    pt_hatch_key k;
    memset(&k, 0, sizeof k); /* padding too: keys are compared with memcmp */
    double min_spacing = h->field.min_spacing;
    k.mode = sl_params_choice(params, "hatch_mode");
    sl_params_vec3(params, "hatch_direction", k.direction);
    k.length = sl_params_float(params, "hatch_length") * sv->set->stats.mean_nn;
    k.segments = sl_params_int(params, "hatch_segments");
    k.cross = sl_params_int(params, "cross_hatching") >> sv->index & 1;
    k.cross_angle = sl_params_float(params, "cross_angle");
    k.eps = sl_params_float(params, "flat_curvature") / min_spacing;
    k.sigma = sl_params_float(params, "repulsion_radius") * sl_params_float(params, "spacing") * min_spacing;
    return k;
}

static void set_field_uniforms(GLuint p, const pt_field *f, double iso)
{
    glUniform1i(glGetUniformLocation(p, "u_volume"), 0);
    glUniform3i(glGetUniformLocation(p, "u_voxel_dims"), f->dims[0], f->dims[1], f->dims[2]);
    glUniform2f(glGetUniformLocation(p, "u_value_map"), f->value_scale, f->value_offset);
    glUniform3f(glGetUniformLocation(p, "u_spacing"), (float)f->spacing[0], (float)f->spacing[1],
                (float)f->spacing[2]);
    glUniform3f(glGetUniformLocation(p, "u_box_world"), (float)((f->dims[0] - 1) * f->spacing[0]),
                (float)((f->dims[1] - 1) * f->spacing[1]), (float)((f->dims[2] - 1) * f->spacing[2]));
    glUniform1f(glGetUniformLocation(p, "u_iso"), (float)iso);
    /* Gradients below this (per world unit) count as vanished, as in the system. */
    glUniform1f(glGetUniformLocation(p, "u_gmin"), (float)(1e-6 * (f->value_max - f->value_min) / f->min_spacing));
}

/* Builds the strokes of one set: one compute pass over its alive particles. */
static sl_status build(pt_hatch *h, pt_hatch_cache *c, const pt_set_view *sv, const pt_hatch_key *key, double iso,
                       sl_err *err)
{
    const pt_set *set = sv->set;
    release_cache(c);
    uint32_t n = set->stats.alive;
    GLsizeiptr bytes = (GLsizeiptr)n * (1 + key->cross) * (key->segments + 1) * 16;
    glCreateBuffers(1, &c->strokes);
    glNamedBufferStorage(c->strokes, bytes > 0 ? bytes : 16, NULL, 0);
    sl_status st = sl_gl_check_errors("particles: allocating the hatch strokes", err);
    if (st != SL_OK) {
        release_cache(c);
        return st;
    }
    c->particles = n;
    c->key = *key;
    GLuint p = h->build_program;
    glUseProgram(p);
    set_field_uniforms(p, &h->field, iso);
    glUniform1f(glGetUniformLocation(p, "u_bin_size"), (float)set->bin_size);
    glUniform3i(glGetUniformLocation(p, "u_bin_dims"), set->bin_dims[0], set->bin_dims[1], set->bin_dims[2]);
    glUniform3i(glGetUniformLocation(p, "u_bin_origin"), set->bin_origin[0], set->bin_origin[1], set->bin_origin[2]);
    glUniform1ui(glGetUniformLocation(p, "u_bins"), set->bins);
    glUniform1ui(glGetUniformLocation(p, "u_count"), n);
    glUniform1i(glGetUniformLocation(p, "u_mode"), key->mode);
    glUniform3fv(glGetUniformLocation(p, "u_direction"), 1, key->direction);
    glUniform1f(glGetUniformLocation(p, "u_step"), (float)(key->length / key->segments));
    glUniform1i(glGetUniformLocation(p, "u_segments"), key->segments);
    glUniform1i(glGetUniformLocation(p, "u_cross"), key->cross);
    glUniform1f(glGetUniformLocation(p, "u_cross_angle"), (float)(key->cross_angle * M_PI / 180.0));
    glUniform1f(glGetUniformLocation(p, "u_eps"), (float)key->eps);
    glUniform1f(glGetUniformLocation(p, "u_sigma"), (float)key->sigma);
    glBindTextureUnit(0, h->field.texture);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, set->table);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, c->strokes);
    if (n > 0)
        glDispatchCompute((n + PT_HATCH_GROUP - 1) / PT_HATCH_GROUP, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glBindTextureUnit(0, 0);
    atomic_fetch_add(&hatch_builds, 1);
    if ((st = sl_gl_check_errors("particles: building the hatch strokes", err)) != SL_OK) {
        release_cache(c);
        return st;
    }
    if (observer)
        observer(observer_user, &(pt_debug_hatch_build){.set = sv->index,
                                                        .particles = n,
                                                        .strokes_per_particle = 1 + key->cross,
                                                        .segments = key->segments,
                                                        .records = set->records,
                                                        .strokes = c->strokes});
    return SL_OK;
}

sl_status pt_hatch_draw(pt_hatch *h, const pt_frame *f, const pt_set_view *sv, double iso, const sl_params *params,
                        double *drawn, sl_err *err)
{
    if (sv->index < 0 || sv->index >= PT_HATCH_SETS)
        return SL_OK;
    sl_status st = ensure_programs(h, err);
    if (st != SL_OK)
        return st;
    pt_hatch_cache *c = &h->cache[sv->index];
    pt_hatch_key key = make_key(h, sv, params);
    if (!c->strokes || c->particles != sv->set->stats.alive || memcmp(&key, &c->key, sizeof key) != 0) {
        st = build(h, c, sv, &key, iso, err);
        if (st != SL_OK)
            return st;
    }
    int strokes = 1 + c->key.cross;
    GLsizei quads = (GLsizei)((size_t)c->particles * strokes * c->key.segments);
    if (quads == 0)
        return SL_OK;
    GLuint p = h->draw_program;
    glUseProgram(p);
    pt_frame_uniforms(p, f);
    glUniform1i(glGetUniformLocation(p, "u_ids"), 0);
    glBindTextureUnit(0, sv->hsr ? sv->id_tex : 0);
    glUniform1i(glGetUniformLocation(p, "u_hsr"), sv->hsr);
    glUniform3fv(glGetUniformLocation(p, "u_light_world"), 1, f->light_world);
    glUniform1i(glGetUniformLocation(p, "u_ink_dark"), sv->ink_dark);
    glUniform3fv(glGetUniformLocation(p, "u_ink"), 1, sv->ink);
    pt_tf2d_uniforms(p, &sv->curvature, 1);
    glUniform1i(glGetUniformLocation(p, "u_segments"), c->key.segments);
    glUniform1i(glGetUniformLocation(p, "u_strokes"), strokes);
    glUniform1f(glGetUniformLocation(p, "u_half_width"), (float)(0.5 * sl_params_float(params, "hatch_width")));
    glUniform1f(glGetUniformLocation(p, "u_hatch_threshold"), (float)sl_params_float(params, "hatch_threshold"));
    glUniform1f(glGetUniformLocation(p, "u_cross_threshold"), (float)sl_params_float(params, "cross_threshold"));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, c->strokes);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glDrawArrays(GL_TRIANGLES, 0, quads * 6);
    glDisable(GL_BLEND);
    glBindTextureUnit(1, 0);
    *drawn += quads;
    return SL_OK;
}
