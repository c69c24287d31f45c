/* test_particles_probe.c — the field functions the particles passes share
 * (renderer/particles/particles_field.glsl), run on the GPU through the probe
 * particles_probe.comp.glsl and checked against the independent double-
 * precision references of tests/support/particles_reference.h.
 *
 * Field: an f32 volume of random values in [0, 1] (17 x 19 x 13) and a u16
 * volume of random integers (16 x 16 x 16, through the R16 texture and its
 * value map), 10^4 random points each over [-1.5, dims + 0.5] (clamping
 * included), plus points on voxel centres and cell faces. Trilinear value
 * and gradient, B-spline value, gradient and Hessian, all relative to the
 * volume's value range. Curvature: 10^4 random world gradients (magnitudes
 * 1e-3 .. 1e3) and symmetric Hessians, plus umbilics (H = c I) and
 * cylinders; k1, k2 relative to max(|k1|, |k2|), e1 as an angle where the two
 * curvatures differ by more than 1 % of it. The bounds below are about 10x
 * what llvmpipe gave (measured values beside them). Exit 0 pass, 1 fail;
 * needs an OpenGL 4.5 context (llvmpipe is fine).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset.h"
#include "gpu/sl_gpu.h"
#include "particles_reference.h"
#include "volume/sl_volume.h"

/* Measured on llvmpipe (relative to the value range, worst of f32 and u16):
 * trilinear f 1.0e-7, gradient 1.4e-7; B-spline (inside the voxel centres'
 * box: beyond it the shader clamps the point, the reference only the taps)
 * f 1.9e-7, gradient 1.5e-7, Hessian 3.5e-7; curvature 1.6e-6 of max |k|,
 * e1 5.1e-4 rad where the curvatures differ by > 1 % (the angle of two
 * nearly equal eigenvalues is ill-conditioned). */
#define BOUND_TRI_F 1e-6
#define BOUND_TRI_G 2e-6
#define BOUND_BS_F 2e-6
#define BOUND_BS_G 2e-6
#define BOUND_BS_H 4e-6
#define BOUND_K 2e-5
#define BOUND_E1_RAD 5e-3

static double urand(void) { return (rand() + 0.5) / ((double)RAND_MAX + 1.0); }

static GLuint buffer(size_t bytes, const void *data)
{
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)bytes, data, data ? 0 : GL_MAP_READ_BIT);
    return b;
}

/* Runs the probe on n points (u: 4 floats each) and n curvature inputs. */
static int run_probe(GLuint prog, const sl_volume_texture *tex, const int dims[3], const float *u, const float *g,
                     const float *h, int n, float *out, float *curv)
{
    GLuint b[5] = {buffer((size_t)n * 16, u), buffer((size_t)n * 80, NULL), buffer((size_t)n * 16, g),
                   buffer((size_t)n * 48, h), buffer((size_t)n * 32, NULL)};
    for (int k = 0; k < 5; k++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, b[k]);
    glUseProgram(prog);
    glUniform1ui(glGetUniformLocation(prog, "u_count"), (GLuint)n);
    glUniform1i(glGetUniformLocation(prog, "u_volume"), 0);
    glUniform3i(glGetUniformLocation(prog, "u_voxel_dims"), dims[0], dims[1], dims[2]);
    glUniform2f(glGetUniformLocation(prog, "u_value_map"), tex->value_scale, tex->value_offset);
    glUniform3f(glGetUniformLocation(prog, "u_spacing"), 1.0f, 1.0f, 1.0f);
    glBindTextureUnit(0, tex->tex);
    glDispatchCompute((GLuint)((n + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(b[1], 0, (GLsizeiptr)n * 80, out);
    glGetNamedBufferSubData(b[4], 0, (GLsizeiptr)n * 32, curv);
    glDeleteBuffers(5, b);
    sl_err err = {0};
    return sl_gl_check_errors("particles probe", &err) == SL_OK;
}

typedef struct field_errors {
    double tri_f, tri_g, bs_f, bs_g, bs_h;
} field_errors;

static void field_check(const sl_volume *vol, const float *u, const float *out, int n, field_errors *e)
{
    double range = vol->value_max - vol->value_min;
    memset(e, 0, sizeof *e);
    for (int i = 0; i < n; i++) {
        double p[3] = {u[4 * i], u[4 * i + 1], u[4 * i + 2]}, f, g[3], fb, gb[3], H[9];
        pref_trilinear(vol, p, &f, g);
        pref_bspline(vol, p, &fb, gb, H);
        const float *o = out + 20 * i;
        e->tri_f = fmax(e->tri_f, fabs(o[0] - f) / range);
        for (int a = 0; a < 3; a++) /* on a cell face both take the cell above (below at the last voxel) */
            e->tri_g = fmax(e->tri_g, fabs(o[1 + a] - g[a]) / range);
        /* Beyond the voxel centres the shader clamps the point (particles stay
         * inside), the reference only the tap indices: compare inside. */
        int inside = 1;
        for (int a = 0; a < 3; a++)
            inside &= p[a] >= 0.0 && p[a] <= vol->dims[a] - 1;
        if (!inside)
            continue;
        e->bs_f = fmax(e->bs_f, fabs(o[4] - fb) / range);
        for (int a = 0; a < 3; a++) {
            e->bs_g = fmax(e->bs_g, fabs(o[5 + a] - gb[a]) / range);
            for (int b = 0; b < 3; b++) /* H column a, row b; the reference is row-major and symmetric */
                e->bs_h = fmax(e->bs_h, fabs(o[8 + 4 * a + b] - H[3 * b + a]) / range);
        }
    }
}

static int report(const char *what, double value, double bound)
{
    int ok = value <= bound;
    printf("%-40s %.3g (bound %.3g)%s\n", what, value, bound, ok ? "" : "  FAIL");
    return ok;
}

/* Random points over [-1.5, dims + 0.5], then voxel centres and cell faces. */
static void make_points(const int dims[3], float *u, int n)
{
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            double x = -1.5 + (dims[a] + 2.0) * urand();
            if (i % 10 == 1)
                x = floor(x); /* on a voxel plane */
            else if (i % 10 == 2)
                x = floor(x) + 0.5;
            u[4 * i + a] = (float)x;
        }
}

static sl_dataset *random_volume(const int dims[3], sl_voxel_type type, sl_err *err)
{
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, "probe");
    if (!ds || sl_volume_alloc(&ds->volume, dims, 1, type, err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    size_t count = (size_t)dims[0] * dims[1] * dims[2];
    for (size_t i = 0; i < count; i++) {
        if (type == SL_VOXEL_F32)
            ((float *)ds->volume.data)[i] = (float)urand();
        else
            ((uint16_t *)ds->volume.data)[i] = (uint16_t)(rand() % 65536);
    }
    for (int a = 0; a < 3; a++)
        ds->volume.spacing[a] = 1.0;
    if (sl_dataset_finish_volume(ds, err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

/* A random unit vector. */
static void random_direction(double v[3])
{
    double z = 2.0 * urand() - 1.0, phi = 2.0 * M_PI * urand(), r = sqrt(1.0 - z * z);
    v[0] = r * cos(phi);
    v[1] = r * sin(phi);
    v[2] = z;
}

int main(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "test_particles_probe: %s\n", err.message);
        return 1;
    }
    GLuint prog = 0;
    if (sl_gl_program_create(&(sl_program_desc){.compute = "particles/particles_probe.comp.glsl",
                                                .label = "particles probe"},
                             &prog, &err) != SL_OK) {
        fprintf(stderr, "test_particles_probe: %s\n", err.message);
        return 1;
    }
    srand(20261202);
    enum { N = 10000 };
    float *u = calloc(N * 4, sizeof *u), *g = calloc(N * 4, sizeof *g), *h = calloc(N * 12, sizeof *h);
    float *out = calloc(N * 20, sizeof *out), *curv = calloc(N * 8, sizeof *curv);
    double kg[N][3], kh[N][9];
    int ok = 1;

    /* Curvature inputs: random gradients and Hessians, umbilics, cylinders. */
    for (int i = 0; i < N; i++) {
        double d[3], mag = pow(10.0, -3.0 + 6.0 * urand());
        random_direction(d);
        for (int a = 0; a < 3; a++)
            kg[i][a] = mag * d[a];
        double A[9];
        for (int a = 0; a < 9; a++)
            A[a] = mag * (2.0 * urand() - 1.0);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                kh[i][3 * a + b] = 0.5 * (A[3 * a + b] + A[3 * b + a]);
        if (i % 10 == 1) { /* umbilic: H = c I */
            double c = mag * (2.0 * urand() - 1.0);
            memset(kh[i], 0, sizeof kh[i]);
            kh[i][0] = kh[i][4] = kh[i][8] = c;
        } else if (i % 10 == 2) { /* a cylinder along a tangent direction: H = c (I - n n^T - t t^T) */
            double t[3], n[3], c = mag * (2.0 * urand() - 1.0);
            for (int a = 0; a < 3; a++)
                n[a] = d[a];
            random_direction(t);
            double tn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2], tl = 0.0;
            for (int a = 0; a < 3; a++)
                t[a] -= tn * n[a], tl += t[a] * t[a];
            for (int a = 0; a < 3; a++)
                t[a] /= sqrt(tl);
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    kh[i][3 * a + b] = c * ((a == b) - n[a] * n[b] - t[a] * t[b]);
        }
        for (int a = 0; a < 3; a++) {
            g[4 * i + a] = (float)kg[i][a];
            for (int b = 0; b < 3; b++)
                h[12 * i + 4 * a + b] = (float)kh[i][3 * a + b]; /* column a */
        }
    }

    const int dims_f[3] = {17, 19, 13}, dims_u[3] = {16, 16, 16};
    const struct {
        const char *name;
        const int *dims;
        sl_voxel_type type;
    } volumes[2] = {{"f32 17x19x13", dims_f, SL_VOXEL_F32}, {"u16 16^3", dims_u, SL_VOXEL_U16}};
    for (int v = 0; v < 2; v++) {
        sl_dataset *ds = random_volume(volumes[v].dims, volumes[v].type, &err);
        sl_volume_texture tex = {0};
        if (!ds || sl_volume_texture_create(&ds->volume, &tex, &err) != SL_OK) {
            fprintf(stderr, "test_particles_probe: %s\n", err.message);
            return 1;
        }
        make_points(volumes[v].dims, u, N);
        if (!run_probe(prog, &tex, volumes[v].dims, u, g, h, N, out, curv)) {
            fprintf(stderr, "test_particles_probe: the probe raised a GL error\n");
            return 1;
        }
        field_errors e;
        field_check(&ds->volume, u, out, N, &e);
        char what[96];
        snprintf(what, sizeof what, "%s trilinear f", volumes[v].name), ok &= report(what, e.tri_f, BOUND_TRI_F);
        snprintf(what, sizeof what, "%s trilinear gradient", volumes[v].name), ok &= report(what, e.tri_g, BOUND_TRI_G);
        snprintf(what, sizeof what, "%s B-spline f", volumes[v].name), ok &= report(what, e.bs_f, BOUND_BS_F);
        snprintf(what, sizeof what, "%s B-spline gradient", volumes[v].name), ok &= report(what, e.bs_g, BOUND_BS_G);
        snprintf(what, sizeof what, "%s B-spline Hessian", volumes[v].name), ok &= report(what, e.bs_h, BOUND_BS_H);
        sl_volume_texture_destroy(&tex);
        sl_dataset_destroy(ds);
    }

    /* Curvature (the same for both runs; the last run's output is used). */
    double worst_k = 0.0, worst_e1 = 0.0;
    int e1_checked = 0;
    for (int i = 0; i < N; i++) {
        double k1, k2, e1[3];
        if (pref_curvature(kg[i], kh[i], &k1, &k2, e1) != 0)
            continue;
        double scale = fmax(fabs(k1), fabs(k2));
        if (!(scale > 0.0))
            continue;
        const float *c = curv + 8 * i;
        worst_k = fmax(worst_k, fmax(fabs(c[0] - k1), fabs(c[1] - k2)) / scale);
        if (k1 - k2 > 0.01 * scale) {
            double dot = fabs(c[4] * e1[0] + c[5] * e1[1] + c[6] * e1[2]);
            worst_e1 = fmax(worst_e1, acos(fmin(1.0, dot)));
            e1_checked++;
        }
    }
    ok &= report("curvature k1, k2 (relative to max |k|)", worst_k, BOUND_K);
    ok &= report("curvature e1 angle (rad)", worst_e1, BOUND_E1_RAD);
    printf("e1 compared at %d of %d points\n", e1_checked, N);
    ok &= e1_checked > N / 2;
    free(u), free(g), free(h), free(out), free(curv);
    glDeleteProgram(prog);
    sl_gpu_destroy(gpu);
    return ok ? 0 : 1;
}
