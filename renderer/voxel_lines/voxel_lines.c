/* voxel_lines.c — technique `voxel_lines`: voxel-based ray casting of large
 * line sets (Kanzler, Rautenhaus, Westermann, "A Voxel-based Rendering
 * Pipeline for Large 3D Line Sets", TVCG 2018).
 *
 * prepare voxelizes on the CPU (voxelize_cpu.c: exact clipping, face
 * quantization, bit packing, 5-byte headers) or, with `voxelize = gpu`,
 * with compute shaders (voxelize_gpu.c: the same lines, attribute byte
 * included) and uploads headers and lines. The per-voxel density (eq. 1:
 * sum of length x the line's weight under the opacity transfer function) and
 * its mip chain (the density LoD) are computed on the GPU from the uploaded
 * lines (voxel_lines_density.comp.glsl) at the first frame and whenever the
 * transfer function, attribute or scalar range change — without
 * re-voxelizing. render casts one ray per pixel in a full-screen fragment
 * pass (voxel_lines.frag.glsl). A camera move only renders; radius, opacity
 * and shading are uniforms; AO is recomputed (compute shader) only when it
 * is on and opacity, radius, the density or its own parameters changed; the
 * grid is rebuilt (by the chosen build) when the colour attribute changes or
 * the radius grows above 1 voxel (2 voxels of padding instead of 1). Grid
 * resolution, quantization and the per-voxel cap re-prepare. Data radii are
 * not used (one radius for all tubes). Lines dropped by the per-voxel cap
 * are reported once per build on stderr and in every frame's
 * sl_render_stats.dropped. Two executions of the one model (`backend`, the
 * rule of core/sl_backend.h: cpu on a software GL device): gl, the fragment
 * pass; cpu, voxel_cast_cpu.c, the same walk in C on every core into an
 * sl_host_frame blended into the target as the pass's output is (the
 * density and AO passes stay on GL and are read back once per change).
 * Work counters for tests: voxel_lines.h. Render thread only.
 * Limits: README.md.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../line_style/sl_line_style.h"
#include "../core/sl_backend.h"
#include "../core/sl_clock.h"
#include "../core/sl_technique.h"
#include "../data/sl_dataset.h"
#include "../gpu/sl_gpu.h"
#include "../lines/sl_line_gpu.h"
#include "../gpu/sl_host_frame.h"
#include "../line_style/sl_line_shade.h"
#include "voxel_cast_cpu.h"
#include "voxel_gpu.h"
#include "voxel_grid.h"
#include "voxel_lines.h"
#include "voxel_lod.h"
#include "voxel_occupancy.h"

static const char *const quant_choices[] = {"2", "4", "8", "16", "32", "64", "128", "256", NULL};
static const char *const neighbor_choices[] = {"auto", "own", "always", NULL};
static const char *const build_choices[] = {"auto", "cpu", "gpu", NULL};
static const char *const shadow_choices[] = {"soft", "lines", NULL};
static const char *const opacity_tf_choices[] = {"constant", "ramp", NULL};
static const char *const backend_choices[] = {"auto", "gl", "cpu", NULL};

/* The CPU execution for the backend rule (core/sl_backend.h): always built. */
static void voxel_lines_backend_cpu(sl_backend_cpu *out)
{
    *out = (sl_backend_cpu){.name = "cpu", .built = 1, .missing = ""};
}

static const sl_param_def voxel_lines_params[] = {
    SL_LINE_STYLE_PARAMS,
    SL_BACKEND_PARAM(backend_choices, "cpu"),
    {"opacity", SL_PARAM_FLOAT, 0.0, 1.0, {1.0}, NULL, "", "per-line opacity; 1 = opaque (first hit ends the ray)",
     SL_INVALIDATE_FRAME},
    {"opacity_transfer", SL_PARAM_ENUM, 0, 0, {0}, opacity_tf_choices, "",
     "constant: every line has `opacity`; ramp: opacity x the line's colormap coordinate (attribute through "
     "scalar_min..scalar_max, clamped to 0..1)", SL_INVALIDATE_FRAME},
    {"grid", SL_PARAM_INT, 0, 512, {0}, NULL, "voxels",
     "voxels along the longest side; 0 = automatic (about two segment lengths per voxel, 32..256)",
     SL_INVALIDATE_PREPARED},
    {"quantization", SL_PARAM_ENUM, 0, 0, {4}, quant_choices, "bins",
     "face subdivision N (N x N bins per voxel face)", SL_INVALIDATE_PREPARED},
    {"voxelize", SL_PARAM_ENUM, 0, 0, {0}, build_choices, "",
     "where to voxelize: auto (gpu on a hardware GPU, cpu on a software renderer, where the CPU build is ~10x faster), cpu, or gpu (compute shaders; the same lines)",
     SL_INVALIDATE_PREPARED},
    {"max_lines_per_voxel", SL_PARAM_INT, 1, 255, {255}, NULL, "",
     "cap per voxel (the header count is 8 bits); further lines are dropped and counted", SL_INVALIDATE_PREPARED},
    {"alpha_threshold", SL_PARAM_FLOAT, 0.5, 1.0, {0.99}, NULL, "",
     "early ray termination at this opacity (0.99: the ray caster's speed-up; lines_oit, the exact reference, "
     "defaults to 1)", SL_INVALIDATE_FRAME},
    {"opacity_by_distance", SL_PARAM_BOOL, 0, 1, {0}, NULL, "",
     "scale opacity by the distance travelled inside the tube (opacity per diameter)", SL_INVALIDATE_FRAME},
    {"neighbors", SL_PARAM_ENUM, 0, 0, {0}, neighbor_choices, "",
     "test neighbouring voxels' lines: auto = only for still frames, own = never, always", SL_INVALIDATE_FRAME},
    {"empty_space_skipping", SL_PARAM_BOOL, 0, 1, {1}, NULL, "",
     "skip blocks of up to 8^3 voxels with no line within 2 voxels (occupancy pyramid)", SL_INVALIDATE_FRAME},
    {"shadows", SL_PARAM_BOOL, 0, 1, {0}, NULL, "", "soft shadows from the density LoD", SL_INVALIDATE_FRAME},
    {"shadow_strength", SL_PARAM_FLOAT, 0.0, 1.0, {0.7}, NULL, "", "how dark full shadow is", SL_INVALIDATE_FRAME},
    {"shadow_mode", SL_PARAM_ENUM, 0, 0, {0}, shadow_choices, "",
     "soft: density cone tracing; lines: hard shadows from representative lines at level max(1, shadow_lod)",
     SL_INVALIDATE_FRAME},
    {"shadow_lod", SL_PARAM_INT, 0, 4, {0}, NULL, "level", "finest density level the shadow cone samples",
     SL_INVALIDATE_FRAME},
    {"ao", SL_PARAM_BOOL, 0, 1, {0}, NULL, "", "ambient occlusion from the density field", SL_INVALIDATE_FRAME},
    {"ao_strength", SL_PARAM_FLOAT, 0.0, 1.0, {0.6}, NULL, "", "weight of ambient occlusion", SL_INVALIDATE_FRAME},
    {"ao_rays", SL_PARAM_INT, 4, 256, {100}, NULL, "", "rays per AO cell (paper: 100)", SL_INVALIDATE_FRAME},
    {"ao_radius", SL_PARAM_FLOAT, 1.0, 16.0, {5.0}, NULL, "voxels", "AO radius of influence", SL_INVALIDATE_FRAME},
};

typedef struct voxel_lines_state {
    const sl_dataset *dataset;  /* borrowed */
    sl_voxel_frame frame;
    int resolution;             /* the `grid` parameter (0 = automatic) */
    int padding;                /* empty voxels on each side of the data: 1, or 2 for a radius above 1 voxel */
    int use_gpu;                /* voxelize with compute shaders (voxelize = gpu) */
    int quant, quant_bits, line_bits, max_per_voxel;
    int built_attribute;        /* attribute index of the uploaded attribute bytes, or -1 */
    size_t voxel_count, line_count, grid_bytes;
    double build_ms;
    sl_prepare_stats prep;      /* timings of the last build_and_upload */
    size_t dropped_overflow, capped_voxels;
    GLuint program, ao_program, density_program, vao, camera_ubo;
    sl_line_colors colors;      /* the colormap texture only (the attribute is baked into the grid) */
    GLuint offsets_buf, counts_buf, lines_buf, density_tex, ao_tex, occupancy_tex, reps_buf;
    int rep_levels, rep_dims[SL_VOXEL_LOD_MAX_LEVELS][3], rep_base[SL_VOXEL_LOD_MAX_LEVELS];
    int occupancy_levels;
    int ready;                  /* 1 when every grid buffer is uploaded */
    int ao_dims[3];
    int ao_valid;
    float ao_key[6];            /* extinction, rays, radius and the density key it was computed from */
    int density_levels;
    int density_valid;          /* level 0 holds the weighted density of density_key */
    float density_key[3];       /* opacity ramp on, colormap t of bytes 0 and 255 (0, 0 when off) */
    sl_voxel_occupancy occupancy; /* the pyramid behind occupancy_tex */
    sl_backend backend;         /* the execution chosen at prepare */
    sl_voxel_cast_model cpu;    /* backend cpu: the decoded model, density and AO copies */
    float *reps_host;           /* backend cpu: the representative lines (reps_buf's floats) */
    sl_host_frame host;         /* backend cpu: the cast frame on its way into the target */
    sl_voxel_cast_stats cast;   /* backend cpu: the last frame's work */
    int cpu_density_valid;      /* backend cpu: cpu.density holds density_tex's levels */
    int cpu_ao_valid;           /* backend cpu: cpu.ao holds ao_tex */
} voxel_lines_state;

static void release_grid(voxel_lines_state *s)
{
    GLuint bufs[4] = {s->offsets_buf, s->counts_buf, s->lines_buf, s->reps_buf};
    for (int i = 0; i < 4; i++)
        if (bufs[i])
            glDeleteBuffers(1, &bufs[i]);
    if (s->density_tex) glDeleteTextures(1, &s->density_tex);
    if (s->ao_tex) glDeleteTextures(1, &s->ao_tex);
    if (s->occupancy_tex) glDeleteTextures(1, &s->occupancy_tex);
    s->offsets_buf = s->counts_buf = s->lines_buf = s->density_tex = s->ao_tex = s->occupancy_tex = 0;
    s->reps_buf = 0;
    s->rep_levels = 0;
    sl_voxel_cast_model_deinit(&s->cpu);
    sl_voxel_occupancy_deinit(&s->occupancy);
    free(s->reps_host);
    s->reps_host = NULL;
    s->ao_valid = 0;
    s->density_valid = 0;
    s->ready = 0;
}

static void voxel_lines_release(void *opaque)
{
    voxel_lines_state *s = opaque;
    if (!s)
        return;
    release_grid(s);
    if (s->program) glDeleteProgram(s->program);
    if (s->ao_program) glDeleteProgram(s->ao_program);
    if (s->density_program) glDeleteProgram(s->density_program);
    if (s->vao) glDeleteVertexArrays(1, &s->vao);
    if (s->camera_ubo) glDeleteBuffers(1, &s->camera_ubo);
    sl_line_colors_deinit(&s->colors);
    sl_host_frame_deinit(&s->host);
    free(s);
}

/* Work counters (voxel_lines.h); render thread only, like every entry point. */
static sl_voxel_lines_counters counters;

void sl_voxel_lines_get_counters(sl_voxel_lines_counters *out)
{
    *out = counters;
}

static GLuint make_buffer(const void *data, size_t bytes)
{
    GLuint b;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(bytes ? bytes : 4), bytes ? data : NULL, 0);
    return b;
}

/* The occupancy pyramid for empty-space skipping (voxel_occupancy.h): built
 * on the CPU from the counts, kept for the CPU execution, uploaded as an
 * R8UI 3D texture with one mip level per pyramid level. */
static sl_status upload_occupancy(voxel_lines_state *s, const uint8_t *counts, sl_err *err)
{
    sl_voxel_occupancy_deinit(&s->occupancy);
    sl_status st = sl_voxel_occupancy_build(s->frame.dims, counts, SL_VOXEL_OCCUPANCY_DILATE, &s->occupancy, err);
    if (st != SL_OK)
        return st;
    const sl_voxel_occupancy *o = &s->occupancy;
    s->occupancy_levels = o->levels;
    glCreateTextures(GL_TEXTURE_3D, 1, &s->occupancy_tex);
    glTextureStorage3D(s->occupancy_tex, o->levels, GL_R8UI, o->dims[0][0], o->dims[0][1], o->dims[0][2]);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (int level = 0; level < o->levels; level++)
        glTextureSubImage3D(s->occupancy_tex, level, 0, 0, 0, o->dims[level][0], o->dims[level][1],
                            o->dims[level][2], GL_RED_INTEGER, GL_UNSIGNED_BYTE, o->level[level]);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureParameteri(s->occupancy_tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glTextureParameteri(s->occupancy_tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return SL_OK;
}

/* Representative lines of levels 1..4 (level 0 would cost 24 bytes per
 * voxel) in one buffer; level L starts at rep_base[L] floats. */
static sl_status upload_representatives(voxel_lines_state *s, const sl_voxel_grid *g, sl_err *err)
{
    sl_voxel_lod lod;
    sl_status st = sl_voxel_lod_build(g, SL_VOXEL_LOD_MAX_LEVELS, &lod, err);
    if (st != SL_OK)
        return st;
    size_t total = 0;
    for (int L = 1; L < lod.levels; L++) {
        s->rep_base[L] = (int)total;
        memcpy(s->rep_dims[L], lod.level[L].dims, sizeof s->rep_dims[L]);
        total += 6u * (size_t)lod.level[L].dims[0] * lod.level[L].dims[1] * lod.level[L].dims[2];
    }
    float *all = malloc((total ? total : 1) * sizeof *all);
    if (!all) {
        sl_voxel_lod_deinit(&lod);
        return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines: out of memory for representative lines");
    }
    for (int L = 1; L < lod.levels; L++)
        memcpy(all + s->rep_base[L], lod.level[L].lines,
               6u * sizeof(float) * (size_t)lod.level[L].dims[0] * lod.level[L].dims[1] * lod.level[L].dims[2]);
    s->rep_levels = lod.levels;
    s->reps_buf = make_buffer(all, total * sizeof *all);
    s->grid_bytes += total * sizeof *all;
    if (s->backend == SL_BACKEND_CPU)
        s->reps_host = all;
    else
        free(all);
    sl_voxel_lod_deinit(&lod);
    return SL_OK;
}

/* Voxelizes with the given attribute and uploads; replaces any previous grid. */
static sl_status build_and_upload(voxel_lines_state *s, int attribute, sl_err *err)
{
    sl_voxel_grid g;
    sl_voxel_grid_desc desc = {.resolution = s->resolution, .quant = s->quant, .padding = s->padding,
                               .max_per_voxel = s->max_per_voxel, .attribute = attribute};
    double t_build = sl_clock_ms();
    sl_status st = s->use_gpu ? sl_voxel_grid_build_gpu(&g, s->dataset, &desc, err)
                              : sl_voxel_grid_build(&g, s->dataset, &desc, err);
    if (st != SL_OK)
        return st;
    double t_pack = sl_clock_ms();
    s->prep = (sl_prepare_stats){0};
    if (s->use_gpu)
        s->prep.gpu_ms = t_pack - t_build; /* compute passes + readback */
    else
        s->prep.preprocess_ms = t_pack - t_build;
    release_grid(s);
    counters.builds++;
    s->frame = g.frame;
    s->quant_bits = g.quant_bits;
    s->line_bits = 8 * g.line_bytes;
    s->voxel_count = g.voxel_count;
    s->line_count = g.line_count;
    s->build_ms = g.build_ms;
    s->dropped_overflow = g.dropped_overflow;
    s->capped_voxels = g.capped_voxels;
    s->built_attribute = g.attribute_index;
    s->grid_bytes = sl_voxel_grid_bytes(&g);

    size_t count_words = (g.voxel_count + 3) / 4;
    uint32_t *packed = calloc(count_words ? count_words : 1, sizeof *packed);
    size_t line_bytes = g.line_count * (size_t)g.line_bytes + 8;
    size_t line_words = (line_bytes + 3) / 4;
    uint32_t *words = calloc(line_words, sizeof *words);
    if (!packed || !words) {
        free(packed);
        free(words);
        sl_voxel_grid_deinit(&g);
        return sl_err_set(err, SL_ERR_NOMEM, "voxel_lines: out of memory packing %zu voxels", g.voxel_count);
    }
    for (size_t v = 0; v < g.voxel_count; v++)
        packed[v / 4] |= (uint32_t)g.counts[v] << (8 * (v % 4));
    memcpy(words, g.lines, g.line_count * (size_t)g.line_bytes);
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    size_t biggest = line_words * sizeof(uint32_t) > g.voxel_count * sizeof(uint32_t)
                         ? line_words * sizeof(uint32_t) : g.voxel_count * sizeof(uint32_t);
    /* The shaders address lines by byte offset in 32 bits (voxel_lines_grid.glsl). */
    if ((max_block > 0 && biggest > (size_t)max_block) || (uint64_t)line_words * 4u > UINT32_MAX) {
        free(packed);
        free(words);
        sl_voxel_grid_deinit(&g);
        return sl_err_set(err, SL_ERR_LIMIT,
                          "voxel_lines: a %zu-byte buffer exceeds the GPU's shader storage block limit of %lld bytes; "
                          "lower `grid` or `quantization`", biggest, (long long)max_block);
    }
    double t_upload = sl_clock_ms();
    s->prep.preprocess_ms += t_upload - t_pack; /* packing the counts and lines */
    s->offsets_buf = make_buffer(g.offsets, g.voxel_count * sizeof(uint32_t));
    s->counts_buf = make_buffer(packed, count_words * sizeof(uint32_t));
    s->lines_buf = make_buffer(words, line_words * sizeof(uint32_t));
    free(packed);
    free(words);

    int maxdim = g.frame.dims[0];
    for (int c = 1; c < 3; c++)
        if (g.frame.dims[c] > maxdim)
            maxdim = g.frame.dims[c];
    s->density_levels = 1;
    while ((1 << s->density_levels) <= maxdim)
        s->density_levels++;
    glCreateTextures(GL_TEXTURE_3D, 1, &s->density_tex);
    /* Filled by update_density (weighted by the opacity transfer function). */
    glTextureStorage3D(s->density_tex, s->density_levels, GL_R32F, g.frame.dims[0], g.frame.dims[1], g.frame.dims[2]);
    glTextureParameteri(s->density_tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(s->density_tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    const float zero[4] = {0, 0, 0, 0};
    glTextureParameterfv(s->density_tex, GL_TEXTURE_BORDER_COLOR, zero);
    glTextureParameteri(s->density_tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTextureParameteri(s->density_tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    glTextureParameteri(s->density_tex, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_BORDER);
    /* AO at half resolution (at least 1): a low-frequency field. */
    for (int c = 0; c < 3; c++)
        s->ao_dims[c] = (g.frame.dims[c] + 1) / 2;
    glCreateTextures(GL_TEXTURE_3D, 1, &s->ao_tex);
    glTextureStorage3D(s->ao_tex, 1, GL_R8, s->ao_dims[0], s->ao_dims[1], s->ao_dims[2]);
    glTextureParameteri(s->ao_tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(s->ao_tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(s->ao_tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(s->ao_tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(s->ao_tex, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    s->grid_bytes += (size_t)s->ao_dims[0] * s->ao_dims[1] * s->ao_dims[2];
    s->ao_valid = 0;
    s->density_valid = 0;
    st = upload_occupancy(s, g.counts, err);
    glFinish();
    double t_reps = sl_clock_ms();
    s->prep.upload_ms = t_reps - t_upload;
    if (st == SL_OK)
        st = upload_representatives(s, &g, err); /* mostly the CPU LoD build */
    if (st == SL_OK && s->backend == SL_BACKEND_CPU)
        st = sl_voxel_cast_model_build(&s->cpu, &g, err);
    s->prep.preprocess_ms += sl_clock_ms() - t_reps;
    s->ready = st == SL_OK;
    if (st == SL_OK && g.dropped_overflow)
        fprintf(stderr, "voxel_lines: %zu lines dropped in %zu voxels above the %d-line header limit "
                        "(largest voxel: %d lines)\n", g.dropped_overflow, g.capped_voxels, s->max_per_voxel,
                g.max_count);
    s->grid_bytes += s->voxel_count * 8 / 7;
    sl_voxel_grid_deinit(&g);
    return st;
}

/* Padding (empty voxels around the data) that keeps tubes of radius_g voxels
 * at the data's edge inside the grid: ceil(radius), at least 1 and at most
 * 2 (the neighbour search reaches 2 voxels; beyond, tubes are cut anyway). */
static int padding_for(float radius_g)
{
    return radius_g > 1.0f ? 2 : 1;
}

static sl_status voxel_lines_prepare(sl_gpu *gpu, const sl_dataset *ds, const sl_params *params, void **out,
                                     sl_err *err)
{
    (void)gpu;
    *out = NULL;
    voxel_lines_state *s = calloc(1, sizeof *s);
    if (!s)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory");
    s->dataset = ds;
    s->quant = atoi(sl_params_choice_name(params, "quantization"));
    s->max_per_voxel = sl_params_int(params, "max_lines_per_voxel");
    s->resolution = sl_params_int(params, "grid");
    int build = sl_params_choice(params, "voxelize");
    s->use_gpu = build == 2 || (build == 0 && !sl_gpu_is_software(gpu));
    sl_status st = sl_line_style_check(params, ds, err);
    if (st != SL_OK) {
        free(s);
        return st;
    }
    sl_line_style style;
    sl_line_style_read(params, ds, &style);
    sl_voxel_frame probe;
    st = sl_voxel_frame_init(&probe, ds, s->resolution, 1, err); /* h does not depend on padding */
    if (st != SL_OK) {
        free(s);
        return st;
    }
    s->padding = padding_for((float)(style.radius / probe.h));
    sl_backend_cpu cpu;
    voxel_lines_backend_cpu(&cpu);
    st = sl_backend_decide("voxel_lines", sl_params_choice(params, "backend"), sl_gpu_is_software(gpu), &cpu,
                           &s->backend, err);
    if (st != SL_OK) {
        free(s);
        return st;
    }
    st = build_and_upload(s, style.attribute, err);
    if (st == SL_OK && s->backend == SL_BACKEND_GL) /* the cpu backend casts on the CPU */
        st = sl_gl_program_create(&(sl_program_desc){.vertex = "gpu/glsl/fullscreen_triangle.vert.glsl",
                                                     .fragment = "voxel_lines/voxel_lines.frag.glsl",
                                                     .label = "voxel_lines"},
                                  &s->program, err);
    if (st == SL_OK)
        st = sl_gl_program_create(&(sl_program_desc){.compute = "voxel_lines/voxel_lines_ao.comp.glsl",
                                                     .label = "voxel_lines_ao"},
                                  &s->ao_program, err);
    if (st == SL_OK)
        st = sl_gl_program_create(&(sl_program_desc){.compute = "voxel_lines/voxel_lines_density.comp.glsl",
                                                     .label = "voxel_lines_density"},
                                  &s->density_program, err);
    if (st != SL_OK) {
        voxel_lines_release(s);
        return st;
    }
    glCreateVertexArrays(1, &s->vao);
    if ((st = sl_line_colors_init(&s->colors, ds->lines.vertex_count, 0, "voxel_lines", err)) != SL_OK ||
        (st = sl_gl_check_errors("voxel_lines: uploading the voxel model", err)) != SL_OK) {
        voxel_lines_release(s);
        return st;
    }
    *out = s;
    return SL_OK;
}

static void set1f(GLuint p, const char *n, float v) { glUniform1f(glGetUniformLocation(p, n), v); }
static void set1i(GLuint p, const char *n, int v) { glUniform1i(glGetUniformLocation(p, n), v); }

/* Dispatches 4^3 groups over dims; the group counts (<= 257 per axis for
 * SL_VOXEL_MAX_DIM) are checked against the driver's limits anyway. */
static sl_status dispatch_cells(const int dims[3], const char *what, sl_err *err)
{
    GLuint groups[3];
    for (int c = 0; c < 3; c++) {
        GLint limit = 0;
        glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, (GLuint)c, &limit);
        groups[c] = (GLuint)(dims[c] + 3) / 4;
        if (limit > 0 && groups[c] > (GLuint)limit)
            return sl_err_set(err, SL_ERR_LIMIT, "voxel_lines: %s needs %u work groups on axis %d, above the GPU's %d",
                              what, groups[c], c, limit);
    }
    glDispatchCompute(groups[0], groups[1], groups[2]);
    return SL_OK;
}

static sl_status compute_ao(voxel_lines_state *s, float extinction, int rays, float radius, sl_err *err)
{
    glUseProgram(s->ao_program);
    set1i(s->ao_program, "u_density", 0);
    glBindTextureUnit(0, s->density_tex);
    glUniform3i(glGetUniformLocation(s->ao_program, "u_ao_dims"), s->ao_dims[0], s->ao_dims[1], s->ao_dims[2]);
    set1i(s->ao_program, "u_rays", rays);
    set1f(s->ao_program, "u_radius", radius);
    set1f(s->ao_program, "u_extinction", extinction);
    glBindImageTexture(0, s->ao_tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R8);
    sl_status st = dispatch_cells(s->ao_dims, "ambient occlusion", err);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    counters.ao_passes++;
    s->cpu_ao_valid = 0;
    return st;
}

/* Backend cpu: copies of the density chain and the AO field the GL passes computed. */
static sl_status read_back_density(voxel_lines_state *s, sl_err *err)
{
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    for (int level = 0; level < s->density_levels && level < SL_VOXEL_CAST_MAX_LEVELS; level++) {
        int d[3];
        glGetTextureLevelParameteriv(s->density_tex, level, GL_TEXTURE_WIDTH, &d[0]);
        glGetTextureLevelParameteriv(s->density_tex, level, GL_TEXTURE_HEIGHT, &d[1]);
        glGetTextureLevelParameteriv(s->density_tex, level, GL_TEXTURE_DEPTH, &d[2]);
        float *dst = sl_voxel_cast_density_level(&s->cpu, level, d, err);
        if (!dst)
            return err ? err->status : SL_ERR_NOMEM;
        glGetTextureImage(s->density_tex, level, GL_RED, GL_FLOAT, (GLsizei)((size_t)d[0] * d[1] * d[2] * sizeof(float)),
                          dst);
    }
    s->cpu_density_valid = 1;
    return sl_gl_check_errors("voxel_lines (cpu): reading the density back", err);
}

static sl_status read_back_ao(voxel_lines_state *s, sl_err *err)
{
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    uint8_t *dst = sl_voxel_cast_ao(&s->cpu, s->ao_dims, err);
    if (!dst)
        return err ? err->status : SL_ERR_NOMEM;
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(s->ao_tex, 0, GL_RED, GL_UNSIGNED_BYTE,
                      (GLsizei)((size_t)s->ao_dims[0] * s->ao_dims[1] * s->ao_dims[2]), dst);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    s->cpu_ao_valid = 1;
    return sl_gl_check_errors("voxel_lines (cpu): reading the AO field back", err);
}

/* Level 0 of the density texture from the uploaded lines, each weighted by
 * the opacity transfer function (voxel_lines_density.comp.glsl), then the
 * mip chain (the density octree). key = {ramp on, t of byte 0, t of byte 255}. */
static sl_status update_density(voxel_lines_state *s, const float key[3], sl_err *err)
{
    GLuint p = s->density_program;
    glUseProgram(p);
    glUniform3i(glGetUniformLocation(p, "u_dims"), s->frame.dims[0], s->frame.dims[1], s->frame.dims[2]);
    set1i(p, "u_quant", s->quant);
    set1i(p, "u_quant_bits", s->quant_bits);
    set1i(p, "u_line_bits", s->line_bits);
    set1i(p, "u_opacity_ramp", key[0] != 0.0f);
    glUniform2f(glGetUniformLocation(p, "u_attr_range"), key[1], key[2]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s->offsets_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->counts_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, s->lines_buf);
    glBindImageTexture(0, s->density_tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    sl_status st = dispatch_cells(s->frame.dims, "the density pass", err);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    glGenerateTextureMipmap(s->density_tex);
    counters.density_passes++;
    s->cpu_density_valid = 0;
    if (st == SL_OK) {
        memcpy(s->density_key, key, sizeof s->density_key);
        s->density_valid = 1;
    }
    return st;
}

static sl_status voxel_lines_render(void *opaque, const sl_view *view, const sl_params *params, sl_target *target,
                                    sl_render_stats *stats, sl_err *err)
{
    (void)target;
    voxel_lines_state *s = opaque;
    sl_status st = sl_line_style_check(params, s->dataset, err);
    if (st != SL_OK)
        return st;
    sl_line_style style;
    sl_line_style_read(params, s->dataset, &style);
    /* Rebuild (re-voxelize) when the attribute bytes change, or when the
     * radius grew beyond the padding (the grid's placement keeps h). */
    int padding = padding_for((float)(style.radius / s->frame.h));
    if (style.attribute != s->built_attribute || !s->ready || padding > s->padding) {
        if (padding > s->padding)
            s->padding = padding;
        sl_status st = build_and_upload(s, style.attribute, err);
        if (st != SL_OK)
            return st;
    }
    int ramp = style.attribute >= 0 && sl_params_choice(params, "opacity_transfer") == 1;
    float span = style.scalar_range[1] - style.scalar_range[0];
    float attr_range[2] = {0.5f, 0.5f};
    if (style.attribute >= 0 && span != 0.0f) { /* min > max: inverted, as in colormap.glsl */
        const sl_attribute *a = &s->dataset->lines.attributes[style.attribute];
        attr_range[0] = (a->min - style.scalar_range[0]) / span;
        attr_range[1] = (a->max - style.scalar_range[0]) / span;
    }
    /* The density (and so shadows and AO) follows the transfer function;
     * with a constant opacity the weights are 1 whatever the attribute. */
    float density_key[3] = {(float)ramp, ramp ? attr_range[0] : 0.0f, ramp ? attr_range[1] : 0.0f};
    if (!s->density_valid || memcmp(density_key, s->density_key, sizeof density_key) != 0) {
        sl_status st = update_density(s, density_key, err);
        if (st != SL_OK)
            return st;
    }
    sl_line_colors_update(&s->colors, &s->dataset->lines, &style);
    const double h = s->frame.h;
    float opacity = (float)sl_params_float(params, "opacity");
    float radius_g = (float)(style.radius / h);
    float extinction = opacity * 2.0f * radius_g;
    int shadows = sl_params_bool(params, "shadows"), ao = sl_params_bool(params, "ao");
    if (ao) {
        int rays = sl_params_int(params, "ao_rays");
        float ao_radius = (float)sl_params_float(params, "ao_radius");
        float key[6] = {extinction, (float)rays, ao_radius, density_key[0], density_key[1], density_key[2]};
        if (!s->ao_valid || memcmp(key, s->ao_key, sizeof key) != 0) {
            sl_status st = compute_ao(s, extinction, rays, ao_radius, err);
            if (st != SL_OK)
                return st;
            memcpy(s->ao_key, key, sizeof key);
            s->ao_valid = 1;
        }
    }
    int neighbors;
    switch (sl_params_choice(params, "neighbors")) {
    case 1: neighbors = 0; break;
    case 2: neighbors = 1; break;
    default: neighbors = view->quality == SL_QUALITY_STILL; break;
    }
    if (neighbors)
        neighbors = radius_g > 1.0f ? (radius_g > 2.0f ? 2 : (int)ceilf(radius_g)) : 1;

    /* Opaque lines end the ray at the first hit (alpha reaches 1); with the
     * ramp they are translucent even at opacity 1, so the threshold applies. */
    float alpha_stop = opacity >= 1.0f && !ramp ? 1.0f : (float)sl_params_float(params, "alpha_threshold");
    int skip_levels = sl_params_bool(params, "empty_space_skipping") ? s->occupancy_levels - 1 : -1;
    int rep_level = sl_params_int(params, "shadow_lod");
    rep_level = rep_level < 1 ? 1 : (rep_level >= s->rep_levels ? s->rep_levels - 1 : rep_level);
    int shadow_lines = shadows && sl_params_choice(params, "shadow_mode") == 1 && rep_level >= 1;
    sl_backend_cpu cpu;
    voxel_lines_backend_cpu(&cpu);
    stats->backend = sl_backend_name(s->backend, &cpu);
    stats->primitives = (double)view->width * view->height;
    stats->dropped = (double)s->dropped_overflow;
    const sl_dataset *ds = s->dataset;
    sl_vec3 eye = sl_v3_sub(view->camera.eye, ds->origin);
    float eye_g[3] = {(float)((eye.x - s->frame.lo[0]) / h), (float)((eye.y - s->frame.lo[1]) / h),
                      (float)((eye.z - s->frame.lo[2]) / h)};
    if (s->backend == SL_BACKEND_CPU) {
        if (((shadows && !shadow_lines) || ao) && !s->cpu_density_valid && (st = read_back_density(s, err)) != SL_OK)
            return st;
        if (ao && !s->cpu_ao_valid && (st = read_back_ao(s, err)) != SL_OK)
            return st;
        sl_line_shader shader;
        sl_line_shader_init(&shader, &style, view);
        shader.range[0] = 0.0f; /* the shader's colormap takes t (attribute byte through attr_range) */
        shader.range[1] = 1.0f;
        sl_voxel_cast_params cp = {
            .eye_g = {eye_g[0], eye_g[1], eye_g[2]}, .inv_h = (float)(1.0 / h), .radius_g = radius_g,
            .opacity = opacity, .alpha_stop = alpha_stop, .neighbors = neighbors,
            .opacity_by_distance = sl_params_bool(params, "opacity_by_distance"), .opacity_ramp = ramp,
            .attr_range = {attr_range[0], attr_range[1]}, .skip_levels = skip_levels, .occupancy = &s->occupancy,
            .extinction = extinction, .shadows = shadows, .shadow_lines = shadow_lines, .ao_on = ao,
            .shadow_strength = (float)sl_params_float(params, "shadow_strength"),
            .shadow_lod = (float)sl_params_int(params, "shadow_lod"), .max_lod = (float)(s->density_levels - 1),
            .ao_strength = (float)sl_params_float(params, "ao_strength"),
            .reps = shadow_lines && s->reps_host ? s->reps_host + s->rep_base[rep_level] : NULL,
            .rep_dims = {s->rep_dims[rep_level][0], s->rep_dims[rep_level][1], s->rep_dims[rep_level][2]},
            .rep_scale = (float)(1 << rep_level), .shader = &shader, .reach_lists = neighbors > 0};
        if (neighbors > 0 && (st = sl_voxel_cast_model_reach(&s->cpu, radius_g, neighbors, err)) != SL_OK)
            return st;
        if ((st = sl_host_frame_resize(&s->host, view->width, view->height, err)) != SL_OK ||
            (st = sl_voxel_cast_render(&s->cpu, &cp, view, &s->host, &s->cast, err)) != SL_OK)
            return st;
        counters.cpu_frames++;
        stats->threads = s->cast.threads;
        stats->samples = s->cast.voxels; /* voxels the rays stepped through (not jumped over) */
        return sl_host_frame_draw(&s->host, err);
    }

    sl_camera_ubo_update(&s->camera_ubo, view);
    GLuint p = s->program;
    glUseProgram(p);
    glUniform3f(glGetUniformLocation(p, "u_eye_g"), eye_g[0], eye_g[1], eye_g[2]);
    glUniform3i(glGetUniformLocation(p, "u_dims"), s->frame.dims[0], s->frame.dims[1], s->frame.dims[2]);
    set1i(p, "u_quant", s->quant);
    set1i(p, "u_quant_bits", s->quant_bits);
    set1i(p, "u_line_bits", s->line_bits);
    set1f(p, "u_inv_h", (float)(1.0 / h));
    set1f(p, "u_radius_g", radius_g);
    set1f(p, "u_opacity", opacity);
    set1f(p, "u_alpha_stop", alpha_stop);
    set1i(p, "u_neighbors", neighbors);
    set1i(p, "u_opacity_by_distance", sl_params_bool(params, "opacity_by_distance"));
    sl_line_style_uniforms(p, &style, 0);
    set1i(p, "u_opacity_ramp", ramp);
    glUniform2fv(glGetUniformLocation(p, "u_attr_range"), 1, attr_range);
    set1i(p, "u_density", 1);
    set1i(p, "u_ao", 2);
    set1i(p, "u_occupancy", 3);
    set1i(p, "u_skip_levels", skip_levels);
    set1f(p, "u_extinction", extinction);
    set1i(p, "u_shadows", shadows);
    set1f(p, "u_shadow_strength", (float)sl_params_float(params, "shadow_strength"));
    set1f(p, "u_shadow_lod", (float)sl_params_int(params, "shadow_lod"));
    set1f(p, "u_max_lod", (float)(s->density_levels - 1));
    set1i(p, "u_ao_on", ao);
    set1i(p, "u_shadow_lines", shadow_lines);
    glUniform3i(glGetUniformLocation(p, "u_rep_dims"), s->rep_dims[rep_level][0], s->rep_dims[rep_level][1],
                s->rep_dims[rep_level][2]);
    set1i(p, "u_rep_base", s->rep_base[rep_level]);
    set1f(p, "u_rep_scale", (float)(1 << rep_level));
    set1f(p, "u_ao_strength", (float)sl_params_float(params, "ao_strength"));
    sl_line_colors_bind(&s->colors, 0, 0);
    glBindTextureUnit(1, s->density_tex);
    glBindTextureUnit(2, s->ao_tex);
    glBindTextureUnit(3, s->occupancy_tex);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s->offsets_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s->counts_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, s->lines_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s->reps_buf);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(s->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    return SL_OK;
}

static void voxel_lines_prepare_stats(const void *opaque, sl_prepare_stats *out)
{
    const voxel_lines_state *s = opaque;
    *out = s ? s->prep : (sl_prepare_stats){0};
}

static size_t voxel_lines_gpu_bytes(const void *opaque)
{
    const voxel_lines_state *s = opaque;
    return s ? s->grid_bytes + sl_line_colors_bytes(&s->colors) : 0;
}

const sl_technique sl_voxel_lines_technique = {
    .name = "voxel_lines",
    .description = "voxel-based ray casting of line sets with transparency, soft shadows and AO (Kanzler et al. 2018)",
    .dataset_kinds = SL_DATASET_LINES,
    .params = voxel_lines_params,
    .param_count = (int)(sizeof voxel_lines_params / sizeof voxel_lines_params[0]),
    .prepare = voxel_lines_prepare,
    .render = voxel_lines_render,
    .release = voxel_lines_release,
    .gpu_bytes = voxel_lines_gpu_bytes,
    .prepare_stats = voxel_lines_prepare_stats,
    .backend_cpu = voxel_lines_backend_cpu,
};
