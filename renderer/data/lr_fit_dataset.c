/* lr_fit_dataset.c — sl_lr_fit_dataset.h: a regular volume or vector field as the samples of an
 * LR fit (renderer/lrspline/sl_lr_fit.h), and the analytic fields sampled to such volumes, the
 * inputs of the LR fits of the abc and tornado samples. The line generators of the same names
 * trace these fields; none of them produces a volume, hence this. Tornado: the generator's own
 * formula (gen_tornado.h). Any thread; no GL. */
#include "sl_lr_fit_dataset.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen_tornado.h"

static sl_status make_samples(const sl_dataset *ds, int stride, sl_lr_fit_samples *s, sl_err *err)
{
    memset(s, 0, sizeof *s);
    const sl_volume *v = &ds->volume;
    s->dim = v->components == 3 ? 3 : 1;
    double origin[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    size_t total = 1;
    int *idx[3] = {NULL, NULL, NULL};
    for (int d = 0; d < 3; d++) {
        int n = (v->dims[d] - 1 + stride - 1) / stride + 1; /* 0, s, 2s, .., and the last voxel */
        s->n[d] = n;
        s->x[d] = malloc((size_t)n * sizeof(double));
        idx[d] = malloc((size_t)n * sizeof(int));
        if (!s->x[d] || !idx[d])
            goto oom;
        for (int m = 0; m < n; m++) {
            int i = m * stride < v->dims[d] - 1 ? m * stride : v->dims[d] - 1;
            idx[d][m] = i;
            s->x[d][m] = origin[d] + i * v->spacing[d];
        }
        s->lo[d] = s->x[d][0];
        s->hi[d] = s->x[d][n - 1];
        total *= (size_t)n;
    }
    if (total > (size_t)UINT32_MAX / 4) {
        for (int d = 0; d < 3; d++)
            free(idx[d]);
        return sl_err_set(err, SL_ERR_LIMIT, "%zu samples are too many: use a larger stride", total);
    }
    s->y = malloc(total * (size_t)s->dim * sizeof *s->y);
    if (!s->y)
        goto oom;
    size_t k = 0;
    for (int z = 0; z < s->n[2]; z++)
        for (int y = 0; y < s->n[1]; y++)
            for (int x = 0; x < s->n[0]; x++)
                for (int c = 0; c < s->dim; c++)
                    s->y[k++] = sl_volume_value(v, (size_t)idx[0][x], (size_t)idx[1][y], (size_t)idx[2][z], c);
    for (int d = 0; d < 3; d++)
        free(idx[d]);
    return SL_OK;
oom:
    for (int d = 0; d < 3; d++) {
        free(idx[d]);
        free(s->x[d]);
        s->x[d] = NULL;
    }
    return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the fit samples");
}

static void free_samples(sl_lr_fit_samples *s)
{
    for (int d = 0; d < 3; d++)
        free(s->x[d]);
    free(s->y);
}

sl_status sl_lr_fit(const sl_dataset *ds, const sl_lr_fit_params *p, sl_lr_volume *out,
                    sl_lr_fit_stats *stats, sl_err *err)
{
    memset(out, 0, sizeof *out);
    memset(stats, 0, sizeof *stats);
    if (!ds || (ds->kind != SL_DATASET_VOLUME && ds->kind != SL_DATASET_VECTORS))
        return sl_err_set(err, SL_ERR_INVALID, "LR fitting needs a regular scalar volume or vector field");
    for (int d = 0; d < 3; d++)
        if (ds->volume.dims[d] < 2)
            return sl_err_set(err, SL_ERR_INVALID, "the volume has %d voxels along axis %d: need at least 2",
                              ds->volume.dims[d], d);
    sl_status st = sl_lr_fit_check_params(p, err);
    if (st != SL_OK)
        return st;
    sl_lr_fit_samples s;
    if ((st = make_samples(ds, p->stride, &s, err)) != SL_OK)
        return st;
    st = sl_lr_fit_grid(&s, p, out, stats, err);
    free_samples(&s);
    return st;
}

static void abc_field(const double p[3], double v[3])
{
    const double a = 1.7320508075688772, b = 1.4142135623730951, c = 1.0;
    v[0] = a * sin(p[2]) + c * cos(p[1]);
    v[1] = b * sin(p[0]) + a * cos(p[2]);
    v[2] = c * sin(p[1]) + b * cos(p[0]);
}

static void tornado_field(const double p[3], double v[3])
{
    double curl[3];
    sl_gen_tornado_eval(p, 0.0, v, curl);
}

sl_status sl_lr_sample_field(const char *name, int n, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    void (*field)(const double[3], double[3]);
    double lo, hi;
    if (strcmp(name, "abc") == 0) {
        field = abc_field;
        lo = 0.0;
        hi = 2.0 * M_PI;
    } else if (strcmp(name, "tornado") == 0) {
        field = tornado_field;
        lo = 0.0;
        hi = 1.0;
    } else {
        return sl_err_set(err, SL_ERR_INVALID, "unknown field '%s' (abc or tornado)", name);
    }
    if (n < 2 || n > 512)
        return sl_err_set(err, SL_ERR_INVALID, "field size %d is outside 2..512", n);
    char label[64];
    snprintf(label, sizeof label, "%s_%d", name, n);
    sl_dataset *ds = sl_dataset_create(SL_DATASET_VECTORS, label);
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the %s field", name);
    int dims[3] = {n, n, n};
    sl_status st = sl_volume_alloc(&ds->volume, dims, 3, SL_VOXEL_F32, err);
    if (st != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    double h = (hi - lo) / (n - 1);
    for (int d = 0; d < 3; d++)
        ds->volume.spacing[d] = h;
    ds->origin = (sl_vec3){lo, lo, lo};
    float *data = ds->volume.data;
    size_t k = 0;
    for (int z = 0; z < n; z++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                double p[3] = {lo + x * h, lo + y * h, lo + z * h}, v[3];
                field(p, v);
                for (int c = 0; c < 3; c++)
                    data[k++] = (float)v[c];
            }
    st = sl_dataset_finish_volume(ds, err);
    if (st != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    *out = ds;
    return SL_OK;
}
