/* particles_system.c — the GPU particle system of one set (particles_system.h).
 *
 * Buffers of a build (m = seeded particles): two particle arrays of 32 B
 * (ping-pong: the energy step reads one in bin order and writes the other),
 * keys and values (4 B each, the sorter's), the energy per work group, the
 * bin table (4 B per bin) and at the end the records (48 B) and the
 * nearest-neighbour distances (4 B), and the list of lattice tiles to
 * place in (4 B per tile, built on the CPU from the min-max bricks). Only
 * the records and the table are kept. Render thread only.
 */
#include "particles_system.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/sl_clock.h"
#include "../gpu/sl_gpu.h"

#define PT_MAX_BINS (1u << 22)      /* 16 MiB of table */
#define PT_MAX_GROUPS 65535u
#define PT_MAX_OFFSET_VOXELS 0.01   /* farther from the surface after settling: lost (dropped) */        /* per 1-D dispatch (the GL minimum, llvmpipe's limit) */

struct pt_system {
    GLuint place[2];                /* PT_EMIT 0, 1 */
    GLuint keys, gather, energy, settle, final;
    pt_sorter *sorter;
};

static sl_status compute_program(const char *file, const char *defines, const char *label, GLuint *out, sl_err *err)
{
    return sl_gl_program_create(&(sl_program_desc){.compute = file, .defines = defines, .label = label}, out, err);
}

void pt_system_destroy(pt_system *sys)
{
    if (!sys)
        return;
    GLuint *programs[] = {&sys->place[0], &sys->place[1], &sys->keys, &sys->gather, &sys->energy, &sys->settle,
                          &sys->final};
    for (size_t i = 0; i < sizeof programs / sizeof programs[0]; i++)
        if (*programs[i])
            glDeleteProgram(*programs[i]);
    pt_sorter_destroy(sys->sorter);
    free(sys);
}

sl_status pt_system_create(pt_system **out, sl_err *err)
{
    *out = NULL;
    pt_system *sys = calloc(1, sizeof *sys);
    if (!sys)
        return sl_err_set(err, SL_ERR_NOMEM, "particles: out of memory");
    sl_status st;
    if ((st = compute_program("particles/particles_place.comp.glsl", "#define PT_EMIT 0\n", "particles place (count)",
                              &sys->place[0], err)) != SL_OK ||
        (st = compute_program("particles/particles_place.comp.glsl", "#define PT_EMIT 1\n", "particles place (emit)",
                              &sys->place[1], err)) != SL_OK ||
        (st = compute_program("particles/particles_bins.comp.glsl", "#define PT_PASS 0\n", "particles keys",
                              &sys->keys, err)) != SL_OK ||
        (st = compute_program("particles/particles_bins.comp.glsl", "#define PT_PASS 1\n", "particles gather",
                              &sys->gather, err)) != SL_OK ||
        (st = compute_program("particles/particles_energy.comp.glsl", NULL, "particles energy", &sys->energy,
                              err)) != SL_OK ||
        (st = compute_program("particles/particles_settle.comp.glsl", NULL, "particles settle", &sys->settle,
                              err)) != SL_OK ||
        (st = compute_program("particles/particles_final.comp.glsl", NULL, "particles final", &sys->final, err)) !=
            SL_OK ||
        (st = pt_sorter_create(&sys->sorter, err)) != SL_OK) {
        pt_system_destroy(sys);
        return st;
    }
    *out = sys;
    return SL_OK;
}

void pt_set_release(pt_set *set)
{
    if (set->records)
        glDeleteBuffers(1, &set->records);
    if (set->table)
        glDeleteBuffers(1, &set->table);
    memset(set, 0, sizeof *set);
}

static GLuint ssbo(size_t bytes)
{
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)(bytes ? bytes : 16), NULL, GL_DYNAMIC_STORAGE_BIT);
    return b;
}

static void u1ui(GLuint p, const char *name, GLuint v) { glUniform1ui(glGetUniformLocation(p, name), v); }
static void u1f(GLuint p, const char *name, double v) { glUniform1f(glGetUniformLocation(p, name), (float)v); }

static void set_field_uniforms(GLuint p, const pt_field *f)
{
    glUniform1i(glGetUniformLocation(p, "u_volume"), 0);
    glUniform3i(glGetUniformLocation(p, "u_voxel_dims"), f->dims[0], f->dims[1], f->dims[2]);
    glUniform2f(glGetUniformLocation(p, "u_value_map"), f->value_scale, f->value_offset);
    glUniform3f(glGetUniformLocation(p, "u_spacing"), (float)f->spacing[0], (float)f->spacing[1],
                (float)f->spacing[2]);
}

/* The local-world extent of the box spanning the voxel centres. */
static void set_box_uniform(GLuint p, const pt_field *f)
{
    glUniform3f(glGetUniformLocation(p, "u_box_world"), (float)((f->dims[0] - 1) * f->spacing[0]),
                (float)((f->dims[1] - 1) * f->spacing[1]), (float)((f->dims[2] - 1) * f->spacing[2]));
}

static void set_bin_uniforms(GLuint p, const pt_set *s)
{
    u1f(p, "u_bin_size", s->bin_size);
    glUniform3i(glGetUniformLocation(p, "u_bin_origin"), s->bin_origin[0], s->bin_origin[1], s->bin_origin[2]);
    glUniform3i(glGetUniformLocation(p, "u_bin_dims"), s->bin_dims[0], s->bin_dims[1], s->bin_dims[2]);
    u1ui(p, "u_bins", s->bins);
}

static void dispatch_1d(uint32_t n, uint32_t group)
{
    uint32_t groups = (n + group - 1) / group;
    if (groups)
        glDispatchCompute(groups, 1, 1);
}

static unsigned bits_for(uint64_t max_value)
{
    unsigned b = 1;
    while (b < 32 && (max_value >> b) != 0)
        b++;
    return b;
}

/* Per-phase wall time: the GL queue is drained at both ends. */
static double phase_end(double t0)
{
    glFinish();
    return sl_clock_ms() - t0;
}

typedef struct build_buffers {
    GLuint particles[2], keys, values, group_energy, nearest, counter, tiles;
} build_buffers;

static void free_build_buffers(build_buffers *b)
{
    GLuint *all[] = {&b->particles[0], &b->particles[1], &b->keys, &b->values, &b->group_energy, &b->nearest,
                     &b->counter, &b->tiles};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        if (*all[i])
            glDeleteBuffers(1, all[i]);
    memset(b, 0, sizeof *b);
}

/* The bricks the isovalue may cross: brick b (voxels [8b, 8b + 8] per axis)
 * when min < iso + eps and max >= iso - eps over its finite values, eps
 * covering the float rounding of the GPU's value map and interpolation (a
 * crossing needs one value below iso and one at or above it, both
 * interpolated from the brick's voxels). Returns a mask (malloc'd, 1 byte
 * per brick) and the voxel box of the marked bricks in lo/hi (lo > hi: none),
 * or NULL when out of memory. */
static uint8_t *iso_bricks(const pt_field *f, double iso, int lo[3], int hi[3])
{
    const sl_volume_bricks *b = f->bricks;
    size_t n = (size_t)b->dims[0] * (size_t)b->dims[1] * (size_t)b->dims[2];
    uint8_t *mask = malloc(n ? n : 1);
    if (!mask)
        return NULL;
    double eps = 1e-4 * (f->value_max - f->value_min) + 1e-6 * fabs(iso);
    for (int a = 0; a < 3; a++)
        lo[a] = INT32_MAX, hi[a] = -1;
    size_t i = 0;
    for (int z = 0; z < b->dims[2]; z++)
        for (int y = 0; y < b->dims[1]; y++)
            for (int x = 0; x < b->dims[0]; x++, i++) {
                mask[i] = b->minmax[2 * i] < iso + eps && b->minmax[2 * i + 1] >= iso - eps;
                if (!mask[i])
                    continue;
                int c[3] = {x, y, z};
                for (int a = 0; a < 3; a++) {
                    int v0 = SL_VOLUME_BRICK * c[a], v1 = v0 + SL_VOLUME_BRICK;
                    v1 = v1 < f->dims[a] - 1 ? v1 : f->dims[a] - 1;
                    lo[a] = v0 < lo[a] ? v0 : lo[a];
                    hi[a] = v1 > hi[a] ? v1 : hi[a];
                }
            }
    return mask;
}

/* The lattice tiles (4^3 points, packed x + tx (y + ty z)) whose voxels
 * touch a marked brick: tile T spans lattice points 4T .. 4T + 4 (its edges
 * end one point further), so the voxels floor(4 s T) .. floor(4 s (T + 1)) + 1
 * per axis; every brick overlapping that range is looked at. Writes the list
 * (malloc'd) into *out and its length into *count; -1 when out of memory. */
static int lattice_tiles(const pt_field *f, const uint8_t *mask, double step, const int tdims[3], uint32_t **out,
                         uint32_t *count)
{
    const sl_volume_bricks *b = f->bricks;
    size_t total = (size_t)tdims[0] * (size_t)tdims[1] * (size_t)tdims[2];
    uint32_t *list = malloc((total ? total : 1) * sizeof *list);
    int *range = malloc(((size_t)tdims[0] + tdims[1] + tdims[2]) * 2 * sizeof *range);
    if (!list || !range) {
        free(list);
        free(range);
        return -1;
    }
    /* Brick ranges per axis and tile: range[2 (off[a] + t)] .. [+1]. */
    int off[3] = {0, tdims[0], tdims[0] + tdims[1]};
    for (int a = 0; a < 3; a++)
        for (int t = 0; t < tdims[a]; t++) {
            int v0 = (int)floor(4.0 * step * t), v1 = (int)floor(4.0 * step * (t + 1)) + 1;
            v1 = v1 < f->dims[a] - 1 ? v1 : f->dims[a] - 1;
            int b0 = v0 / SL_VOLUME_BRICK, b1 = v1 / SL_VOLUME_BRICK;
            range[2 * (off[a] + t)] = b0 < b->dims[a] ? b0 : b->dims[a] - 1;
            range[2 * (off[a] + t) + 1] = b1 < b->dims[a] ? b1 : b->dims[a] - 1;
        }
    uint32_t k = 0, t = 0;
    for (int tz = 0; tz < tdims[2]; tz++)
        for (int ty = 0; ty < tdims[1]; ty++)
            for (int tx = 0; tx < tdims[0]; tx++, t++) {
                const int *rx = range + 2 * (off[0] + tx), *ry = range + 2 * (off[1] + ty),
                          *rz = range + 2 * (off[2] + tz);
                int hit = 0;
                for (int bz = rz[0]; bz <= rz[1] && !hit; bz++)
                    for (int by = ry[0]; by <= ry[1] && !hit; by++)
                        for (int bx = rx[0]; bx <= rx[1] && !hit; bx++)
                            hit = mask[((size_t)bz * b->dims[1] + by) * b->dims[0] + bx];
                if (hit)
                    list[k++] = t;
            }
    free(range);
    *out = list;
    *count = k;
    return 0;
}

/* Algorithm 1: count, allocate, emit (into particles[1], keys = edge ids,
 * values = slots). Returns the seed count in *count. With a brick mask
 * (NULL: the whole lattice) only the tiles that may hold a crossing are
 * dispatched: the same crossings, found at the same points. */
static sl_status place(pt_system *sys, const pt_field *f, const pt_system_desc *d, const uint8_t *mask,
                       build_buffers *b, pt_set_stats *stats, uint32_t *count, unsigned *id_bits, sl_err *err)
{
    int ldims[3];
    uint64_t total = 1;
    for (int a = 0; a < 3; a++) {
        ldims[a] = (int)floor((f->dims[a] - 1) / d->lattice_step + 1e-9) + 1;
        total *= (uint64_t)ldims[a];
    }
    if (total * 3 >= UINT32_MAX)
        return sl_err_set(err, SL_ERR_LIMIT,
                          "a lattice of %d x %d x %d points at spacing %g is above the 32-bit edge ids; raise spacing",
                          ldims[0], ldims[1], ldims[2], d->lattice_step);
    *id_bits = bits_for(total * 3 - 1);
    double gmin = 1e-6 * (f->value_max - f->value_min) / f->min_spacing;
    double sigma = d->sigma;
    int tdims[3];
    for (int a = 0; a < 3; a++)
        tdims[a] = (ldims[a] + 3) / 4;
    stats->tiles_total = (uint32_t)((uint64_t)tdims[0] * tdims[1] * tdims[2]);
    stats->tiles = stats->tiles_total;
    if (mask) {
        uint32_t *list = NULL;
        if (lattice_tiles(f, mask, d->lattice_step, tdims, &list, &stats->tiles) != 0)
            return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the lattice tiles");
        b->tiles = ssbo((size_t)stats->tiles * 4);
        if (stats->tiles)
            glNamedBufferSubData(b->tiles, 0, (GLsizeiptr)stats->tiles * 4, list);
        free(list);
    }
    b->counter = ssbo(sizeof(GLuint));
    for (int emit = 0; emit < 2; emit++) {
        GLuint p = sys->place[emit];
        glUseProgram(p);
        set_field_uniforms(p, f);
        u1f(p, "u_iso", d->iso);
        u1f(p, "u_lattice_step", d->lattice_step);
        glUniform3i(glGetUniformLocation(p, "u_lattice_dims"), ldims[0], ldims[1], ldims[2]);
        u1ui(p, "u_total", (GLuint)total);
        u1f(p, "u_gmin", gmin);
        u1f(p, "u_lambda0", sigma * sigma / 16.0);
        glClearNamedBufferData(b->counter, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, b->counter);
        if (emit) {
            u1ui(p, "u_capacity", *count);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, b->particles[1]);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, b->keys);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, b->values);
        }
        GLint first_loc = glGetUniformLocation(p, "u_first");
        glUniform1i(glGetUniformLocation(p, "u_tiled"), mask != NULL);
        glUniform3ui(glGetUniformLocation(p, "u_tile_dims"), (GLuint)tdims[0], (GLuint)tdims[1], (GLuint)tdims[2]);
        if (mask) {
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, b->tiles);
            for (uint32_t first = 0; first < stats->tiles; first += PT_MAX_GROUPS) {
                uint32_t n = stats->tiles - first < PT_MAX_GROUPS ? stats->tiles - first : PT_MAX_GROUPS;
                glUniform1ui(first_loc, first);
                glDispatchCompute(n, 1, 1);
            }
        } else {
            uint64_t per_chunk = (uint64_t)PT_MAX_GROUPS * 64;
            for (uint64_t first = 0; first < total; first += per_chunk) {
                uint64_t n = total - first < per_chunk ? total - first : per_chunk;
                glUniform1ui(first_loc, (GLuint)first);
                glDispatchCompute((GLuint)((n + 63) / 64), 1, 1);
            }
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        GLuint n = 0;
        glGetNamedBufferSubData(b->counter, 0, sizeof n, &n);
        if (!emit) {
            if (n > d->max_particles)
                return sl_err_set(err, SL_ERR_LIMIT,
                                  "isovalue %g has %u particles at spacing %g, above max_particles %u; raise spacing "
                                  "or max_particles",
                                  d->iso, n, d->lattice_step, d->max_particles);
            *count = n;
            if (n == 0)
                return SL_OK;
            b->particles[0] = ssbo((size_t)n * 32);
            b->particles[1] = ssbo((size_t)n * 32);
            b->keys = ssbo((size_t)n * 4);
            b->values = ssbo((size_t)n * 4);
            sl_status st = sl_gl_check_errors("allocating particles", err);
            if (st != SL_OK)
                return st;
        } else if (n != *count) {
            return sl_err_set(err, SL_ERR_GPU, "the emit pass found %u crossings, the count pass %u", n, *count);
        }
    }
    return SL_OK;
}

static void run_keys(pt_system *sys, const pt_set *s, GLuint src, build_buffers *b, uint32_t n)
{
    glUseProgram(sys->keys);
    set_bin_uniforms(sys->keys, s);
    u1ui(sys->keys, "u_count", n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, src);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, b->keys);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, b->values);
    dispatch_1d(n, 256);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

static void run_gather(pt_system *sys, GLuint src, GLuint dst, build_buffers *b, uint32_t n)
{
    glUseProgram(sys->gather);
    u1ui(sys->gather, "u_count", n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, src);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, b->values);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, dst);
    dispatch_1d(n, 256);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

/* Keys of src, sort, gather into dst, bin table: one "bin order" of the
 * particles. Adds the phase times to st. */
static sl_status bin_order(pt_system *sys, const pt_system_desc *d, pt_set *s, build_buffers *b, GLuint src,
                           GLuint dst, uint32_t n, sl_err *err)
{
    double t0 = sl_clock_ms();
    run_keys(sys, s, src, b, n);
    sl_status st = pt_sort_pairs(sys->sorter, d->sort, b->keys, b->values, n, bits_for(s->bins), err);
    if (st != SL_OK)
        return st;
    s->stats.sort_ms += phase_end(t0);
    t0 = sl_clock_ms();
    run_gather(sys, src, dst, b, n);
    s->stats.gather_ms += phase_end(t0);
    t0 = sl_clock_ms();
    if ((st = pt_bin_table(sys->sorter, d->lookup, b->keys, n, s->bins, s->table, err)) != SL_OK)
        return st;
    s->stats.lookup_ms += phase_end(t0);
    return SL_OK;
}

static uint32_t alive_count(const pt_set *s)
{
    GLuint alive = 0;
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(s->table, (GLintptr)s->bins * 4, 4, &alive);
    return alive;
}

/* One energy step from src (bin order) into dst; returns E of src's
 * configuration, summed in double over the work groups. */
static double energy_step(pt_system *sys, const pt_field *f, const pt_system_desc *d, pt_set *s, build_buffers *b,
                          GLuint src, GLuint dst, uint32_t n, float *group_sums)
{
    GLuint p = sys->energy;
    glUseProgram(p);
    set_field_uniforms(p, f);
    set_bin_uniforms(p, s);
    u1ui(p, "u_count", n);
    u1f(p, "u_iso", d->iso);
    u1f(p, "u_sigma", d->sigma);
    u1f(p, "u_gmin", 1e-6 * (f->value_max - f->value_min) / f->min_spacing);
    set_box_uniform(p, f);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, src);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, dst);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, s->table);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, b->group_energy);
    uint32_t groups = (n + 255) / 256;
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(b->group_energy, 0, (GLsizeiptr)groups * 4, group_sums);
    double e = 0.0;
    for (uint32_t g = 0; g < groups; g++)
        e += group_sums[g];
    return e;
}

/* Bins: cubes of side >= sigma over the volume box, at most PT_MAX_BINS;
 * with a voxel box lo..hi of the bricks the surface may cross (NULL: none)
 * only the bins within sigma of it are kept (u_bin_origin): the same bin
 * size and alignment, so the bins keep their order (z, y, x) and a particle
 * inside keeps its neighbours in the same order — the same particles, with
 * fewer bins to count and scan. */
static void choose_bins(const pt_field *f, double sigma, const int *lo, const int *hi, pt_set *s)
{
    double ext[3], volume = 1.0;
    for (int a = 0; a < 3; a++) {
        ext[a] = fmax((f->dims[a] - 1) * f->spacing[a], 0.0);
        volume *= fmax(ext[a], sigma);
    }
    double size = fmax(sigma, cbrt(volume / (double)PT_MAX_BINS) * 1.0001);
    for (;;) {
        uint64_t bins = 1;
        for (int a = 0; a < 3; a++) {
            s->bin_dims[a] = (int)floor(ext[a] / size) + 1;
            bins *= (uint64_t)s->bin_dims[a];
        }
        if (bins <= PT_MAX_BINS) {
            s->bins = (uint32_t)bins;
            break;
        }
        size *= 1.05;
    }
    s->bin_size = size;
    if (!lo || lo[0] > hi[0])
        return;
    uint64_t bins = 1;
    for (int a = 0; a < 3; a++) {
        int b0 = (int)floor((lo[a] * f->spacing[a] - sigma) / size);
        int b1 = (int)floor((hi[a] * f->spacing[a] + sigma) / size);
        b0 = b0 > 0 ? b0 : 0;
        b1 = b1 < s->bin_dims[a] - 1 ? b1 : s->bin_dims[a] - 1;
        s->bin_origin[a] = b0;
        s->bin_dims[a] = b1 - b0 + 1;
        bins *= (uint64_t)s->bin_dims[a];
    }
    s->bins = (uint32_t)bins;
}

static void nn_statistics(const float *nn, uint32_t n, pt_set_stats *st)
{
    double sum = 0.0, sum2 = 0.0;
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++)
        if (nn[i] >= 0.0f) {
            sum += nn[i];
            sum2 += (double)nn[i] * nn[i];
            k++;
        }
    st->mean_nn = k ? sum / k : 0.0;
    double var = k ? sum2 / k - st->mean_nn * st->mean_nn : 0.0;
    st->nn_cv = k && st->mean_nn > 0.0 ? sqrt(fmax(var, 0.0)) / st->mean_nn : 0.0;
}

sl_status pt_set_build(pt_system *sys, const pt_field *f, const pt_system_desc *d, pt_set *out, sl_err *err)
{
    memset(out, 0, sizeof *out);
    pt_set s = {0};
    build_buffers b = {0};
    float *group_sums = NULL, *nn = NULL;
    sl_status st = SL_OK;
    glBindTextureUnit(0, f->texture);

    double t0 = sl_clock_ms();
    uint8_t *mask = NULL;
    int lo[3], hi[3];
    if (f->bricks && !d->no_skipping && !(mask = iso_bricks(f, d->iso, lo, hi))) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the brick mask");
        goto fail;
    }
    choose_bins(f, d->sigma, mask ? lo : NULL, mask ? hi : NULL, &s);
    uint32_t n = 0;
    unsigned id_bits = 1;
    st = place(sys, f, d, mask, &b, &s.stats, &n, &id_bits, err);
    free(mask);
    if (st != SL_OK)
        goto fail;
    s.stats.placement_ms = phase_end(t0);
    s.stats.seeded = n;
    s.count = n;
    s.table = ssbo(((size_t)s.bins + 1) * 4);
    if (n == 0) {
        s.records = ssbo(0);
        s.bytes = ((size_t)s.bins + 1) * 4;
        *out = s;
        free_build_buffers(&b);
        return sl_gl_check_errors("particles: an empty set", err);
    }
    b.group_energy = ssbo(((size_t)n + 255) / 256 * 4);
    b.nearest = ssbo((size_t)n * 4);
    group_sums = malloc(((size_t)n + 255) / 256 * sizeof *group_sums);
    nn = malloc((size_t)n * sizeof *nn);
    if (!group_sums || !nn) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for %u particles", n);
        goto fail;
    }
    if ((st = sl_gl_check_errors("allocating the bin table", err)) != SL_OK)
        goto fail;

    /* The deterministic order: by edge id (emitted into particles[1]). */
    t0 = sl_clock_ms();
    if ((st = pt_sort_pairs(sys->sorter, d->sort, b.keys, b.values, n, id_bits, err)) != SL_OK)
        goto fail;
    run_gather(sys, b.particles[1], b.particles[0], &b, n);
    s.stats.id_sort_ms = phase_end(t0);

    /* particles[0] holds the current configuration between steps. */
    double previous = 0.0;
    uint32_t alive_before = n;
    double loop_t0 = sl_clock_ms();
    GLuint p = 0;
    for (int step = 1; step <= d->max_steps; step++) {
        if ((st = bin_order(sys, d, &s, &b, b.particles[0], b.particles[1], n, err)) != SL_OK)
            goto fail;
        uint32_t alive = alive_count(&s);
        t0 = sl_clock_ms();
        double e = energy_step(sys, f, d, &s, &b, b.particles[1], b.particles[0], n, group_sums);
        s.stats.energy_ms += phase_end(t0);
        s.stats.steps = step;
        if (step == 1)
            s.stats.first_energy = e;
        s.stats.final_energy = e;
        int died = alive != alive_before;
        alive_before = alive;
        if (e == 0.0)
            break;
        if (step > 1 && !died && fabs(e - previous) <= d->energy_tol * previous)
            break;
        previous = e;
    }
    if (s.stats.steps)
        s.stats.ms_per_step = (sl_clock_ms() - loop_t0) / s.stats.steps;

    /* Settle onto the surface; drop the particles that lost it. */
    t0 = sl_clock_ms();
    p = sys->settle;
    glUseProgram(p);
    set_field_uniforms(p, f);
    set_box_uniform(p, f);
    u1ui(p, "u_count", n);
    u1f(p, "u_iso", d->iso);
    u1f(p, "u_sigma", d->sigma);
    u1f(p, "u_max_offset", PT_MAX_OFFSET_VOXELS * f->min_spacing);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, b.particles[0]);
    dispatch_1d(n, 256);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    s.stats.settle_ms = phase_end(t0);

    /* The final order, the records and the nearest neighbours. */
    if ((st = bin_order(sys, d, &s, &b, b.particles[0], b.particles[1], n, err)) != SL_OK)
        goto fail;
    s.stats.alive = alive_count(&s);
    s.stats.dropped = n - s.stats.alive;
    t0 = sl_clock_ms();
    s.records = ssbo((size_t)n * sizeof(pt_record));
    p = sys->final;
    glUseProgram(p);
    set_field_uniforms(p, f);
    set_bin_uniforms(p, &s);
    u1ui(p, "u_count", n);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, b.particles[1]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, s.table);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, s.records);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, b.nearest);
    dispatch_1d(n, 64);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(b.nearest, 0, (GLsizeiptr)s.stats.alive * 4, nn);
    nn_statistics(nn, s.stats.alive, &s.stats);
    s.stats.final_ms = phase_end(t0);
    if ((st = sl_gl_check_errors("building particles", err)) != SL_OK)
        goto fail;
    s.bytes = (size_t)n * sizeof(pt_record) + ((size_t)s.bins + 1) * 4;
    free_build_buffers(&b);
    free(group_sums);
    free(nn);
    *out = s;
    return SL_OK;
fail:
    free_build_buffers(&b);
    free(group_sums);
    free(nn);
    pt_set_release(&s);
    return st;
}
