/* fuzz_check.h — the result check shared by the loader fuzz targets (line
 * sets: fuzz_trk.c, fuzz_tck.c, fuzz_vtk.c, fuzz_obj.c, fuzz_generate.c;
 * volumes: fuzz_nrrd.c, fuzz_nifti.c, fuzz_raw_json.c).
 *
 * On failure *out must be NULL and the message non-empty. On success the
 * dataset must be consistent: offsets start at 0, never decrease and end at
 * vertex_count; positions and bounds are finite; every position, normal and
 * attribute value is read (so ASan sees the whole arrays); attribute ranges
 * are ordered. A volume has dims >= 1 within SL_MAX_VOXELS, 1 or 3
 * components, an ordered value range, positive spacing, and every voxel is
 * read. An LR-spline volume (fuzz_lr.c) has a finished model whose element
 * lists index existing basis functions, a finite domain equal to the
 * bounds, an ordered value range, and a finite value at every element's
 * centre. Violations abort(); the dataset is destroyed. Single-threaded;
 * test-only.
 */
#ifndef SL_FUZZ_CHECK_H
#define SL_FUZZ_CHECK_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "data/sl_load.h"
#include "lrspline/sl_lr.h"

/* The LR branch of sl_fuzz_check. */
static inline void sl_fuzz_check_lr(const sl_dataset *ds)
{
    const sl_lr_volume *lr = ds->lr;
    if (!lr || lr->element_count == 0 || lr->basis_count == 0 || (lr->dim != 1 && lr->dim != 3) ||
        !(lr->value_min <= lr->value_max) || ds->bounds_min.x != lr->domain_lo[0] ||
        ds->bounds_max.z != lr->domain_hi[2])
        abort();
    for (size_t i = 0; i < lr->element_count; i++) {
        const sl_lr_element *e = &lr->elements[i];
        if ((size_t)e->basis_offset + e->basis_count > lr->element_basis_count)
            abort();
        for (uint32_t k = 0; k < e->basis_count; k++)
            if (lr->element_basis[e->basis_offset + k] >= lr->basis_count)
                abort();
        double p[3], v[SL_LR_MAX_DIM], g[3 * SL_LR_MAX_DIM];
        for (int d = 0; d < 3; d++)
            p[d] = 0.5 * (e->lo[d] + e->hi[d]);
        sl_err err = {0};
        if (sl_lr_eval(lr, p, (long)i, v, g, &err) != SL_OK)
            abort();
        for (int c = 0; c < lr->dim; c++)
            if (!isfinite(v[c]))
                abort();
    }
}

static inline void sl_fuzz_check(sl_status st, sl_dataset *ds, const sl_err *err)
{
    if (st != SL_OK) {
        if (ds || err->message[0] == '\0')
            abort();
        return;
    }
    if (!ds)
        abort();
    volatile double sink = 0.0;
    if (ds->kind == SL_DATASET_LINES) {
        const sl_lines *l = &ds->lines;
        if (!l->line_offsets || !l->positions || l->line_count == 0 || l->line_count > SL_MAX_LINES ||
            l->vertex_count > SL_MAX_VERTICES || l->line_offsets[0] != 0 ||
            l->line_offsets[l->line_count] != l->vertex_count)
            abort();
        for (size_t k = 0; k < l->line_count; k++)
            if (l->line_offsets[k + 1] < l->line_offsets[k])
                abort();
        for (size_t i = 0; i < 3 * l->vertex_count; i++) {
            if (!isfinite(l->positions[i]))
                abort();
            sink += l->positions[i];
            if (l->normals)
                sink += l->normals[i];
        }
        for (int a = 0; a < l->attribute_count; a++) {
            if (!(l->attributes[a].min <= l->attributes[a].max))
                abort();
            for (size_t v = 0; v < l->vertex_count; v++)
                sink += l->attributes[a].values[v];
        }
        for (int a = 0; a < l->line_attribute_count; a++) {
            if (!(l->line_attributes[a].min <= l->line_attributes[a].max))
                abort();
            for (size_t k = 0; k < l->line_count; k++)
                sink += l->line_attributes[a].values[k];
        }
        if (!isfinite(ds->bounds_min.x + ds->bounds_min.y + ds->bounds_min.z + ds->bounds_max.x +
                      ds->bounds_max.y + ds->bounds_max.z) ||
            !(ds->bounds_min.x <= ds->bounds_max.x))
            abort();
    } else if (ds->kind == SL_DATASET_LR) {
        sl_fuzz_check_lr(ds);
    } else {
        const sl_volume *v = &ds->volume;
        if ((ds->kind != SL_DATASET_VOLUME && ds->kind != SL_DATASET_VECTORS) || !v->data ||
            (v->components != 1 && v->components != 3) || v->dims[0] < 1 || v->dims[1] < 1 || v->dims[2] < 1 ||
            (uint64_t)v->dims[0] * (uint64_t)v->dims[1] * (uint64_t)v->dims[2] * (uint64_t)v->components > SL_MAX_VOXELS ||
            !(v->value_min <= v->value_max) || !(v->spacing[0] > 0 && v->spacing[1] > 0 && v->spacing[2] > 0))
            abort();
        for (size_t z = 0; z < (size_t)v->dims[2]; z++)
            for (size_t y = 0; y < (size_t)v->dims[1]; y++)
                for (size_t x = 0; x < (size_t)v->dims[0]; x++)
                    for (int c = 0; c < v->components; c++)
                        sink += sl_volume_value(v, x, y, z, c);
    }
    (void)sink;
    sl_dataset_destroy(ds);
}

#endif
