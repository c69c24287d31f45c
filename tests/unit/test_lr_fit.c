/* test_lr_fit.c — adaptive LR-spline fitting (renderer/lrspline/lr_fit.c).
 *
 * 1. A tensor polynomial of degree 2 (values exact in f32 on a dyadic grid)
 *    is in the spline space: the fit reproduces it to 1e-10 at the samples
 *    and at random points (sl_lr_eval against the formula), also after a
 *    forced refinement step.
 * 2. The distance to a sphere's centre (a cone point, so not in the space)
 *    fitted to a tolerance: the reported max error is <= tol (or the cap or
 *    the level limit is reported), the mesh is local (sl_lr_level_ratio >
 *    1), and the reported max error equals an independent recomputation
 *    with sl_lr_eval at the voxel centres.
 * 3. A vector field (abc) fits and its reported error is recomputed too.
 * 4. Bad parameters and datasets are refused.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lrspline/sl_lr.h"
#include "data/sl_lr_fit_dataset.h"
#include "sl_test.h"

static double poly(double x, double y, double z)
{
    return x * x * y - 2 * z * z + x * y * z + 3 - 0.5 * x * x * z * z * y;
}

static double sphere(double x, double y, double z)
{
    return sqrt((x - 1.1) * (x - 1.1) + (y - 0.9) * (y - 0.9) + (z - 1.3) * (z - 1.3));
}

static sl_dataset *make_volume(int n0, int n1, int n2, double h, double (*f)(double, double, double))
{
    sl_err err = {0};
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VOLUME, "test");
    int dims[3] = {n0, n1, n2};
    if (!ds || sl_volume_alloc(&ds->volume, dims, 1, SL_VOXEL_F32, &err) != SL_OK)
        return NULL;
    for (int d = 0; d < 3; d++)
        ds->volume.spacing[d] = h;
    ds->origin = (sl_vec3){0.5, 0.25, 0.0};
    float *v = ds->volume.data;
    for (int z = 0; z < n2; z++)
        for (int y = 0; y < n1; y++)
            for (int x = 0; x < n0; x++)
                *v++ = (float)f(0.5 + x * h, 0.25 + y * h, z * h);
    if (sl_dataset_finish_volume(ds, &err) != SL_OK)
        return NULL;
    return ds;
}

/* The max error at the voxel centres, recomputed from the model. */
static double recompute_error(const sl_dataset *ds, const sl_lr_volume *lr)
{
    const sl_volume *v = &ds->volume;
    double mx = 0.0;
    sl_err err = {0};
    for (int z = 0; z < v->dims[2]; z++)
        for (int y = 0; y < v->dims[1]; y++)
            for (int x = 0; x < v->dims[0]; x++) {
                double p[3] = {ds->origin.x + x * v->spacing[0], ds->origin.y + y * v->spacing[1],
                               ds->origin.z + z * v->spacing[2]};
                double f[3];
                if (sl_lr_eval(lr, p, -1, f, NULL, &err) != SL_OK)
                    return INFINITY;
                double e2 = 0.0;
                for (int c = 0; c < lr->dim; c++) {
                    double d = f[c] - sl_volume_value(v, (size_t)x, (size_t)y, (size_t)z, c);
                    e2 += d * d;
                }
                mx = fmax(mx, sqrt(e2));
            }
    return mx;
}

static void test_polynomial(void)
{
    sl_dataset *ds = make_volume(13, 11, 9, 0.25, poly);
    SL_CHECK(ds != NULL);
    if (!ds)
        return;
    for (int pass = 0; pass < 2; pass++) {
        sl_lr_fit_params p;
        sl_lr_fit_defaults(&p);
        p.cells_longest = 3;
        p.cg_tol = 1e-15;
        p.cg_iterations = 3000;
        p.tol = pass == 0 ? 1e-9 : 0.0; /* pass 1: tol 0 forces one refinement */
        p.max_iterations = pass;
        sl_lr_volume lr;
        sl_lr_fit_stats s;
        sl_err err = {0};
        SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_OK);
        if (pass == 1)
            SL_CHECK_MSG(s.iterations == 1 && lr.element_count > 3 * 3 * 2, "%d iterations, %zu elements",
                         s.iterations, lr.element_count);
        SL_CHECK_MSG(s.max_error < 1e-10, "pass %d: polynomial fit error %g", pass, s.max_error);
        double mx = 0.0;
        for (int i = 0; i < 2000; i++) {
            double q[3];
            for (int d = 0; d < 3; d++)
                q[d] = lr.domain_lo[d] + (lr.domain_hi[d] - lr.domain_lo[d]) * ((i * (d + 3) * 7919 % 1000) / 999.0);
            double f;
            SL_CHECK(sl_lr_eval(&lr, q, -1, &f, NULL, &err) == SL_OK);
            mx = fmax(mx, fabs(f - poly(q[0], q[1], q[2])));
        }
        SL_CHECK_MSG(mx < 1e-10, "pass %d: polynomial error at random points %g", pass, mx);
        printf("polynomial pass %d: max error %.3g at the samples, %.3g at random points (%zu basis)\n", pass,
               s.max_error, mx, lr.basis_count);
        sl_lr_free(&lr);
    }
    sl_dataset_destroy(ds);
}

static void test_sphere(void)
{
    sl_dataset *ds = make_volume(48, 48, 48, 2.0 / 47, sphere);
    SL_CHECK(ds != NULL);
    if (!ds)
        return;
    sl_lr_fit_params p;
    sl_lr_fit_defaults(&p);
    p.tol = 0.004;
    p.max_levels = 3;
    p.cells_longest = 4; /* spans of 0.5: halved twice before the floor of two sample spacings (0.085) */
    sl_lr_volume lr;
    sl_lr_fit_stats s;
    sl_err err = {0};
    SL_CHECK_MSG(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_OK, "%s", err.message);
    SL_CHECK_MSG(s.max_error <= p.tol || s.cap_hit || s.levels_exhausted, "max error %g above tol %g",
                 s.max_error, p.tol);
    SL_CHECK_MSG(sl_lr_level_ratio(&lr) > 1.0, "level ratio %g", sl_lr_level_ratio(&lr));
    SL_CHECK(sl_lr_finish(&lr, &err) == SL_OK);
    double again = recompute_error(ds, &lr);
    SL_CHECK_MSG(fabs(again - s.max_error) <= 1e-9, "reported %g, recomputed %g", s.max_error, again);
    printf("sphere: %zu elements, %zu basis, %d levels, max error %.3g (tol %g)%s%s\n", s.elements, s.basis,
           s.levels, s.max_error, p.tol, s.cap_hit ? ", cap hit" : "", s.levels_exhausted ? ", levels used up" : "");
    sl_lr_free(&lr);
    /* Minimal span refines only the offending elements, so it needs fewer
     * basis functions for an error as small, on this local feature. */
    size_t structured_basis = s.basis;
    double structured_error = s.max_error;
    p.strategy = SL_LR_FIT_MINIMAL_SPAN;
    SL_CHECK_MSG(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_OK, "%s", err.message);
    SL_CHECK_MSG(s.max_error <= p.tol || s.cap_hit || s.levels_exhausted, "minimal span: max error %g above tol %g",
                 s.max_error, p.tol);
    SL_CHECK_MSG(s.basis < structured_basis && s.max_error <= fmax(p.tol, 1.5 * structured_error),
                 "minimal span: %zu basis functions, max error %g; structured: %zu, %g", s.basis, s.max_error,
                 structured_basis, structured_error);
    SL_CHECK(sl_lr_finish(&lr, &err) == SL_OK);
    again = recompute_error(ds, &lr);
    SL_CHECK_MSG(fabs(again - s.max_error) <= 1e-9, "minimal span: reported %g, recomputed %g", s.max_error, again);
    printf("sphere, minimal span: %zu elements, %zu basis, %d levels, max error %.3g%s\n", s.elements, s.basis,
           s.levels, s.max_error, s.levels_exhausted ? ", levels used up" : "");
    sl_lr_free(&lr);
    p.strategy = SL_LR_FIT_STRUCTURED;
    /* A small cap is reported, and the model kept within it. */
    p.max_basis = 400;
    SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_OK);
    SL_CHECK(s.cap_hit && lr.basis_count <= 400 && s.max_error > p.tol);
    sl_lr_free(&lr);
    sl_dataset_destroy(ds);
}

static void test_vectors(void)
{
    sl_dataset *ds = NULL;
    sl_err err = {0};
    SL_CHECK(sl_lr_sample_field("abc", 14, &ds, &err) == SL_OK);
    if (!ds)
        return;
    sl_lr_fit_params p;
    sl_lr_fit_defaults(&p);
    p.tol = 0.05;
    p.max_levels = 2;
    sl_lr_volume lr;
    sl_lr_fit_stats s;
    SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_OK);
    SL_CHECK(lr.dim == 3);
    SL_CHECK(s.max_error <= p.tol || s.levels_exhausted);
    double again = recompute_error(ds, &lr);
    SL_CHECK_MSG(fabs(again - s.max_error) <= 1e-9, "vectors: reported %g, recomputed %g", s.max_error, again);
    sl_lr_free(&lr);
    sl_dataset_destroy(ds);
    SL_CHECK(sl_lr_sample_field("nope", 14, &ds, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_lr_sample_field("abc", 1, &ds, &err) == SL_ERR_INVALID);
}

static void test_refusals(void)
{
    sl_dataset *ds = make_volume(5, 5, 5, 0.25, poly);
    sl_lr_fit_params p;
    sl_lr_volume lr;
    sl_lr_fit_stats s;
    sl_err err = {0};
    sl_lr_fit_defaults(&p);
    p.degree = 0;
    SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_ERR_INVALID);
    sl_lr_fit_defaults(&p);
    p.fraction = 0;
    SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_ERR_INVALID);
    sl_lr_fit_defaults(&p);
    p.tol = -1;
    SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_ERR_INVALID);
    sl_lr_fit_defaults(&p);
    p.max_basis = 10; /* below the initial 6^3 */
    SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_ERR_INVALID);
    sl_dataset *lines = sl_dataset_create(SL_DATASET_LINES, "lines");
    sl_lr_fit_defaults(&p);
    SL_CHECK(sl_lr_fit(lines, &p, &lr, &s, &err) == SL_ERR_INVALID);
    sl_lr_fit_defaults(&p);
    p.strategy = (sl_lr_fit_strategy)7;
    SL_CHECK(sl_lr_fit(ds, &p, &lr, &s, &err) == SL_ERR_INVALID);
    sl_dataset_destroy(lines);
    sl_dataset_destroy(ds);
}

int main(void)
{
    test_polynomial();
    test_sphere();
    test_vectors();
    test_refusals();
    SL_TEST_END();
}
