/* test_lr_gpu.c — GPU evaluation of LR-spline Bézier blocks
 * (renderer/lrspline/lr_bezier_gpu.c, lr_bezier.glsl, lr_lookup.glsl (the auto look-up)
 * through lr_probe.comp.glsl) against the CPU double reference sl_lr_eval
 * (lr_eval.c, from the LR basis, no Bézier form) on llvmpipe.
 *
 * 10^4 points per model: random inside, on knot planes (element faces),
 * on the domain's upper faces and corners, and a few outside (the look-up
 * must say -1). Knots are dyadic so they are exact in float and the element
 * the GPU's rule picks must equal sl_lr_find_element_linear's exactly.
 * Bounds (single precision): value within 1e-5 of the value range (the
 * issue's target), gradient within 1e-5 of the largest gradient seen; the double
 * variant: value within 1e-12, gradient within 1e-11 (relative, same
 * scales). Scalar and vector (Jacobian) models, degrees (1,1,1), (2,2,2),
 * (3,3,3), (1,2,3) and the hand-refined LR model. Needs a GL 4.5 context.
 * Single-threaded (render thread).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "lrspline/sl_lr.h"
#include "lrspline/sl_lr_bezier.h"
#include "lr_test_models.h"
#include "sl_test.h"

enum { NPOINTS = 10000, STRIDE = 20 };

static void make_points(const sl_lr_volume *lr, float *pts)
{
    for (int i = 0; i < NPOINTS; i++) {
        float *p = pts + i * 4;
        int kind = i % 8;
        size_t e = (size_t)(urand() * (double)lr->element_count);
        for (int d = 0; d < 3; d++) {
            double lo = lr->domain_lo[d], hi = lr->domain_hi[d];
            double v = lo + (hi - lo) * urand();
            if (kind == 0 || kind == 1) /* knot planes: an element's faces */
                v = (urand() < 0.5) ? lr->elements[e].lo[d] : lr->elements[e].hi[d];
            else if (kind == 2 && d == (i / 8) % 3)
                v = hi; /* the upper face */
            else if (kind == 3 && urand() < 0.7)
                v = urand() < 0.5 ? lo : hi; /* edges and corners */
            else if (kind == 4 && i % 64 == 4 && d == 0)
                v = hi + 0.01 * (hi - lo); /* outside */
            p[d] = (float)v;
        }
        p[3] = 0.0f;
    }
}

static void run_model(sl_lr_volume *lr, const char *name, int want_double)
{
    sl_err err;
    sl_lr_bezier bz;
    sl_status st = sl_lr_bezier_build(lr, SL_LR_LOOKUP_AUTO, 0, &bz, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", name, err.message);
    if (st != SL_OK)
        return;
    sl_lr_bezier_gpu g;
    st = sl_lr_bezier_upload(&bz, want_double, &g, &err);
    SL_CHECK_MSG(st == SL_OK, "%s upload: %s", name, err.message);
    char defines[256];
    sl_lr_bezier_defines(&bz, want_double, defines, sizeof defines);
    GLuint prog = 0;
    if (st == SL_OK) {
        st = sl_gl_program_create(&(sl_program_desc){.compute = "lrspline/lr_probe.comp.glsl",
                                                     .defines = defines, .label = "lr_probe"}, &prog, &err);
        SL_CHECK_MSG(st == SL_OK, "%s program: %s", name, err.message);
    }
    float *pts = malloc(sizeof(float) * 4 * NPOINTS);
    size_t out_size = want_double ? sizeof(double) : sizeof(float);
    void *out = malloc(out_size * STRIDE * NPOINTS);
    if (st == SL_OK && pts && out) {
        make_points(lr, pts);
        GLuint in_buf, out_buf;
        glCreateBuffers(1, &in_buf);
        glNamedBufferStorage(in_buf, (GLsizeiptr)(sizeof(float) * 4 * NPOINTS), pts, 0);
        glCreateBuffers(1, &out_buf);
        glNamedBufferStorage(out_buf, (GLsizeiptr)(out_size * STRIDE * NPOINTS), NULL, GL_DYNAMIC_STORAGE_BIT);
        glUseProgram(prog);
        sl_lr_bezier_set_uniforms(prog, &bz);
        glUniform1i(glGetUniformLocation(prog, "u_count"), NPOINTS);
        sl_lr_bezier_bind(&g, prog);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, in_buf);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, out_buf);
        glDispatchCompute((NPOINTS + 63) / 64, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(out_buf, 0, (GLsizeiptr)(out_size * STRIDE * NPOINTS), out);
        glDeleteBuffers(1, &in_buf);
        glDeleteBuffers(1, &out_buf);
        SL_CHECK_MSG(sl_gl_check_errors("lr probe", &err) == SL_OK, "%s", err.message);

        double range = lr->value_max - lr->value_min;
        if (lr->dim == 3) { /* components: the largest component range */
            range = 0.0;
            for (size_t k = 0; k < bz.element_count * bz.stride; k++)
                range = fmax(range, 2.0 * fabs(bz.coef[k]));
        }
        double gscale = 1e-300, max_ve = 0.0, max_ge = 0.0;
        int wrong_element = 0, outside = 0;
        double *ref_v = malloc(sizeof(double) * 3 * NPOINTS), *ref_g = malloc(sizeof(double) * 9 * NPOINTS);
        long *ref_e = malloc(sizeof(long) * NPOINTS);
        for (int i = 0; i < NPOINTS && ref_v && ref_g && ref_e; i++) {
            double p[3] = {pts[i * 4], pts[i * 4 + 1], pts[i * 4 + 2]};
            ref_e[i] = sl_lr_find_element_linear(lr, p);
            if (ref_e[i] >= 0)
                sl_lr_eval(lr, p, ref_e[i], ref_v + i * 3, ref_g + i * 9, &err);
            for (int k = 0; ref_e[i] >= 0 && k < 3 * lr->dim; k++)
                gscale = fmax(gscale, fabs(ref_g[i * 9 + k]));
        }
        for (int i = 0; i < NPOINTS && ref_v && ref_g && ref_e; i++) {
            double r[STRIDE];
            for (int k = 0; k < STRIDE; k++)
                r[k] = want_double ? ((double *)out)[i * STRIDE + k] : ((float *)out)[i * STRIDE + k];
            if ((long)r[0] != ref_e[i]) {
                wrong_element++;
                continue;
            }
            if (ref_e[i] < 0) {
                outside++;
                continue;
            }
            for (int c = 0; c < lr->dim; c++) {
                double v = lr->dim == 1 ? r[1] : r[5 + c];
                max_ve = fmax(max_ve, fabs(v - ref_v[i * 3 + c]) / range);
                for (int j = 0; j < 3; j++) {
                    double gv = lr->dim == 1 ? r[2 + j] : r[8 + j * 3 + c];
                    max_ge = fmax(max_ge, fabs(gv - ref_g[i * 9 + c * 3 + j]) / gscale);
                }
            }
        }
        double vb = want_double ? 1e-12 : 1e-5, gb = want_double ? 1e-11 : 1e-5;
        printf("%-30s %s elements %4zu: value err %.3e of range, gradient err %.3e of max, %d outside\n", name,
               want_double ? "double" : "float ", lr->element_count, max_ve, max_ge, outside);
        SL_CHECK_MSG(wrong_element == 0, "%s: %d points in another element than the CPU rule's", name, wrong_element);
        SL_CHECK_MSG(outside > 0, "%s: no outside point tested", name);
        SL_CHECK_MSG(max_ve <= vb, "%s: value error %.3e > %.0e of the range", name, max_ve, vb);
        SL_CHECK_MSG(max_ge <= gb, "%s: gradient error %.3e > %.0e", name, max_ge, gb);
        free(ref_v);
        free(ref_g);
        free(ref_e);
    }
    free(pts);
    free(out);
    if (prog)
        glDeleteProgram(prog);
    sl_lr_bezier_release(&g);
    sl_lr_bezier_free(&bz);
}

static void run_tensor(int o0, int o1, int o2, int dim, int want_double)
{
    sl_lr_volume lr;
    memset(&lr, 0, sizeof lr);
    SL_CHECK(lr_test_tensor(&lr, o0, o1, o2, dim, 1));
    if (!lr.element_count)
        return;
    char name[64];
    snprintf(name, sizeof name, "tensor degree (%d,%d,%d) dim %d", o0 - 1, o1 - 1, o2 - 1, dim);
    run_model(&lr, name, want_double);
    sl_lr_free(&lr);
}

int main(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "test_lr_gpu: %s\n", err.message);
        return 1;
    }
    for (int dbl = 0; dbl < 2; dbl++) {
        run_tensor(2, 2, 2, 1, dbl);
        run_tensor(3, 3, 3, 1, dbl);
        run_tensor(4, 4, 4, 1, dbl);
        run_tensor(2, 3, 4, 1, dbl);
        run_tensor(2, 3, 4, 3, dbl);
        for (int dim = 1; dim <= 3; dim += 2) {
            sl_lr_volume lr;
            memset(&lr, 0, sizeof lr);
            SL_CHECK(lr_test_refined(&lr, dim, 1));
            if (lr.element_count) {
                run_model(&lr, dim == 1 ? "locally refined dim 1" : "locally refined dim 3", dbl);
                sl_lr_free(&lr);
            }
        }
    }
    /* A generated model of 4096 elements (the linear look-up's scan is long). */
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json("{\"generator\":\"lr_field\",\"field\":\"trilinear_ml\",\"degree\":1,"
                                    "\"cells\":16}", &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "lr_field: %s", err.message);
    if (st == SL_OK)
        run_model(ds->lr, "lr_field trilinear_ml 16^3", 0);
    sl_dataset_destroy(ds);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
