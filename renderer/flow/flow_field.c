/* flow_field.c — vector-field sampling for the CPU integrators, in double
 * (sl_flow.h: the voxel-centre convention, the trilinear order of
 * operations the compute shader repeats, the heuristic local size).
 * LR look-up: the cursor's element is tried first under the element rule,
 * then sl_lr_find_element (the model's k-d forest or texture when it carries
 * one, sl_lr_index; else a linear search).
 * Any thread; no GL; the field is read-only.
 */
#include <math.h>
#include <string.h>

#include "sl_flow.h"

sl_status sl_flow_field_from_dataset(sl_flow_field *f, const sl_dataset *ds, sl_err *err)
{
    memset(f, 0, sizeof *f);
    if (ds->kind == SL_DATASET_VECTORS) {
        const sl_volume *v = &ds->volume;
        if (v->components != 3 || v->type != SL_VOXEL_F32)
            return sl_err_set(err, SL_ERR_INVALID, "vector field '%s' is not f32 x 3", ds->name);
        f->kind = SL_FLOW_FIELD_REGULAR;
        f->volume = v;
        f->origin[0] = ds->origin.x;
        f->origin[1] = ds->origin.y;
        f->origin[2] = ds->origin.z;
        for (int a = 0; a < 3; a++) {
            f->dims[a] = v->dims[a];
            f->spacing[a] = v->spacing[a];
            if (v->dims[a] > 1) {
                f->lo[a] = f->origin[a];
                f->hi[a] = f->origin[a] + (double)(v->dims[a] - 1) * v->spacing[a];
            } else {
                f->lo[a] = f->origin[a] - 0.5 * v->spacing[a];
                f->hi[a] = f->origin[a] + 0.5 * v->spacing[a];
            }
        }
        return SL_OK;
    }
    if (ds->kind == SL_DATASET_LR) {
        if (!ds->lr || ds->lr->dim != 3)
            return sl_err_set(err, SL_ERR_INVALID,
                              "LR-spline volume '%s' is scalar (dim %d); streamlines need dim 3",
                              ds->name, ds->lr ? ds->lr->dim : 0);
        f->kind = SL_FLOW_FIELD_LR;
        f->lr = ds->lr;
        memcpy(f->lo, ds->lr->domain_lo, sizeof f->lo);
        memcpy(f->hi, ds->lr->domain_hi, sizeof f->hi);
        return SL_OK;
    }
    return sl_err_set(err, SL_ERR_INVALID,
                      "dataset '%s' is a %s dataset; streamlines need a vector field "
                      "(vectors or an LR-spline volume of dim 3)",
                      ds->name, sl_dataset_kind_name(ds->kind));
}

void sl_flow_field_helix(sl_flow_field *f, double omega, double axial, const double lo[3],
                         const double hi[3])
{
    memset(f, 0, sizeof *f);
    f->kind = SL_FLOW_FIELD_HELIX;
    f->omega = omega;
    f->axial = axial;
    memcpy(f->lo, lo, sizeof f->lo);
    memcpy(f->hi, hi, sizeof f->hi);
}

void sl_flow_helix_exact(const sl_flow_field *f, const double x0[3], double t, double x[3])
{
    double c = cos(f->omega * t), s = sin(f->omega * t);
    x[0] = c * x0[0] - s * x0[1];
    x[1] = s * x0[0] + c * x0[1];
    x[2] = x0[2] + f->axial * t;
}

int sl_flow_inside(const sl_flow_field *f, const double p[3])
{
    for (int a = 0; a < 3; a++)
        if (!(p[a] >= f->lo[a] && p[a] <= f->hi[a]))  /* NaN fails too */
            return 0;
    return 1;
}

static int lr_in_element(const sl_lr_volume *lr, long e, const double p[3])
{
    const sl_lr_element *el = &lr->elements[e];
    for (int d = 0; d < 3; d++) {
        if (p[d] < el->lo[d])
            return 0;
        if (p[d] >= el->hi[d] && !(p[d] == lr->domain_hi[d] && el->hi[d] == lr->domain_hi[d]))
            return 0;
    }
    return 1;
}

static long lr_element(const sl_lr_volume *lr, const double p[3], sl_flow_cursor *cursor)
{
    if (cursor && cursor->element >= 0 && (size_t)cursor->element < lr->element_count &&
        lr_in_element(lr, cursor->element, p))
        return cursor->element;
    long e = sl_lr_find_element(lr, p);
    if (cursor)
        cursor->element = e;
    return e;
}

static void trilinear(const sl_flow_field *f, const double p[3], double v[3])
{
    const float *data = f->volume->data;
    int i0[3], i1[3];
    double w[3];
    for (int a = 0; a < 3; a++) {
        if (f->dims[a] == 1) {
            i0[a] = i1[a] = 0;
            w[a] = 0.0;
            continue;
        }
        double q = (p[a] - f->origin[a]) / f->spacing[a];
        double fl = floor(q);
        if (fl < 0.0)
            fl = 0.0;
        if (fl > (double)(f->dims[a] - 2))
            fl = (double)(f->dims[a] - 2);
        i0[a] = (int)fl;
        i1[a] = i0[a] + 1;
        w[a] = q - fl;
    }
    size_t nx = (size_t)f->dims[0], nxy = nx * (size_t)f->dims[1];
    for (int c = 0; c < 3; c++) {
        double cz[2];
        for (int kz = 0; kz < 2; kz++) {
            size_t z = (size_t)(kz ? i1[2] : i0[2]);
            double cy[2];
            for (int ky = 0; ky < 2; ky++) {
                size_t y = (size_t)(ky ? i1[1] : i0[1]);
                size_t row = z * nxy + y * nx;
                double a0 = data[3 * (row + (size_t)i0[0]) + (size_t)c];
                double a1 = data[3 * (row + (size_t)i1[0]) + (size_t)c];
                cy[ky] = a0 + w[0] * (a1 - a0);
            }
            cz[kz] = cy[0] + w[1] * (cy[1] - cy[0]);
        }
        v[c] = cz[0] + w[2] * (cz[1] - cz[0]);
    }
}

int sl_flow_sample(const sl_flow_field *f, const double p[3], sl_flow_cursor *cursor, double v[3])
{
    if (!sl_flow_inside(f, p)) {
        v[0] = v[1] = v[2] = 0.0;
        return -1;
    }
    switch (f->kind) {
    case SL_FLOW_FIELD_REGULAR:
        trilinear(f, p, v);
        return 0;
    case SL_FLOW_FIELD_LR: {
        long e = lr_element(f->lr, p, cursor);
        sl_err err;
        if (e < 0 || sl_lr_eval(f->lr, p, e, v, NULL, &err) != SL_OK) {
            v[0] = v[1] = v[2] = 0.0;
            return -1;
        }
        return 0;
    }
    case SL_FLOW_FIELD_HELIX:
        v[0] = -f->omega * p[1];
        v[1] = f->omega * p[0];
        v[2] = f->axial;
        return 0;
    }
    v[0] = v[1] = v[2] = 0.0;
    return -1;
}

double sl_flow_local_size(const sl_flow_field *f, const double p[3], sl_flow_cursor *cursor)
{
    if (!sl_flow_inside(f, p))
        return 0.0;
    switch (f->kind) {
    case SL_FLOW_FIELD_REGULAR: {
        double s = f->spacing[0];
        for (int a = 1; a < 3; a++)
            if (f->spacing[a] < s)
                s = f->spacing[a];
        return 0.5 * s;
    }
    case SL_FLOW_FIELD_LR: {
        long e = lr_element(f->lr, p, cursor);
        if (e < 0)
            return 0.0;
        const sl_lr_element *el = &f->lr->elements[e];
        double s = el->hi[0] - el->lo[0];
        int order = f->lr->order[0];
        for (int d = 1; d < 3; d++) {
            if (el->hi[d] - el->lo[d] < s)
                s = el->hi[d] - el->lo[d];
            if (f->lr->order[d] > order)
                order = f->lr->order[d];
        }
        int degree = order - 1 < 1 ? 1 : order - 1;
        return ldexp(s, -degree);
    }
    case SL_FLOW_FIELD_HELIX: {
        double s = f->hi[0] - f->lo[0];
        for (int a = 1; a < 3; a++)
            if (f->hi[a] - f->lo[a] < s)
                s = f->hi[a] - f->lo[a];
        return s / 64.0;
    }
    }
    return 0.0;
}
