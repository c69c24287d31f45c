/* test_probe_gpu.c — the shader path of sightline-probe
 * (renderer/probe/probe_gpu.c, sl_probe_gpu.h) against the CPU double
 * reference (probe_cpu.c: sl_lr_eval from the LR basis, the trilinear in
 * double) on llvmpipe.
 *
 * LR-spline volumes: the files of tests/data/lr/ (refined_quadratic.lr.gz,
 * the reference library's locally refined identity map, vector; two_lines.lr,
 * ours, scalar, degree 0 in z), an lr_field Marschner-Lobb of degree 3 (its
 * model carries the auto index, reused), a tensor product with random
 * coefficients and the hand-refined model of lr_test_models.h (knot 0.4, not
 * a float) (no index: the blocks build their own). 20000 points each:
 * random inside, on element faces (knot planes), on the domain's faces,
 * edges and corners, just outside a face (1e-9 of the side) and far
 * outside. Inside/outside must match exactly (empty fields in the same
 * rows); value within 1e-5 of the value range (the target; the
 * largest component range for vectors) of the CPU's at the point as given;
 * gradient / Jacobian within 1e-5 of the largest gradient entry seen, of the
 * CPU's at the point the GPU evaluates (rounded to float and clamped into
 * the float box, sl_probe_gpu.h): on a C0 knot plane that is not a float the
 * gradient jumps, and the side the point rounds to decides it.
 * Regular volumes: a scalar f32 volume and a u8 one through volume_dvr's
 * filtered texture, and a vector field through the streamline field, same
 * kinds of points (voxel planes for knot planes): value within 2e-6 of the
 * range (measured below); gradients of regular volumes are refused
 * (SL_ERR_UNSUPPORTED). Needs a GL 4.5 context.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data/sl_dataset_open.h"
#include "data/sl_generate.h"
#include "gpu/sl_gpu.h"
#include "lr_test_models.h"
#include "probe/sl_probe.h"
#include "probe/sl_probe_gpu.h"
#include "sl_test.h"

enum { NPOINTS = 20000 };

/* Bounds (relative, see the header). Measured on llvmpipe: LR values <=
 * 2.9e-7, gradients <= 2.1e-6 (Marschner-Lobb degree 3); regular volumes
 * f32 5.9e-7 and u8 5.7e-7 through the texture filter (llvmpipe's weights
 * are not 8-bit here), vectors 8.8e-7 (float positions and lerps). */
#define LR_BOUND 1e-5
#define REGULAR_BOUND 2e-6

/* The domain box and the planes points are put on (element or voxel faces). */
typedef struct point_set {
    double lo[3], hi[3];
    const double *planes[3];
    size_t plane_count[3];
} point_set;

static void make_points(const point_set *ps, double *pts)
{
    for (int i = 0; i < NPOINTS; i++) {
        double *p = pts + 3 * i;
        int kind = i % 8;
        for (int d = 0; d < 3; d++) {
            double lo = ps->lo[d], hi = ps->hi[d], v = lo + (hi - lo) * urand();
            if ((kind == 0 || kind == 1) && ps->plane_count[d]) /* knot / voxel planes */
                v = ps->planes[d][(size_t)(urand() * (double)ps->plane_count[d]) % ps->plane_count[d]];
            else if (kind == 2 && d == (i / 8) % 3)
                v = urand() < 0.5 ? lo : hi;              /* a face */
            else if (kind == 3 && urand() < 0.7)
                v = urand() < 0.5 ? lo : hi;              /* edges and corners */
            else if (kind == 4 && d == (i / 8) % 3)
                v = urand() < 0.5 ? lo - 1e-9 * (hi - lo) : hi + 1e-9 * (hi - lo); /* just outside */
            else if (kind == 5 && i % 40 == 5 && d == 0)
                v = hi + 0.5 * (hi - lo);                 /* far outside */
            p[d] = v;
        }
    }
}

/* Compares the GPU answers with sl_probe_eval at the points; value error of
 * `range`-relative bound vb, gradient of the largest entry gb (gb < 0: no
 * gradients). */
static void compare(const sl_dataset *ds, const point_set *ps, const char *name, double vb, double gb)
{
    sl_err err = {0};
    int nc = sl_probe_components(ds), grad = gb >= 0.0;
    sl_probe_gpu *g = NULL;
    sl_status st = sl_probe_gpu_create(ds, grad, &g, &err);
    SL_CHECK_MSG(st == SL_OK, "%s: %s", name, err.message);
    double *pts = malloc(sizeof(double) * 3 * NPOINTS);
    double *gv = calloc((size_t)NPOINTS * 3, sizeof(double)), *gg = calloc((size_t)NPOINTS * 9, sizeof(double));
    double *cv = calloc((size_t)NPOINTS * 3, sizeof(double)), *cg = calloc((size_t)NPOINTS * 9, sizeof(double));
    unsigned char *gin = malloc(NPOINTS), *cin = malloc(NPOINTS);
    if (st != SL_OK || !pts || !gv || !gg || !cv || !cg || !gin || !cin)
        goto done;
    make_points(ps, pts);
    st = sl_probe_gpu_eval(g, NPOINTS, pts, gv, grad ? gg : NULL, gin, &err);
    SL_CHECK_MSG(st == SL_OK, "%s eval: %s", name, err.message);
    if (st != SL_OK)
        goto done;
    int mismatch = 0, inside = 0, outside = 0;
    double vmin[3] = {INFINITY, INFINITY, INFINITY}, vmax[3] = {-INFINITY, -INFINITY, -INFINITY}, gscale = 1e-300;
    for (int i = 0; i < NPOINTS; i++) {
        int in = 0;
        SL_CHECK(sl_probe_eval(ds, pts + 3 * i, cv + 3 * i, grad ? cg + 9 * i : NULL, &in, &err) == SL_OK);
        cin[i] = (unsigned char)in;
        mismatch += cin[i] != gin[i];
        inside += in;
        outside += !in;
        for (int c = 0; in && c < nc; c++) {
            vmin[c] = fmin(vmin[c], cv[3 * i + c]);
            vmax[c] = fmax(vmax[c], cv[3 * i + c]);
            for (int j = 0; grad && j < 3; j++)
                gscale = fmax(gscale, fabs(cg[9 * i + 3 * c + j]));
        }
    }
    double range = 0.0;
    for (int c = 0; c < nc; c++)
        range = fmax(range, vmax[c] - vmin[c]);
    double ve = 0.0, ge = 0.0;
    for (int i = 0; i < NPOINTS; i++) {
        if (!cin[i] || !gin[i])
            continue;
        /* Gradients: the CPU's at the point the GPU evaluates, p rounded to
         * float and clamped into the float box (on a C0 knot plane that is
         * not a float, the side it rounds to decides the gradient). */
        double pf[3], fv[3], fg[9];
        int in_f = 0;
        for (int d = 0; d < 3; d++) {
            float f = (float)pts[3 * i + d], lo = (float)ps->lo[d], hi = (float)ps->hi[d];
            lo = (double)lo < ps->lo[d] ? nextafterf(lo, INFINITY) : lo;
            hi = (double)hi > ps->hi[d] ? nextafterf(hi, -INFINITY) : hi;
            pf[d] = f < lo ? lo : f > hi ? hi : f;
        }
        if (grad)
            SL_CHECK(sl_probe_eval(ds, pf, fv, fg, &in_f, &err) == SL_OK && in_f);
        for (int c = 0; c < nc; c++) {
            ve = fmax(ve, fabs(gv[nc * i + c] - cv[3 * i + c]) / range);
            for (int j = 0; grad && in_f && j < 3; j++)
                ge = fmax(ge, fabs(gg[3 * nc * i + 3 * c + j] - fg[3 * c + j]) / gscale);
        }
    }
    printf("%-34s %5d inside %4d outside: value err %.3e of range %.4g%s", name, inside, outside, ve, range,
           grad ? "" : "\n");
    if (grad)
        printf(", gradient err %.3e of %.4g\n", ge, gscale);
    SL_CHECK_MSG(mismatch == 0, "%s: %d points inside on one path and outside on the other", name, mismatch);
    SL_CHECK_MSG(inside > NPOINTS / 2 && outside > NPOINTS / 40, "%s: %d inside, %d outside", name, inside, outside);
    SL_CHECK_MSG(range > 0.0, "%s: constant field", name);
    SL_CHECK_MSG(ve <= vb, "%s: value error %.3e > %.0e of the range", name, ve, vb);
    SL_CHECK_MSG(!grad || ge <= gb, "%s: gradient error %.3e > %.0e", name, ge, gb);
done:
    free(pts);
    free(gv);
    free(gg);
    free(cv);
    free(cg);
    free(gin);
    free(cin);
    sl_probe_gpu_destroy(g);
}

/* The element faces of an LR model as the point set's planes. */
static void lr_points(const sl_lr_volume *lr, point_set *ps, double *planes[3])
{
    for (int d = 0; d < 3; d++) {
        ps->lo[d] = lr->domain_lo[d];
        ps->hi[d] = lr->domain_hi[d];
        planes[d] = malloc(sizeof(double) * 2 * lr->element_count);
        ps->plane_count[d] = 0;
        for (size_t e = 0; planes[d] && e < lr->element_count; e++) {
            planes[d][ps->plane_count[d]++] = lr->elements[e].lo[d];
            planes[d][ps->plane_count[d]++] = lr->elements[e].hi[d];
        }
        ps->planes[d] = planes[d];
    }
}

static void check_lr(const sl_dataset *ds, const char *name)
{
    point_set ps;
    double *planes[3];
    lr_points(ds->lr, &ps, planes);
    compare(ds, &ps, name, LR_BOUND, LR_BOUND);
    for (int d = 0; d < 3; d++)
        free(planes[d]);
}

static void test_lr_files(void)
{
    static const char *const files[2] = {"tests/data/lr/refined_quadratic.lr.gz", "tests/data/lr/two_lines.lr"};
    const char *src = getenv("SIGHTLINE_SOURCE_DIR");
    for (int k = 0; k < 2; k++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", src ? src : ".", files[k]);
        sl_dataset *ds = NULL;
        sl_err err = {0};
        sl_status st = sl_dataset_open(path, NULL, &ds, &err);
        SL_CHECK_MSG(st == SL_OK, "%s: %s", path, err.message);
        if (st == SL_OK)
            check_lr(ds, files[k] + strlen("tests/data/lr/"));
        sl_dataset_destroy(ds);
    }
}

static void test_lr_models(void)
{
    sl_err err = {0};
    sl_dataset *ds = NULL;
    sl_status st = sl_generate_json("{\"generator\":\"lr_field\",\"field\":\"marschner_lobb\",\"degree\":3,"
                                    "\"cells\":10,\"grading\":0.5}", &ds, &err);
    SL_CHECK_MSG(st == SL_OK, "lr_field: %s", err.message);
    if (st == SL_OK) {
        SL_CHECK(ds->lr->index != NULL); /* the blocks reuse it */
        check_lr(ds, "lr_field marschner_lobb degree 3");
    }
    sl_dataset_destroy(ds);
    sl_dataset t = {.kind = SL_DATASET_LR};
    sl_lr_volume lr;
    memset(&lr, 0, sizeof lr);
    SL_CHECK(lr_test_tensor(&lr, 3, 4, 2, 3, 0)); /* uneven knots, vector, no index */
    if (lr.element_count) {
        t.lr = &lr;
        snprintf(t.name, sizeof t.name, "tensor");
        check_lr(&t, "tensor (2,3,1) vector, own look-up");
    }
    sl_lr_free(&lr);
    memset(&lr, 0, sizeof lr);
    SL_CHECK(lr_test_refined(&lr, 1, 0)); /* knots 0.4 in z: not floats */
    if (lr.element_count) {
        t.lr = &lr;
        check_lr(&t, "hand-refined scalar, own look-up");
    }
    sl_lr_free(&lr);
}

static double voxel(int i, int j, int k, int c)
{
    return sin(0.7 * i + 1.3 * j - 0.4 * k + c) * 3 + c;
}

static sl_dataset *make_volume(int nc, sl_voxel_type type)
{
    sl_err err = {0};
    const int dims[3] = {17, 11, 9};
    sl_dataset *ds = sl_dataset_create(nc == 3 ? SL_DATASET_VECTORS : SL_DATASET_VOLUME, "v");
    if (!ds || sl_volume_alloc(&ds->volume, dims, nc, type, &err) != SL_OK)
        return NULL;
    for (int k = 0; k < dims[2]; k++)
        for (int j = 0; j < dims[1]; j++)
            for (int i = 0; i < dims[0]; i++)
                for (int c = 0; c < nc; c++) {
                    size_t v = (((size_t)k * dims[1] + j) * dims[0] + i) * nc + c;
                    if (type == SL_VOXEL_U8)
                        ((uint8_t *)ds->volume.data)[v] = (uint8_t)lround(127.5 + 40.0 * voxel(i, j, k, c));
                    else
                        ((float *)ds->volume.data)[v] = (float)voxel(i, j, k, c);
                }
    const double sp[3] = {0.3, 0.7, 0.45};
    for (int a = 0; a < 3; a++)
        ds->volume.spacing[a] = sp[a];
    ds->origin = sl_v3(-1.3, 0.2, 2.1);
    if (sl_dataset_finish_volume(ds, &err) != SL_OK) {
        sl_dataset_destroy(ds);
        return NULL;
    }
    return ds;
}

static void check_volume(int nc, sl_voxel_type type, const char *name, double bound)
{
    sl_dataset *ds = make_volume(nc, type);
    SL_CHECK(ds != NULL);
    if (!ds)
        return;
    point_set ps;
    double planes[3][32];
    const double origin[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    for (int d = 0; d < 3; d++) {
        int n = ds->volume.dims[d];
        ps.lo[d] = origin[d];
        ps.hi[d] = origin[d] + ds->volume.spacing[d] * (n - 1);
        for (int i = 0; i < n; i++)
            planes[d][i] = origin[d] + ds->volume.spacing[d] * i;
        ps.planes[d] = planes[d];
        ps.plane_count[d] = (size_t)n;
    }
    compare(ds, &ps, name, bound, -1.0);
    sl_probe_gpu *g = NULL;
    sl_err err = {0};
    SL_CHECK_MSG(sl_probe_gpu_create(ds, 1, &g, &err) == SL_ERR_UNSUPPORTED && g == NULL &&
                     strstr(err.message, "gradient"), "%s: gradients not refused", name);
    sl_dataset_destroy(ds);
}

int main(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        fprintf(stderr, "test_probe_gpu: %s\n", err.message);
        return 1;
    }
    test_lr_files();
    test_lr_models();
    check_volume(1, SL_VOXEL_F32, "volume f32 (volume_dvr's texture)", REGULAR_BOUND);
    check_volume(1, SL_VOXEL_U8, "volume u8 (volume_dvr's texture)", REGULAR_BOUND);
    check_volume(3, SL_VOXEL_F32, "vector field (streamline field)", REGULAR_BOUND);
    sl_gpu_destroy(gpu);
    SL_TEST_END();
}
