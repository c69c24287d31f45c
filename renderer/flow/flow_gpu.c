/* flow_gpu.c — the compute-shader streamline driver (flow_gpu.h): field
 * texture (regular, flow_field_gpu.c) or Bézier blocks and element look-up
 * (LR: built and uploaded once in create, or borrowed from a renderer that
 * has them; bound per trace), one program per precision, the tableau of
 * sl_flow_methods as uniforms (doubles for mixed / double, so both paths run
 * the same coefficients; b - e subtracted here), seed / sample / info
 * buffers, dispatch, read-back. Render thread only.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../gpu/sl_gpu.h"
#include "../lrspline/sl_lr_bezier.h"
#include "flow_gpu.h"

#define VARIANTS 3                 /* one program per precision */

struct sl_flow_gpu {
    sl_flow_field field;          /* copy; volume pointer not used after create */
    GLuint texture;
    GLuint programs[VARIANTS];
    int has_double;
    /* LR: the blocks and look-up (bz) and their GPU buffers (blocks), either
     * borrowed (sl_flow_gpu_create_lr) or own_bz / own_blocks (owns_blocks) */
    int has_lr, owns_blocks;
    const sl_lr_bezier *bz;
    const sl_lr_bezier_gpu *blocks;
    sl_lr_bezier own_bz;
    sl_lr_bezier_gpu own_blocks;
};

const char *const sl_flow_precision_names[4] = {"single", "mixed", "double", NULL};

int sl_flow_precision_find(const char *name)
{
    for (int i = 0; name && i < 3; i++)
        if (strcmp(name, sl_flow_precision_names[i]) == 0)
            return i;
    return -1;
}

const char *sl_flow_precision_name(sl_flow_precision p)
{
    return p >= SL_FLOW_SINGLE && p <= SL_FLOW_DOUBLE ? sl_flow_precision_names[p] : "?";
}

static int has_doubles(void)
{
    return epoxy_gl_version() >= 40 || epoxy_has_gl_extension("GL_ARB_gpu_shader_fp64");
}

/* The state of an LR field of dim 3 without its blocks yet. */
static sl_status lr_state(const sl_flow_field *f, sl_flow_gpu **out, sl_err *err)
{
    *out = NULL;
    if (f->kind != SL_FLOW_FIELD_LR || !f->lr || f->lr->dim != 3)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "GPU streamlines need an LR-spline volume of dim 3 (got dim %d)",
                          f->lr ? f->lr->dim : 0);
    sl_flow_gpu *g = calloc(1, sizeof *g);
    if (!g)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the GPU streamline state");
    g->field = *f;
    g->field.lr = NULL; /* borrowed only during create */
    g->has_double = has_doubles();
    g->has_lr = 1;
    *out = g;
    return SL_OK;
}

/* LR: the Bézier blocks with the look-up (auto kind), uploaded with the
 * double copies when GL has doubles (mixed needs the double boxes too). */
static sl_status create_lr(const sl_flow_field *f, sl_flow_gpu **out, sl_err *err)
{
    sl_flow_gpu *g;
    sl_status st = lr_state(f, &g, err);
    if (st != SL_OK)
        return st;
    g->owns_blocks = 1;
    g->bz = &g->own_bz;
    g->blocks = &g->own_blocks;
    st = sl_lr_bezier_build(f->lr, SL_LR_LOOKUP_AUTO, 0, &g->own_bz, err);
    sl_err stale = {0};
    sl_gl_check_errors("before the LR field upload", &stale); /* clears errors not ours */
    if (st == SL_OK)
        st = sl_lr_bezier_upload(&g->own_bz, g->has_double, &g->own_blocks, err);
    if (st != SL_OK) {
        sl_flow_gpu_destroy(g);
        return st;
    }
    *out = g;
    return SL_OK;
}

sl_status sl_flow_gpu_create_lr(const sl_flow_field *f, const sl_lr_bezier *bz, const sl_lr_bezier_gpu *blocks,
                                sl_flow_gpu **out, sl_err *err)
{
    *out = NULL;
    if (f->kind == SL_FLOW_FIELD_LR && f->lr &&
        (bz->dim != f->lr->dim || bz->element_count != f->lr->element_count ||
         blocks->element_count != bz->element_count))
        return sl_err_set(err, SL_ERR_INVALID,
                          "the Bézier blocks (%zu elements, dim %d) are not those of this LR field (%zu, dim %d)",
                          bz->element_count, bz->dim, f->lr->element_count, f->lr->dim);
    sl_flow_gpu *g;
    sl_status st = lr_state(f, &g, err);
    if (st != SL_OK)
        return st;
    g->bz = bz;
    g->blocks = blocks;
    *out = g;
    return SL_OK;
}

sl_status sl_flow_gpu_create(const sl_flow_field *f, sl_flow_gpu **out, sl_err *err)
{
    *out = NULL;
    if (f->kind == SL_FLOW_FIELD_LR)
        return create_lr(f, out, err);
    if (f->kind != SL_FLOW_FIELD_REGULAR)
        return sl_err_set(err, SL_ERR_UNSUPPORTED,
                          "GPU streamlines need a regular vector field or an LR-spline volume of dim 3");
    sl_flow_gpu *g = calloc(1, sizeof *g);
    if (!g)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the GPU streamline state");
    g->field = *f;
    g->has_double = has_doubles();
    sl_status st = sl_flow_field_texture_create(f, &g->texture, err);
    if (st != SL_OK) {
        sl_flow_gpu_destroy(g);
        return st;
    }
    *out = g;
    return SL_OK;
}

void sl_flow_gpu_destroy(sl_flow_gpu *g)
{
    if (!g)
        return;
    for (int i = 0; i < VARIANTS; i++)
        if (g->programs[i])
            glDeleteProgram(g->programs[i]);
    if (g->texture)
        glDeleteTextures(1, &g->texture);
    if (g->owns_blocks) {
        sl_lr_bezier_release(&g->own_blocks);
        sl_lr_bezier_free(&g->own_bz);
    }
    free(g);
}

static sl_status program_for(sl_flow_gpu *g, sl_flow_precision p, GLuint *program, sl_err *err)
{
    if (g->programs[p]) {
        *program = g->programs[p];
        return SL_OK;
    }
    char defines[512];
    int used = snprintf(defines, sizeof defines, "#define SL_PREC %d\n", (int)p);
    if (g->has_lr)
        sl_lr_bezier_defines(g->bz, p != SL_FLOW_SINGLE, defines + used, sizeof defines - (size_t)used);
    sl_program_desc d = {.compute = g->has_lr ? "flow/flow_trace_lr.comp.glsl" : "flow/flow_trace_regular.comp.glsl",
                         .defines = defines, .label = g->has_lr ? "flow_trace_lr" : "flow_trace"};
    sl_status st = sl_gl_program_create(&d, &g->programs[p], err);
    if (st != SL_OK)
        return st;
    *program = g->programs[p];
    return SL_OK;
}

/* The tableau as uniforms, zero-padded to 6 x 6; d = b - e in double here. */
static void set_tableau(GLuint prog, const sl_flow_method *m, int dbl)
{
    double a[SL_FLOW_MAX_STAGES * SL_FLOW_MAX_STAGES] = {0}, b[SL_FLOW_MAX_STAGES] = {0},
           d[SL_FLOW_MAX_STAGES] = {0};
    for (int i = 0; i < m->stages; i++) {
        for (int j = 0; j < m->stages; j++)
            a[i * SL_FLOW_MAX_STAGES + j] = m->a[i][j];
        b[i] = m->b[i];
        d[i] = m->b[i] - m->e[i];
    }
    GLint la = glGetUniformLocation(prog, "u_a"), lb = glGetUniformLocation(prog, "u_b"),
          ld = glGetUniformLocation(prog, "u_d");
    if (dbl) {
        glUniform1dv(la, SL_FLOW_MAX_STAGES * SL_FLOW_MAX_STAGES, a);
        glUniform1dv(lb, SL_FLOW_MAX_STAGES, b);
        glUniform1dv(ld, SL_FLOW_MAX_STAGES, d);
    } else {
        float fa[SL_FLOW_MAX_STAGES * SL_FLOW_MAX_STAGES], fb[SL_FLOW_MAX_STAGES], fd[SL_FLOW_MAX_STAGES];
        for (int i = 0; i < SL_FLOW_MAX_STAGES * SL_FLOW_MAX_STAGES; i++)
            fa[i] = (float)a[i];
        for (int i = 0; i < SL_FLOW_MAX_STAGES; i++) {
            fb[i] = (float)b[i];
            fd[i] = (float)d[i];
        }
        glUniform1fv(la, SL_FLOW_MAX_STAGES * SL_FLOW_MAX_STAGES, fa);
        glUniform1fv(lb, SL_FLOW_MAX_STAGES, fb);
        glUniform1fv(ld, SL_FLOW_MAX_STAGES, fd);
    }
    glUniform1i(glGetUniformLocation(prog, "u_stages"), m->stages);
    glUniform1i(glGetUniformLocation(prog, "u_embedded"), m->embedded_order);
}

static void uniform_real(GLuint prog, const char *name, double v, int dbl)
{
    GLint loc = glGetUniformLocation(prog, name);
    if (dbl)
        glUniform1d(loc, v);
    else
        glUniform1f(loc, (float)v);
}

static void uniform_vec3(GLuint prog, const char *name, const double v[3], int dbl)
{
    GLint loc = glGetUniformLocation(prog, name);
    if (dbl)
        glUniform3d(loc, v[0], v[1], v[2]);
    else
        glUniform3f(loc, (float)v[0], (float)v[1], (float)v[2]);
}

sl_status sl_flow_gpu_trace(sl_flow_gpu *g, const double *seeds, size_t seed_count,
                            const sl_flow_options *o, sl_flow_precision precision,
                            sl_flow_result *out, double *compute_ms, sl_err *err)
{
    memset(out, 0, sizeof *out);
    sl_status st = sl_flow_options_check(o, err);
    if (st != SL_OK)
        return st;
    if ((int)precision < 0 || precision > SL_FLOW_DOUBLE)
        return sl_err_set(err, SL_ERR_INVALID, "unknown precision %d", (int)precision);
    if (precision != SL_FLOW_SINGLE && !g->has_double)
        return sl_err_set(err, SL_ERR_UNSUPPORTED,
                          "%s precision needs GL doubles (GL_ARB_gpu_shader_fp64), which this GPU lacks",
                          sl_flow_precision_name(precision));
    if (precision != SL_FLOW_SINGLE && g->has_lr && !g->blocks->box_buffer_d)
        return sl_err_set(err, SL_ERR_INVALID,
                          "%s precision reads the Bézier blocks in double, which were uploaded without them "
                          "(sl_lr_bezier_upload_double)", sl_flow_precision_name(precision));
    if (seed_count == 0)
        return sl_err_set(err, SL_ERR_INVALID, "no seeds to trace");
    const sl_flow_method *m = &sl_flow_methods[o->solver];
    size_t max_samples = o->max_samples ? o->max_samples : 10000;
    int dbl = precision != SL_FLOW_SINGLE;
    size_t real = dbl ? sizeof(double) : sizeof(float);
    if (seed_count > SL_FLOW_MAX_SEEDS || max_samples > SL_MAX_VERTICES / seed_count)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu seeds x %zu samples exceed %u samples", seed_count,
                          max_samples, (unsigned)SL_MAX_VERTICES);
    size_t sample_bytes = seed_count * max_samples * 8 * real;
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    if (max_block > 0 && sample_bytes > (size_t)max_block)
        return sl_err_set(err, SL_ERR_LIMIT,
                          "%zu seeds x %zu samples need %zu bytes, above this GPU's storage block limit %lld",
                          seed_count, max_samples, sample_bytes, (long long)max_block);
    GLuint program;
    st = program_for(g, precision, &program, err);
    if (st != SL_OK)
        return st;

    void *seed_data = malloc(3 * seed_count * real);
    sl_flow_line *lines = calloc(seed_count, sizeof *lines);
    if (!seed_data || !lines) {
        free(seed_data);
        free(lines);
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu seeds", seed_count);
    }
    for (size_t i = 0; i < 3 * seed_count; i++) {
        if (dbl)
            ((double *)seed_data)[i] = seeds[i];
        else
            ((float *)seed_data)[i] = (float)seeds[i];
    }
    GLuint buf[3];
    glGenBuffers(3, buf);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf[0]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)sample_bytes, NULL, GL_DYNAMIC_READ);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf[1]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(4 * seed_count * sizeof(GLuint)), NULL, GL_DYNAMIC_READ);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf[2]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(3 * seed_count * real), seed_data, GL_STATIC_DRAW);
    free(seed_data);
    for (int i = 0; i < 3; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)i, buf[i]);

    const sl_flow_field *f = &g->field;
    glUseProgram(program);
    if (g->has_lr) {
        sl_lr_bezier_set_uniforms(program, g->bz);
        sl_lr_bezier_bind(g->blocks, program);
    } else {
        sl_flow_field_texture_bind(program, f, g->texture, precision != SL_FLOW_SINGLE);
    }
    set_tableau(program, m, dbl);
    glUniform1i(glGetUniformLocation(program, "u_mode"), (int)o->mode);
    glUniform1ui(glGetUniformLocation(program, "u_lines"), (GLuint)seed_count);
    glUniform1ui(glGetUniformLocation(program, "u_max_samples"), (GLuint)max_samples);
    uniform_vec3(program, "u_lo", f->lo, dbl);
    uniform_vec3(program, "u_hi", f->hi, dbl);
    double h_max = o->h_max > 0.0 ? o->h_max : o->t_max;
    double h_min = o->h_min > 0.0 ? o->h_min : 1e-9 * o->t_max;
    if (h_min > h_max)
        h_min = h_max;
    double step = o->step;
    if (o->mode == SL_FLOW_STEP_HEURISTIC && !g->has_lr)
        step = o->step * sl_flow_local_size(f, f->lo, NULL); /* constant on a regular field */
    /* LR: u_step = H, the shader multiplies by its element's size per point */
    double h0 = o->step > 0.0 ? o->step : pow(o->tol, 1.0 / (double)(m->embedded_order + 1));
    if (m->embedded_order)
        h0 = h0 > h_max ? h_max : h0 < h_min ? h_min : h0;
    uniform_real(program, "u_step", step, dbl);
    uniform_real(program, "u_tol", o->tol, dbl);
    uniform_real(program, "u_h_min", h_min, dbl);
    uniform_real(program, "u_h_max", h_max, dbl);
    uniform_real(program, "u_t_max", o->t_max, dbl);
    uniform_real(program, "u_min_speed", o->min_speed > 0.0 ? o->min_speed : (dbl ? 1e-300 : 1e-37), dbl);
    uniform_real(program, "u_h0", h0, dbl);

    glFinish();
    double t0 = sl_clock_ms();
    sl_gpu_dispatch_chunked(glGetUniformLocation(program, "u_group_base"), (seed_count + 63) / 64, 0);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glFinish();
    if (compute_ms)
        *compute_ms = sl_clock_ms() - t0;

    GLuint *info = malloc(4 * seed_count * sizeof *info);
    void *samples = malloc(sample_bytes);
    st = SL_OK;
    if (!info || !samples) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory reading back %zu bytes of samples", sample_bytes);
    } else {
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf[1]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(4 * seed_count * sizeof *info), info);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf[0]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)sample_bytes, samples);
        st = sl_gl_check_errors("tracing streamlines on the GPU", err);
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    glDeleteBuffers(3, buf);
    glUseProgram(0);
    for (size_t j = 0; st == SL_OK && j < seed_count; j++) {
        sl_flow_line *l = &lines[j];
        size_t n = info[4 * j] <= max_samples ? info[4 * j] : max_samples;
        l->stop = (sl_flow_stop)info[4 * j + 1];
        l->rejected = info[4 * j + 2];
        l->forced = info[4 * j + 3];
        if (n == 0)
            continue;
        l->t = malloc(n * sizeof *l->t);
        l->x = malloc(3 * n * sizeof *l->x);
        l->v = malloc(3 * n * sizeof *l->v);
        if (!l->t || !l->x || !l->v) {
            st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the samples of streamline %zu", j);
            break;
        }
        l->count = n;
        for (size_t i = 0; i < n; i++) {
            size_t b = (j * max_samples + i) * 8;
            double r[7];
            for (int c = 0; c < 7; c++)
                r[c] = dbl ? ((const double *)samples)[b + c] : ((const float *)samples)[b + c];
            l->t[i] = r[0];
            memcpy(l->x + 3 * i, r + 1, 3 * sizeof *r);
            memcpy(l->v + 3 * i, r + 4, 3 * sizeof *r);
        }
    }
    free(info);
    free(samples);
    sl_flow_result r = {seed_count, lines};
    if (st != SL_OK) {
        sl_flow_result_free(&r);
        return st;
    }
    *out = r;
    return SL_OK;
}
