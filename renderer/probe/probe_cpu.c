/* probe_cpu.c — CPU double evaluation of a dataset's field at world points
 * (see sl_probe.h): trilinear for regular volumes, sl_lr_eval for LR-spline
 * volumes. Any thread; no GL. */
#include "sl_probe.h"

#include <math.h>

#include "../lrspline/sl_lr.h"

int sl_probe_components(const sl_dataset *ds)
{
    switch (ds->kind) {
    case SL_DATASET_VOLUME: return 1;
    case SL_DATASET_VECTORS: return 3;
    case SL_DATASET_LR: return ds->lr ? ds->lr->dim : 0;
    default: return 0;
    }
}

/* The cell of a regular volume around world point p: per axis the voxels
 * lo..hi, the local weight t and whether the axis varies (live); 0 when p is
 * outside the domain (the closed box of the voxel centres; a one-voxel
 * axis: a slab one spacing thick). */
static int volume_cell(const sl_dataset *ds, const double p[3], size_t lo[3], size_t hi[3], double t[3],
                       double live[3])
{
    const sl_volume *vol = &ds->volume;
    const double origin[3] = {ds->origin.x, ds->origin.y, ds->origin.z};
    for (int a = 0; a < 3; a++) {
        double u = (p[a] - origin[a]) / vol->spacing[a]; /* voxel coordinate */
        int n = vol->dims[a];
        if (n == 1) {
            if (!(u >= -0.5 && u <= 0.5))
                return 0;
            lo[a] = hi[a] = 0;
            t[a] = 0.0;
            live[a] = 0.0;
            continue;
        }
        if (!(u >= 0.0 && u <= (double)(n - 1)))
            return 0;
        double cell = floor(u);
        if (cell > (double)(n - 2))
            cell = (double)(n - 2); /* the last voxel belongs to the cell below */
        lo[a] = (size_t)cell;
        hi[a] = lo[a] + 1;
        t[a] = u - cell;
        live[a] = 1.0;
    }
    return 1;
}

/* Trilinear value and gradient of a regular volume at world point p. */
static int probe_volume(const sl_dataset *ds, const double p[3], double *value, double *gradient)
{
    const sl_volume *vol = &ds->volume;
    size_t lo[3], hi[3];
    double t[3], live[3];
    if (!volume_cell(ds, p, lo, hi, t, live))
        return 0;
    int nc = vol->components;
    for (int c = 0; c < nc; c++) {
        double f = 0.0, g[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < 2; k++)
            for (int j = 0; j < 2; j++)
                for (int i = 0; i < 2; i++) {
                    double wx = i ? t[0] : 1.0 - t[0], wy = j ? t[1] : 1.0 - t[1], wz = k ? t[2] : 1.0 - t[2];
                    double dx = (i ? 1.0 : -1.0) * live[0], dy = (j ? 1.0 : -1.0) * live[1],
                           dz = (k ? 1.0 : -1.0) * live[2];
                    /* A tap is read only where its weight is not zero (NaN * 0 is NaN). */
                    double w[4] = {wx * wy * wz, dx * wy * wz, wx * dy * wz, wx * wy * dz};
                    if (w[0] == 0.0 && (!gradient || (w[1] == 0.0 && w[2] == 0.0 && w[3] == 0.0)))
                        continue;
                    double v = sl_volume_value(vol, i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2], c);
                    if (w[0] != 0.0)
                        f += w[0] * v;
                    for (int a = 0; a < 3; a++)
                        if (w[a + 1] != 0.0)
                            g[a] += w[a + 1] * v;
                }
        value[c] = f;
        if (gradient)
            for (int a = 0; a < 3; a++)
                gradient[c * 3 + a] = g[a] / vol->spacing[a];
    }
    return 1;
}

int sl_probe_inside(const sl_dataset *ds, const double p[3])
{
    if (sl_probe_components(ds) == 0 || !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return 0;
    if (ds->kind == SL_DATASET_LR)
        return sl_lr_find_element(ds->lr, p) >= 0;
    size_t lo[3], hi[3];
    double t[3], live[3];
    return volume_cell(ds, p, lo, hi, t, live);
}

sl_status sl_probe_eval(const sl_dataset *ds, const double p[3], double *value, double *gradient, int *inside,
                        sl_err *err)
{
    *inside = 0;
    if (sl_probe_components(ds) == 0)
        return sl_err_set(err, SL_ERR_UNSUPPORTED, "dataset \"%s\" is a %s dataset: it has no field to probe"
                          " (volumes, vector fields and LR-spline volumes do)", ds->name,
                          sl_dataset_kind_name(ds->kind));
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return SL_OK;
    if (ds->kind == SL_DATASET_LR) {
        long e = sl_lr_find_element(ds->lr, p);
        if (e < 0)
            return SL_OK;
        sl_status st = sl_lr_eval(ds->lr, p, e, value, gradient, err);
        *inside = st == SL_OK;
        return st;
    }
    *inside = probe_volume(ds, p, value, gradient);
    return SL_OK;
}
