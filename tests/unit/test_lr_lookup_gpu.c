/* test_lr_lookup_gpu.c — lr_find_element of renderer/lrspline/lr_lookup.glsl
 * (through lr_lookup_probe.comp.glsl on llvmpipe) against
 * sl_lr_find_element_linear on the same float points widened to double.
 *
 * Volumes as in test_lr_lookup (tests/support/lr_test_volumes.h), with
 * domain bounds and knots that are not floats; 2*10^5 float probes each
 * (uniform, on/beside element faces, edges, corners and the domain's, just
 * outside; each coordinate also moved one float ulp down or up) for every
 * applicable structure, forest sizes 1, 8, 32, the kind compiled in by
 * #define and chosen by the uniform, and with the heads read from the 3D
 * texture (LR_LOOKUP_HEADS_TEXTURE). Every answer must equal the reference
 * exactly (the planes' round-up makes float queries exact). Render thread =
 * main thread.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../support/lr_test_volumes.h"
#include "gpu/sl_gpu.h"
#include "lrspline/sl_lr_lookup.h"
#include "sl_test.h"

#define PROBES 200000

static GLuint programs[10]; /* [0]: kind by uniform; [k]: LR_LOOKUP_KIND k; [5 + k]: and heads texture */

static int program_for(int slot, sl_err *err)
{
    if (programs[slot])
        return 1;
    char defines[128];
    snprintf(defines, sizeof defines, "%s%s", slot ? sl_lr_lookup_glsl_define((sl_lr_lookup_kind)(slot % 5)) : "",
             slot >= 5 ? "#define LR_LOOKUP_HEADS_TEXTURE\n" : "");
    sl_program_desc desc = {.compute = "lrspline/lr_lookup_probe.comp.glsl", .defines = defines,
                            .label = "lr_lookup_probe"};
    return sl_gl_program_create(&desc, &programs[slot], err) == SL_OK;
}

static void run_gpu(GLuint program, const sl_lr_lookup_gpu *g, GLuint points, GLuint results, size_t n)
{
    sl_lr_lookup_gpu_bind(g, program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, points);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, results);
    glUniform1ui(glGetUniformLocation(program, "u_count"), (GLuint)n);
    sl_gpu_dispatch_chunked(glGetUniformLocation(program, "u_group_base"), (n + 63) / 64, 0);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
}

static void check_volume(const char *name, const sl_lr_volume *lr, int texture, int octree)
{
    float *pts = malloc(PROBES * 3 * sizeof *pts);
    long *ref = malloc(PROBES * sizeof *ref);
    int32_t *got = malloc(PROBES * sizeof *got);
    if (!pts || !ref || !got) {
        SL_CHECK(!"out of memory");
        free(pts), free(ref), free(got);
        return;
    }
    lrt_rng r = {0xC0FFEEull + lr->element_count};
    size_t outside = 0;
    for (size_t i = 0; i < PROBES; i++) {
        lrt_probe_float(lr, &r, &pts[3 * i]);
        double p[3] = {pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]};
        ref[i] = sl_lr_find_element_linear(lr, p);
        outside += ref[i] < 0;
    }
    SL_CHECK_MSG(outside > PROBES / 50 && outside < PROBES / 2, "%s: %zu outside", name, outside);
    GLuint bufs[2];
    glCreateBuffers(2, bufs);
    glNamedBufferStorage(bufs[0], PROBES * 3 * sizeof(float), pts, 0);
    glNamedBufferStorage(bufs[1], PROBES * sizeof(int32_t), NULL, GL_MAP_READ_BIT);
    static const struct { sl_lr_lookup_kind kind; int forest; } cases[] = {
        {SL_LR_LOOKUP_TEXTURE, 0}, {SL_LR_LOOKUP_OCTREE, 0}, {SL_LR_LOOKUP_KDTREE, 0},
        {SL_LR_LOOKUP_KDFOREST, 1}, {SL_LR_LOOKUP_KDFOREST, 8}, {SL_LR_LOOKUP_KDFOREST, 32}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        sl_err err;
        sl_lr_lookup lk;
        sl_status st = sl_lr_lookup_init(&lk, lr, cases[c].kind, cases[c].forest, &err);
        int expect = cases[c].kind == SL_LR_LOOKUP_TEXTURE ? texture : cases[c].kind == SL_LR_LOOKUP_OCTREE ? octree : 1;
        SL_CHECK_MSG((st == SL_OK) == expect, "%s %s: %s", name, sl_lr_lookup_kind_name(cases[c].kind),
                     st ? err.message : "built");
        if (st != SL_OK)
            continue;
        sl_lr_lookup_gpu g;
        st = sl_lr_lookup_gpu_init(&g, &lk, 1, &err);
        SL_CHECK_MSG(st == SL_OK, "%s", err.message);
        for (int slot = 0; slot < 3 && st == SL_OK; slot++) {
            if (slot == 2 && lk.kind == SL_LR_LOOKUP_OCTREE)
                break;
            int ps = slot == 0 ? 0 : slot == 1 ? (int)lk.kind : 5 + (int)lk.kind;
            if (!program_for(ps, &err)) {
                SL_CHECK_MSG(0, "%s", err.message);
                break;
            }
            run_gpu(programs[ps], &g, bufs[0], bufs[1], PROBES);
            glGetNamedBufferSubData(bufs[1], 0, PROBES * sizeof(int32_t), got);
            size_t bad = 0, first = 0, cpu_bad = 0;
            for (size_t i = 0; i < PROBES; i++) {
                if (got[i] != ref[i] && bad++ == 0)
                    first = i;
                double p[3] = {pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]};
                cpu_bad += sl_lr_lookup_find(&lk, p) != ref[i];
            }
            SL_CHECK_MSG(bad == 0, "%s %s/%d (%s): %zu of %d GPU answers differ; first (%.9g %.9g %.9g) gives %d, "
                         "reference %ld", name, sl_lr_lookup_kind_name(lk.kind), cases[c].forest,
                         slot == 2 ? "heads3d" : slot ? "#define" : "uniform", bad, PROBES, pts[3 * first], pts[3 * first + 1],
                         pts[3 * first + 2], got[first], ref[first]);
            SL_CHECK(cpu_bad == 0);
            printf("  %-10s %-8s n=%-3d %-8s GPU %zu bytes: %zu/%d differ\n", name, sl_lr_lookup_kind_name(lk.kind),
                   cases[c].forest, slot == 2 ? "heads3d" : slot ? "#define" : "uniform", g.bytes, bad, PROBES);
        }
        SL_CHECK(sl_gl_check_errors("lr look-up probe", &err) == SL_OK);
        sl_lr_lookup_gpu_deinit(&g);
        sl_lr_lookup_deinit(&lk);
    }
    glDeleteBuffers(2, bufs);
    free(pts);
    free(ref);
    free(got);
}

int main(void)
{
    sl_gpu *gpu = NULL;
    sl_err err;
    sl_gpu_desc desc = {.quiet = 1};
    if (sl_gpu_create(&desc, &gpu, &err) != SL_OK) {
        fprintf(stderr, "test_lr_lookup_gpu: %s\n", err.message);
        return 1;
    }
    sl_lr_volume lr;
    double u0[] = {0.1, 0.35, 0.6, 0.85, 1.1}, u1[] = {-2, -1, 0, 1, 2}, u2[] = {3, 3.5, 4, 4.5, 5};
    const double *bu[3] = {u0, u1, u2};
    int mu[3] = {5, 5, 5};
    SL_CHECK(lrt_tensor(&lr, 3, bu, mu, &err) == SL_OK);
    check_volume("uniform", &lr, 1, 1);
    sl_lr_free(&lr);
    double n0[] = {0, 0.1, 1.0 / 3.0, 0.37, 0.9, 1.0}, n1[] = {0, M_PI / 10, 1}, n2[] = {0, 0.5, 0.51, 2};
    const double *bn[3] = {n0, n1, n2};
    int mn[3] = {6, 3, 4};
    SL_CHECK(lrt_tensor(&lr, 2, bn, mn, &err) == SL_OK);
    check_volume("nonuniform", &lr, 0, 0);
    sl_lr_free(&lr);
    double lo[3] = {0.1, -0.3, 2.0}, hi[3] = {1.7, 0.9, 2.5};
    lrt_refine rf = {.point = {0.6123, 0.2, 2.3}, .point_level = 10, .centre = {0.9, 0.3, 2.25}, .radius = 0.35,
                     .surface_level = 3, .t = 0.5};
    SL_CHECK(lrt_refined(&lr, lo, hi, 4, &rf, &err) == SL_OK);
    check_volume("refined", &lr, 0, 1);
    sl_lr_free(&lr);
    rf.t = 0.4;
    rf.point_level = 8;
    SL_CHECK(lrt_refined(&lr, lo, hi, 3, &rf, &err) == SL_OK);
    check_volume("nondyadic", &lr, 0, 0);
    sl_lr_free(&lr);
    for (int i = 0; i < 10; i++)
        if (programs[i])
            glDeleteProgram(programs[i]);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
