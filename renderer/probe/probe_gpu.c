/* probe_gpu.c — the shader path of sightline-probe (sl_probe_gpu.h): per
 * dataset kind the GPU form the renderer samples (LR Bézier blocks and
 * look-up, the volume texture, flow's field texture), one compute program,
 * point and result buffers grown to the largest batch; eval packs the
 * points the CPU rule puts inside, dispatches once and unpacks. Render
 * thread only.
 */
#include "sl_probe_gpu.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../flow/flow_gpu.h"
#include "../gpu/sl_gpu.h"
#include "../lrspline/sl_lr_bezier.h"
#include "../volume/sl_volume.h"
#include "sl_probe.h"

enum { IN_BINDING = 1, OUT_BINDING = 2, LR_STRIDE = 20, REGULAR_STRIDE = 4, GROUP = 64 };

struct sl_probe_gpu {
    const sl_dataset *ds;          /* borrowed */
    int components, stride;        /* result floats per point */
    GLuint program, in_buf, out_buf;
    size_t capacity;               /* points the buffers hold */
    float lo[3], hi[3];            /* the float box points are clamped into (voxel coordinates for volumes) */
    int has_lr;
    sl_lr_bezier bz;               /* LR */
    sl_lr_bezier_gpu blocks;
    sl_volume_texture volume;      /* scalar volume */
    sl_flow_field field;           /* vector field */
    GLuint field_tex;
};

/* The smallest float >= v and the largest float <= v. */
static float float_up(double v)
{
    float f = (float)v;
    return (double)f < v ? nextafterf(f, INFINITY) : f;
}

static float float_down(double v)
{
    float f = (float)v;
    return (double)f > v ? nextafterf(f, -INFINITY) : f;
}

void sl_probe_gpu_destroy(sl_probe_gpu *g)
{
    if (!g)
        return;
    if (g->program)
        glDeleteProgram(g->program);
    if (g->in_buf)
        glDeleteBuffers(1, &g->in_buf);
    if (g->out_buf)
        glDeleteBuffers(1, &g->out_buf);
    if (g->has_lr) {
        sl_lr_bezier_release(&g->blocks);
        sl_lr_bezier_free(&g->bz);
    }
    sl_volume_texture_destroy(&g->volume);
    if (g->field_tex)
        glDeleteTextures(1, &g->field_tex);
    free(g);
}

static sl_status create_lr(sl_probe_gpu *g, sl_err *err)
{
    g->has_lr = 1;
    sl_status st = sl_lr_bezier_build(g->ds->lr, SL_LR_LOOKUP_AUTO, 0, &g->bz, err);
    if (st != SL_OK) {
        g->has_lr = 0;
        return st;
    }
    if ((st = sl_lr_bezier_upload(&g->bz, 0, &g->blocks, err)) != SL_OK)
        return st;
    for (int d = 0; d < 3; d++) {
        g->lo[d] = g->blocks.lookup.lo[d];
        g->hi[d] = g->blocks.lookup.hi[d];
    }
    g->stride = LR_STRIDE;
    char defines[256];
    sl_lr_bezier_defines(&g->bz, 0, defines, sizeof defines);
    return sl_gl_program_create(&(sl_program_desc){.compute = "lrspline/lr_probe.comp.glsl", .defines = defines,
                                                   .label = "probe (LR)"}, &g->program, err);
}

static sl_status create_volume(sl_probe_gpu *g, sl_err *err)
{
    sl_status st = sl_volume_texture_create(&g->ds->volume, &g->volume, err);
    if (st != SL_OK)
        return st;
    sl_volume_texture_set_filter(&g->volume, 1);
    sl_volume_geometry geo;
    sl_volume_geometry_init(g->ds, &geo);
    for (int d = 0; d < 3; d++) {
        g->lo[d] = float_up(geo.box_lo[d]);
        g->hi[d] = float_down(geo.box_hi[d]);
    }
    g->stride = REGULAR_STRIDE;
    return sl_gl_program_create(&(sl_program_desc){.compute = "probe/probe_volume.comp.glsl",
                                                   .label = "probe (volume)"}, &g->program, err);
}

static sl_status create_vectors(sl_probe_gpu *g, sl_err *err)
{
    sl_status st = sl_flow_field_from_dataset(&g->field, g->ds, err);
    if (st == SL_OK)
        st = sl_flow_field_texture_create(&g->field, &g->field_tex, err);
    if (st != SL_OK)
        return st;
    for (int d = 0; d < 3; d++) {
        g->lo[d] = float_up(g->field.lo[d]);
        g->hi[d] = float_down(g->field.hi[d]);
    }
    g->stride = REGULAR_STRIDE;
    return sl_gl_program_create(&(sl_program_desc){.compute = "probe/probe_vectors.comp.glsl",
                                                   .label = "probe (vectors)"}, &g->program, err);
}

sl_status sl_probe_gpu_create(const sl_dataset *ds, int gradient, sl_probe_gpu **out, sl_err *err)
{
    *out = NULL;
    int nc = sl_probe_components(ds);
    if (nc == 0)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "dataset \"%s\" is a %s dataset: it has no field to probe",
                          ds->name, sl_dataset_kind_name(ds->kind));
    if (gradient && ds->kind != SL_DATASET_LR)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "the GPU path has no gradient of a regular volume's trilinear "
                          "interpolant (volume_dvr shades with central differences, streamlines need none): probe "
                          "gradients of \"%s\" on the CPU (without --gpu)", ds->name);
    sl_probe_gpu *g = calloc(1, sizeof *g);
    if (!g)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the GPU probe");
    g->ds = ds;
    g->components = nc;
    sl_err stale = {0};
    sl_gl_check_errors("before the GPU probe", &stale); /* clears errors not ours */
    sl_status st = ds->kind == SL_DATASET_LR ? create_lr(g, err)
                   : ds->kind == SL_DATASET_VOLUME ? create_volume(g, err) : create_vectors(g, err);
    if (st != SL_OK) {
        sl_err_prefix(err, "GPU probe");
        sl_probe_gpu_destroy(g);
        return st;
    }
    *out = g;
    return SL_OK;
}

/* Grows the point and result buffers to n points. */
static sl_status reserve(sl_probe_gpu *g, size_t n, sl_err *err)
{
    if (n <= g->capacity)
        return SL_OK;
    size_t cap = g->capacity ? g->capacity : 1024;
    while (cap < n)
        cap *= 2;
    GLuint b[2] = {g->in_buf, g->out_buf};
    if (b[0])
        glDeleteBuffers(2, b);
    glCreateBuffers(1, &g->in_buf);
    glNamedBufferStorage(g->in_buf, (GLsizeiptr)(cap * 4 * sizeof(float)), NULL, GL_DYNAMIC_STORAGE_BIT);
    glCreateBuffers(1, &g->out_buf);
    glNamedBufferStorage(g->out_buf, (GLsizeiptr)(cap * (size_t)g->stride * sizeof(float)), NULL,
                         GL_DYNAMIC_STORAGE_BIT);
    g->capacity = cap;
    return sl_gl_check_errors("GPU probe buffers", err);
}

/* The shader's input for a point inside: LR and vectors the world point,
 * volumes the voxel coordinate (in double, as volume_dvr's eye), rounded to
 * float and clamped into the float box. */
static void shader_point(const sl_probe_gpu *g, const double p[3], float *q)
{
    const sl_dataset *ds = g->ds;
    const double origin[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    for (int d = 0; d < 3; d++) {
        double v = ds->kind == SL_DATASET_VOLUME ? (p[d] - origin[d]) / ds->volume.spacing[d] : p[d];
        float f = (float)v;
        q[d] = f < g->lo[d] ? g->lo[d] : f > g->hi[d] ? g->hi[d] : f;
    }
    q[3] = 0.0f;
}

sl_status sl_probe_gpu_eval(sl_probe_gpu *g, size_t n, const double *points, double *values, double *gradients,
                            unsigned char *inside, sl_err *err)
{
    size_t *which = malloc((n ? n : 1) * sizeof *which);
    float *pts = malloc((n ? n : 1) * 4 * sizeof *pts);
    float *res = malloc((n ? n : 1) * (size_t)g->stride * sizeof *res);
    sl_status st = which && pts && res ? SL_OK : sl_err_set(err, SL_ERR_NOMEM, "out of memory probing %zu points", n);
    size_t m = 0;
    for (size_t i = 0; st == SL_OK && i < n; i++) {
        inside[i] = (unsigned char)sl_probe_inside(g->ds, points + 3 * i);
        if (inside[i]) {
            shader_point(g, points + 3 * i, pts + 4 * m);
            which[m++] = i;
        }
    }
    if (st == SL_OK && m > 0)
        st = reserve(g, m, err);
    if (st == SL_OK && m > 0) {
        glNamedBufferSubData(g->in_buf, 0, (GLsizeiptr)(m * 4 * sizeof(float)), pts);
        glUseProgram(g->program);
        if (g->has_lr) {
            sl_lr_bezier_set_uniforms(g->program, &g->bz);
            sl_lr_bezier_bind(&g->blocks, g->program);
        } else if (g->ds->kind == SL_DATASET_VOLUME) {
            const sl_volume *v = &g->ds->volume;
            glBindTextureUnit(0, g->volume.tex);
            glUniform1i(glGetUniformLocation(g->program, "u_volume"), 0);
            glUniform3f(glGetUniformLocation(g->program, "u_dims"), (float)v->dims[0], (float)v->dims[1],
                        (float)v->dims[2]);
            glUniform2f(glGetUniformLocation(g->program, "u_value_map"), g->volume.value_scale,
                        g->volume.value_offset);
            glUniform1i(glGetUniformLocation(g->program, "u_nearest"), 0);
        } else {
            sl_flow_field_texture_bind(g->program, &g->field, g->field_tex, 0);
        }
        glUniform1i(glGetUniformLocation(g->program, "u_count"), (GLint)m);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, IN_BINDING, g->in_buf);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, OUT_BINDING, g->out_buf);
        glDispatchCompute((GLuint)((m + GROUP - 1) / GROUP), 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(g->out_buf, 0, (GLsizeiptr)(m * (size_t)g->stride * sizeof(float)), res);
        glUseProgram(0);
        st = sl_gl_check_errors("GPU probe dispatch", err);
    }
    const int nc = g->components;
    for (size_t k = 0; st == SL_OK && k < m; k++) {
        const float *r = res + k * (size_t)g->stride;
        double *v = values + which[k] * (size_t)nc;
        double *gr = gradients ? gradients + which[k] * 3 * (size_t)nc : NULL;
        if (!g->has_lr) {
            for (int c = 0; c < nc; c++)
                v[c] = r[c];
            continue;
        }
        if (r[0] < 0.0f) {
            st = sl_err_set(err, SL_ERR_GPU, "GPU probe: the element look-up found no element for point %zu "
                            "(%.17g, %.17g, %.17g), which lies inside the domain", which[k],
                            points[3 * which[k]], points[3 * which[k] + 1], points[3 * which[k] + 2]);
            break;
        }
        /* lr_probe.comp.glsl: [1] value, [2..4] gradient; [5..7] vector, [8 + 3j + c] d f_c / d x_j. */
        for (int c = 0; c < nc; c++) {
            v[c] = nc == 1 ? r[1] : r[5 + c];
            for (int j = 0; gr && j < 3; j++)
                gr[c * 3 + j] = nc == 1 ? r[2 + j] : r[8 + 3 * j + c];
        }
    }
    free(which);
    free(pts);
    free(res);
    return st;
}
