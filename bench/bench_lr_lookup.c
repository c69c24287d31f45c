/* bench-lr-lookup — element look-up of LR-spline volumes (paper 003, Fig. 4-8
 * tables): per structure and forest size, the tree statistics (trees, nodes,
 * depth min/mean/max/variance over the trees, CPU and GPU bytes, build ms)
 * and the time per look-up on the CPU (one thread, ns/point) and on the GPU
 * (lr_lookup_probe.comp.glsl, wall time of the dispatch to glFinish, the
 * best of --repeat runs, ns/point), for two point sets: uniform in the domain
 * (like rays' samples) and element-weighted (a random element, a uniform
 * point in it: the refined regions dominate, like adaptive sampling).
 * Volumes: `uniform` (tensor product, 32^3 quadratic elements: every
 * structure applies) and `refined` (tests/support/lr_test_volumes.h: a 4^3
 * grid split in 8 at the middle near a point down to 1:2^10 and near a
 * sphere down to 1:2^5; dyadic, so the octree applies, the texture does not;
 * its sphere elements line up with 128^3 blocks) and `refined-nondyadic`
 * (a 3^3 grid split at 0.4 of each side near the point to level 10 and the
 * sphere to level 4: only the k-d structures apply, no block alignment).
 * The GPU answers are compared with the CPU ones (column "GPU=CPU").
 * Also the GPU variants: kind by #define or by uniform, heads from the SSBO
 * or from a GL_R32UI 3D texture (texture and default forest).
 * Usage: bench-lr-lookup [--points N] [--repeat R] [--forests 1,8,32,64,128]
 * Main thread = render thread. Prints Markdown; checks nothing else.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../tests/support/lr_test_volumes.h"
#include "gpu/sl_gpu.h"
#include "lrspline/sl_lr_lookup.h"

static double now_ms(void)
{
    struct timespec t;
    timespec_get(&t, TIME_UTC);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

typedef struct points {
    size_t n;
    float *f;          /* xyz */
    double (*d)[3];    /* the same, widened */
} points;

static int points_make(points *ps, const sl_lr_volume *lr, size_t n, int weighted, uint64_t seed)
{
    ps->n = n;
    ps->f = malloc(n * 3 * sizeof *ps->f);
    ps->d = malloc(n * sizeof *ps->d);
    if (!ps->f || !ps->d)
        return 0;
    lrt_rng r = {seed};
    for (size_t i = 0; i < n; i++) {
        const sl_lr_element *e = &lr->elements[lrt_next(&r) % lr->element_count];
        for (int d = 0; d < 3; d++) {
            double lo = weighted ? e->lo[d] : lr->domain_lo[d], hi = weighted ? e->hi[d] : lr->domain_hi[d];
            float f = (float)(lo + (hi - lo) * lrt_unit(&r));
            ps->f[3 * i + d] = f;
            ps->d[i][d] = f;
        }
    }
    return 1;
}

static void points_free(points *ps)
{
    free(ps->f);
    free(ps->d);
}

static GLuint programs[10]; /* [0]: kind by uniform; [k]: LR_LOOKUP_KIND k; [5 + k]: and heads texture */

static GLuint program_for(int slot)
{
    if (!programs[slot]) {
        sl_err err;
        char defines[128];
        snprintf(defines, sizeof defines, "%s%s", slot ? sl_lr_lookup_glsl_define((sl_lr_lookup_kind)(slot % 5)) : "",
                 slot >= 5 ? "#define LR_LOOKUP_HEADS_TEXTURE\n" : "");
        sl_program_desc desc = {.compute = "lrspline/lr_lookup_probe.comp.glsl", .defines = defines,
                                .label = "lr_lookup_probe"};
        if (sl_gl_program_create(&desc, &programs[slot], &err) != SL_OK) {
            fprintf(stderr, "bench-lr-lookup: %s\n", err.message);
            return 0;
        }
    }
    return programs[slot];
}

/* Best wall ns per point of `repeat` dispatches; mismatches against cpu[]. */
static double gpu_time(const sl_lr_lookup_gpu *g, int slot, const points *ps, const long *cpu, int repeat,
                       size_t *mismatch)
{
    GLuint program = program_for(slot);
    if (!program)
        return NAN;
    GLuint bufs[2];
    glCreateBuffers(2, bufs);
    glNamedBufferStorage(bufs[0], (GLsizeiptr)(ps->n * 3 * sizeof(float)), ps->f, 0);
    glNamedBufferStorage(bufs[1], (GLsizeiptr)(ps->n * sizeof(int32_t)), NULL, 0);
    sl_lr_lookup_gpu_bind(g, program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bufs[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bufs[1]);
    glUniform1ui(glGetUniformLocation(program, "u_count"), (GLuint)ps->n);
    GLint base = glGetUniformLocation(program, "u_group_base");
    glFinish();
    double best = INFINITY;
    for (int r = 0; r < repeat; r++) {
        double t0 = now_ms();
        sl_gpu_dispatch_chunked(base, (ps->n + 63) / 64, 0);
        glFinish();
        double t = now_ms() - t0;
        best = t < best ? t : best;
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    int32_t *got = malloc(ps->n * sizeof *got);
    *mismatch = got ? 0 : ps->n;
    if (got) {
        glGetNamedBufferSubData(bufs[1], 0, (GLsizeiptr)(ps->n * sizeof *got), got);
        for (size_t i = 0; i < ps->n; i++)
            *mismatch += got[i] != cpu[i];
        free(got);
    }
    glDeleteBuffers(2, bufs);
    return best * 1e6 / (double)ps->n;
}

/* Best of `repeat` passes, ns per point. */
static double cpu_time(const sl_lr_lookup *lk, const points *ps, long *out, int repeat)
{
    double best = INFINITY;
    for (int r = 0; r < repeat; r++) {
        double t0 = now_ms();
        for (size_t i = 0; i < ps->n; i++)
            out[i] = sl_lr_lookup_find(lk, ps->d[i]);
        double t = now_ms() - t0;
        best = t < best ? t : best;
    }
    return best * 1e6 / (double)ps->n;
}

typedef struct options {
    size_t points;
    int repeat;
    int forests[8], forest_count;
} options;

static void bench_volume(const char *name, const sl_lr_volume *lr, const options *o)
{
    points ps[2];
    long *cpu = malloc(o->points * sizeof *cpu);
    if (!cpu || !points_make(&ps[0], lr, o->points, 0, 1) || !points_make(&ps[1], lr, o->points, 1, 2)) {
        fprintf(stderr, "bench-lr-lookup: out of memory\n");
        exit(1);
    }
    printf("### `%s`: %zu elements, level ratio %.0f, %zu points per set\n\n", name, lr->element_count,
           sl_lr_level_ratio(lr), o->points);
    printf("CPU ns and GPU ns: best of %d passes.\n\n", o->repeat);
    printf("| structure | trees | nodes | direct blocks | depth min | depth mean | depth max | depth var | CPU KiB | "
           "GPU KiB | build ms | CPU ns uniform | CPU ns weighted | GPU ns uniform | GPU ns weighted | GPU=CPU |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    typedef struct { sl_lr_lookup_kind kind; int forest; } run;
    run runs[16];
    int nr = 0;
    runs[nr++] = (run){SL_LR_LOOKUP_TEXTURE, 0};
    runs[nr++] = (run){SL_LR_LOOKUP_OCTREE, 0};
    runs[nr++] = (run){SL_LR_LOOKUP_KDTREE, 0};
    for (int f = 0; f < o->forest_count; f++)
        runs[nr++] = (run){SL_LR_LOOKUP_KDFOREST, o->forests[f]};
    for (int k = 0; k < nr; k++) {
        sl_err err;
        sl_lr_lookup lk;
        char label[32];
        if (runs[k].kind == SL_LR_LOOKUP_KDFOREST)
            snprintf(label, sizeof label, "kdforest %d^3", runs[k].forest);
        else
            snprintf(label, sizeof label, "%s", sl_lr_lookup_kind_name(runs[k].kind));
        if (sl_lr_lookup_init(&lk, lr, runs[k].kind, runs[k].forest, &err) != SL_OK) {
            printf("| %s | refused: %s |||||||||||||||\n", label, err.message);
            continue;
        }
        sl_lr_lookup_gpu g;
        if (sl_lr_lookup_gpu_init(&g, &lk, 1, &err) != SL_OK) {
            printf("| %s | GPU upload failed: %s |||||||||||||||\n", label, err.message);
            sl_lr_lookup_deinit(&lk);
            continue;
        }
        double cns[2], gns[2];
        size_t mism = 0;
        for (int s = 0; s < 2; s++) {
            cns[s] = cpu_time(&lk, &ps[s], cpu, o->repeat);
            size_t m = 0;
            gns[s] = gpu_time(&g, (int)lk.kind, &ps[s], cpu, o->repeat, &m);
            mism += m;
        }
        const sl_lr_lookup_stats *st = &lk.stats;
        printf("| %s | %zu | %zu | %zu | %d | %.3g | %d | %.3g | %.0f | %.0f | %.1f | %.1f | %.1f | %.1f | %.1f | %s |\n",
               label, st->trees, st->nodes, st->direct_blocks, st->depth_min, st->depth_mean, st->depth_max,
               st->depth_var, (double)st->bytes / 1024.0, (double)g.bytes / 1024.0, st->build_ms, cns[0], cns[1],
               gns[0], gns[1], mism ? "NO" : "yes");
        if (mism)
            fprintf(stderr, "bench-lr-lookup: %s %s: %zu GPU answers differ from the CPU\n", name, label, mism);
        sl_lr_lookup_gpu_deinit(&g);
        sl_lr_lookup_deinit(&lk);
    }
    printf("\n");
    /* GPU variants (weighted points): kind by uniform or #define, heads
     * from the SSBO or the 3D texture. */
    printf("GPU variants, weighted points, ns per point (best of %d):\n\n", o->repeat);
    printf("| structure | kind by uniform, heads SSBO | `#define LR_LOOKUP_KIND`, heads SSBO | `#define`, heads 3D texture |\n");
    printf("|---|---:|---:|---:|\n");
    sl_lr_lookup_kind vk[2] = {SL_LR_LOOKUP_TEXTURE, SL_LR_LOOKUP_KDFOREST};
    for (int v = 0; v < 2; v++) {
        sl_err err;
        sl_lr_lookup lk;
        if (sl_lr_lookup_init(&lk, lr, vk[v], 0, &err) != SL_OK)
            continue;
        sl_lr_lookup_gpu g;
        if (sl_lr_lookup_gpu_init(&g, &lk, 1, &err) == SL_OK) {
            cpu_time(&lk, &ps[1], cpu, 1);
            size_t m[3] = {0, 0, 0};
            double t0 = gpu_time(&g, 0, &ps[1], cpu, o->repeat, &m[0]);
            double t1 = gpu_time(&g, (int)lk.kind, &ps[1], cpu, o->repeat, &m[1]);
            double t2 = g.heads_texture ? gpu_time(&g, 5 + (int)lk.kind, &ps[1], cpu, o->repeat, &m[2]) : NAN;
            char label[32];
            snprintf(label, sizeof label, vk[v] == SL_LR_LOOKUP_KDFOREST ? "kdforest %d^3" : "texture",
                     SL_LR_FOREST_DEFAULT_AXIS);
            printf("| %s | %.1f | %.1f | %.1f |%s\n", label, t0, t1, t2, m[0] + m[1] + m[2] ? " MISMATCHES" : "");
            sl_lr_lookup_gpu_deinit(&g);
        }
        sl_lr_lookup_deinit(&lk);
    }
    printf("\n");
    points_free(&ps[0]);
    points_free(&ps[1]);
    free(cpu);
}

int main(int argc, char **argv)
{
    options o = {.points = 1000000, .repeat = 3, .forests = {1, 8, 16, 32, 64, 128}, .forest_count = 6};
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--points") == 0 && i + 1 < argc) {
            long v = strtol(argv[++i], NULL, 10);
            if (v < 1000 || v > 20000000) {
                fprintf(stderr, "bench-lr-lookup: --points must be 1000..20000000\n");
                return 2;
            }
            o.points = (size_t)v;
        } else if (strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            o.repeat = atoi(argv[++i]);
            if (o.repeat < 1 || o.repeat > 100) {
                fprintf(stderr, "bench-lr-lookup: --repeat must be 1..100\n");
                return 2;
            }
        } else if (strcmp(argv[i], "--forests") == 0 && i + 1 < argc) {
            o.forest_count = 0;
            for (char *s = argv[++i]; *s && o.forest_count < 8;) {
                long v = strtol(s, &s, 10);
                if (v < 1 || v > 128) {
                    fprintf(stderr, "bench-lr-lookup: forest sizes must be 1..128\n");
                    return 2;
                }
                o.forests[o.forest_count++] = (int)v;
                if (*s == ',')
                    s++;
            }
        } else {
            fprintf(stderr, "usage: bench-lr-lookup [--points N] [--repeat R] [--forests 1,8,32,64,128]\n");
            return 2;
        }
    }
    sl_gpu *gpu = NULL;
    sl_err err;
    sl_gpu_desc desc = {.quiet = 1};
    if (sl_gpu_create(&desc, &gpu, &err) != SL_OK) {
        fprintf(stderr, "bench-lr-lookup: %s\n", err.message);
        return 1;
    }
    printf("# bench-lr-lookup — %s\n\n", sl_gpu_renderer(gpu));
    printf("Time per look-up (ns/point): CPU one thread, double points; GPU the probe compute shader, wall time to "
           "glFinish, best of %d. Depth statistics over the trees (forest blocks; a block holding one element "
           "directly has depth 0), as in the paper's Fig. 4-8 tables.\n\n", o.repeat);
    sl_lr_volume lr;
    double bp[33];
    for (int i = 0; i <= 32; i++)
        bp[i] = i / 32.0;
    const double *b3[3] = {bp, bp, bp};
    int m3[3] = {33, 33, 33};
    if (lrt_tensor(&lr, 3, b3, m3, &err) != SL_OK) {
        fprintf(stderr, "bench-lr-lookup: %s\n", err.message);
        return 1;
    }
    bench_volume("uniform", &lr, &o);
    sl_lr_free(&lr);
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    lrt_refine rf = {.point = {0.6123, 0.2789, 0.4321}, .point_level = 10, .centre = {0.5, 0.5, 0.5}, .radius = 0.3,
                     .surface_level = 5, .t = 0.5};
    if (lrt_refined(&lr, lo, hi, 4, &rf, &err) != SL_OK) {
        fprintf(stderr, "bench-lr-lookup: %s\n", err.message);
        return 1;
    }
    bench_volume("refined", &lr, &o);
    sl_lr_free(&lr);
    /* Not aligned with any block grid: a 3^3 base, splits at 0.4 of the side. */
    rf.t = 0.4;
    rf.surface_level = 4;
    if (lrt_refined(&lr, lo, hi, 3, &rf, &err) != SL_OK) {
        fprintf(stderr, "bench-lr-lookup: %s\n", err.message);
        return 1;
    }
    bench_volume("refined-nondyadic", &lr, &o);
    sl_lr_free(&lr);
    for (int i = 0; i < 10; i++)
        if (programs[i])
            glDeleteProgram(programs[i]);
    sl_gpu_destroy(gpu);
    return 0;
}
