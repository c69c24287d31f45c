/* lr_fit_fields.c — analytic vector fields sampled to regular vector
 * volumes (SL_DATASET_VECTORS), the inputs of the LR fits of the abc and
 * tornado samples (see sl_lr_sample_field in sl_lr_fit.h). The line
 * generators of the same names trace these fields; none of them produces a
 * volume, hence this. Tornado: the generator's own formula
 * (data/gen_tornado.h). Any thread; no GL. */
#include "sl_lr_fit.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../data/gen_tornado.h"

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
