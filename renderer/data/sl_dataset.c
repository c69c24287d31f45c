/* sl_dataset.c — allocation, limits and finishing of the dataset model (see sl_dataset.h).
 * Any thread; no GL. */
#include "sl_dataset.h"

#include "../lrspline/sl_lr.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const sl_dataset_kind sl_dataset_kinds[SL_DATASET_KIND_COUNT] = {
    SL_DATASET_LINES, SL_DATASET_VOLUME, SL_DATASET_VECTORS, SL_DATASET_LR};

sl_dataset *sl_dataset_create(sl_dataset_kind kind, const char *name)
{
    sl_dataset *ds = calloc(1, sizeof *ds);
    if (!ds)
        return NULL;
    ds->kind = kind;
    snprintf(ds->name, sizeof ds->name, "%s", name ? name : "");
    return ds;
}

sl_dataset *sl_dataset_retain(sl_dataset *ds)
{
    if (ds)
        atomic_fetch_add(&ds->extra_owners, 1);
    return ds;
}

void sl_dataset_destroy(sl_dataset *ds)
{
    if (!ds)
        return;
    if (atomic_fetch_sub(&ds->extra_owners, 1) > 0)
        return; /* another owner keeps it */
    sl_lines *l = &ds->lines;
    free(l->line_offsets);
    free(l->positions);
    free(l->radii);
    free(l->tangents);
    free(l->normals);
    for (int i = 0; i < l->attribute_count; i++)
        free(l->attributes[i].values);
    for (int i = 0; i < l->line_attribute_count; i++)
        free(l->line_attributes[i].values);
    free(ds->volume.data);
    if (ds->lr) {
        sl_lr_free(ds->lr);
        free(ds->lr);
    }
    free(ds);
}

sl_status sl_lines_alloc(sl_lines *l, size_t line_count, size_t vertex_count,
                         int with_radii, int with_tangents, sl_err *err)
{
    if (line_count > SL_MAX_LINES)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu lines exceed the limit of %u", line_count, SL_MAX_LINES);
    if (vertex_count > SL_MAX_VERTICES)
        return sl_err_set(err, SL_ERR_LIMIT, "%zu vertices exceed the limit of %u", vertex_count, SL_MAX_VERTICES);
    l->line_offsets = calloc(line_count + 1, sizeof *l->line_offsets);
    l->positions = malloc((vertex_count ? vertex_count : 1) * 3 * sizeof(float));
    if (with_radii)
        l->radii = calloc(vertex_count ? vertex_count : 1, sizeof(float));
    if (with_tangents)
        l->tangents = calloc((vertex_count ? vertex_count : 1) * 3, sizeof(float));
    if (!l->line_offsets || !l->positions || (with_radii && !l->radii) || (with_tangents && !l->tangents))
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu vertices", vertex_count);
    l->line_count = line_count;
    l->vertex_count = vertex_count;
    return SL_OK;
}

float *sl_lines_add_attribute(sl_lines *l, const char *name, int per_line, sl_err *err)
{
    int *count = per_line ? &l->line_attribute_count : &l->attribute_count;
    sl_attribute *set = per_line ? l->line_attributes : l->attributes;
    if (*count >= SL_MAX_ATTRIBUTES) {
        sl_err_set(err, SL_ERR_LIMIT, "more than %d attributes", SL_MAX_ATTRIBUTES);
        return NULL;
    }
    size_t n = per_line ? l->line_count : l->vertex_count;
    float *values = calloc(n ? n : 1, sizeof(float));
    if (!values) {
        sl_err_set(err, SL_ERR_NOMEM, "out of memory for attribute '%s'", name);
        return NULL;
    }
    sl_attribute *a = &set[(*count)++];
    snprintf(a->name, sizeof a->name, "%s", name);
    a->values = values;
    return values;
}

int sl_lines_find_attribute(const sl_lines *l, const char *name)
{
    for (int i = 0; i < l->attribute_count; i++)
        if (strcmp(l->attributes[i].name, name) == 0)
            return i;
    return -1;
}

static void attribute_range(sl_attribute *a, size_t n)
{
    float lo = FLT_MAX, hi = -FLT_MAX;
    for (size_t i = 0; i < n; i++)
        if (isfinite(a->values[i])) {
            if (a->values[i] < lo) lo = a->values[i];
            if (a->values[i] > hi) hi = a->values[i];
        }
    a->min = lo <= hi ? lo : 0.0f;
    a->max = lo <= hi ? hi : 0.0f;
}

sl_status sl_dataset_finish_lines(sl_dataset *ds, sl_err *err)
{
    sl_lines *l = &ds->lines;
    if (l->line_offsets[0] != 0 || l->line_offsets[l->line_count] != l->vertex_count)
        return sl_err_set(err, SL_ERR_FORMAT, "line offsets do not cover the %zu vertices", l->vertex_count);
    for (size_t k = 0; k < l->line_count; k++)
        if (l->line_offsets[k + 1] < l->line_offsets[k])
            return sl_err_set(err, SL_ERR_FORMAT, "line %zu has a negative vertex count", k);
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t v = 0; v < l->vertex_count; v++) {
        double r = l->radii ? fabs((double)l->radii[v]) : 0.0;
        if (l->radii && !isfinite(l->radii[v]))
            return sl_err_set(err, SL_ERR_FORMAT, "vertex %zu has a non-finite radius", v);
        for (int c = 0; c < 3; c++) {
            double x = l->positions[3 * v + c];
            if (!isfinite(x))
                return sl_err_set(err, SL_ERR_FORMAT, "vertex %zu has a non-finite coordinate", v);
            if (x - r < lo[c]) lo[c] = x - r;
            if (x + r > hi[c]) hi[c] = x + r;
        }
    }
    if (l->vertex_count == 0) {
        for (int c = 0; c < 3; c++)
            lo[c] = hi[c] = 0.0;
    }
    double centre[3];
    for (int c = 0; c < 3; c++)
        centre[c] = 0.5 * (lo[c] + hi[c]);
    /* Re-centre in double: stored = old - centre, origin += centre. */
    for (size_t v = 0; v < l->vertex_count; v++)
        for (int c = 0; c < 3; c++)
            l->positions[3 * v + c] = (float)((double)l->positions[3 * v + c] - centre[c]);
    ds->origin = sl_v3(ds->origin.x + centre[0], ds->origin.y + centre[1], ds->origin.z + centre[2]);
    ds->bounds_min = sl_v3(ds->origin.x + lo[0] - centre[0], ds->origin.y + lo[1] - centre[1], ds->origin.z + lo[2] - centre[2]);
    ds->bounds_max = sl_v3(ds->origin.x + hi[0] - centre[0], ds->origin.y + hi[1] - centre[1], ds->origin.z + hi[2] - centre[2]);
    for (int i = 0; i < l->attribute_count; i++)
        attribute_range(&l->attributes[i], l->vertex_count);
    for (int i = 0; i < l->line_attribute_count; i++)
        attribute_range(&l->line_attributes[i], l->line_count);
    return SL_OK;
}

size_t sl_voxel_type_size(sl_voxel_type t)
{
    switch (t) {
    case SL_VOXEL_U8: return 1;
    case SL_VOXEL_U16: return 2;
    case SL_VOXEL_S16: return 2;
    case SL_VOXEL_F32: return 4;
    }
    return 0;
}

const char *sl_voxel_type_name(sl_voxel_type t)
{
    switch (t) {
    case SL_VOXEL_U8: return "u8";
    case SL_VOXEL_U16: return "u16";
    case SL_VOXEL_S16: return "s16";
    case SL_VOXEL_F32: return "f32";
    }
    return "unknown";
}

const char *sl_dataset_kind_name(sl_dataset_kind k)
{
    switch (k) {
    case SL_DATASET_LINES: return "lines";
    case SL_DATASET_VOLUME: return "volume";
    case SL_DATASET_VECTORS: return "vectors";
    case SL_DATASET_LR: return "lr_volume";
    }
    return "unknown";
}

sl_status sl_volume_alloc(sl_volume *vol, const int dims[3], int components,
                          sl_voxel_type type, sl_err *err)
{
    if (components != 1 && components != 3)
        return sl_err_set(err, SL_ERR_INVALID, "a volume has 1 or 3 components, not %d", components);
    unsigned long long n = (unsigned long long)components;
    for (int c = 0; c < 3; c++) {
        if (dims[c] < 1)
            return sl_err_set(err, SL_ERR_FORMAT, "volume dimension %d is %d, must be >= 1", c, dims[c]);
        n *= (unsigned long long)dims[c];
        if (n > SL_MAX_VOXELS)
            return sl_err_set(err, SL_ERR_LIMIT, "volume of %dx%dx%d x%d exceeds the limit of %llu values",
                              dims[0], dims[1], dims[2], components, SL_MAX_VOXELS);
    }
    vol->data = calloc((size_t)n, sl_voxel_type_size(type));
    if (!vol->data)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for %llu voxels", n);
    memcpy(vol->dims, dims, sizeof vol->dims);
    vol->components = components;
    vol->type = type;
    for (int c = 0; c < 3; c++)
        if (!(vol->spacing[c] > 0.0))
            vol->spacing[c] = 1.0;
    return SL_OK;
}

double sl_volume_value(const sl_volume *vol, size_t x, size_t y, size_t z, int c)
{
    size_t i = ((z * (size_t)vol->dims[1] + y) * (size_t)vol->dims[0] + x) * (size_t)vol->components + (size_t)c;
    switch (vol->type) {
    case SL_VOXEL_U8: return ((const uint8_t *)vol->data)[i];
    case SL_VOXEL_U16: return ((const uint16_t *)vol->data)[i];
    case SL_VOXEL_S16: return ((const int16_t *)vol->data)[i];
    case SL_VOXEL_F32: return ((const float *)vol->data)[i];
    }
    return 0.0;
}

/* Range of the finite values of a scalar volume: one tight loop per voxel type. */
#define SCALAR_RANGE_LOOP(T)                                 \
    do {                                                     \
        const T *p = data;                                   \
        for (size_t i = 0; i < n; i++) {                     \
            double s = (double)p[i];                         \
            if (s < l) l = s;                                \
            if (s > h) h = s;                                \
        }                                                    \
    } while (0)

static void scalar_range(sl_voxel_type type, const void *data, size_t n, double *lo, double *hi)
{
    double l = *lo, h = *hi;
    switch (type) {
    case SL_VOXEL_U8: SCALAR_RANGE_LOOP(uint8_t); break;
    case SL_VOXEL_U16: SCALAR_RANGE_LOOP(uint16_t); break;
    case SL_VOXEL_S16: SCALAR_RANGE_LOOP(int16_t); break;
    case SL_VOXEL_F32: {
        const float *p = data;
        for (size_t i = 0; i < n; i++) {
            double s = (double)p[i];
            if (!isfinite(s))
                continue;
            if (s < l) l = s;
            if (s > h) h = s;
        }
        break;
    }
    }
    *lo = l;
    *hi = h;
}
#undef SCALAR_RANGE_LOOP

/* Range of the finite magnitudes of a 3-component f32 vector field. */
static void vector_magnitude_range(const float *f, size_t n, double *lo, double *hi)
{
    double l = *lo, h = *hi;
    for (size_t i = 0; i < n; i++, f += 3) {
        double s = sqrt((double)f[0] * f[0] + (double)f[1] * f[1] + (double)f[2] * f[2]);
        if (!isfinite(s))
            continue;
        if (s < l) l = s;
        if (s > h) h = s;
    }
    *lo = l;
    *hi = h;
}

/* The histogram of the finite values over [lo, hi] (see sl_volume). */
#define HISTOGRAM_LOOP(T, VALUE, STRIDE)                                  \
    do {                                                                  \
        const T *p = v->data;                                             \
        for (size_t i = 0; i < n; i++, p += (STRIDE)) {                   \
            double s = (VALUE);                                           \
            if (!isfinite(s))                                             \
                continue;                                                 \
            double b = (s - lo) * scale;                                  \
            v->histogram[b < last ? (size_t)b : (size_t)last]++;          \
            v->finite_count++;                                            \
        }                                                                 \
    } while (0)

static void volume_histogram(sl_volume *v, size_t n)
{
    double lo = v->value_min, hi = v->value_max;
    double scale = hi > lo ? SL_VOLUME_HISTOGRAM_BINS / (hi - lo) : 0.0;
    double last = SL_VOLUME_HISTOGRAM_BINS - 1;
    memset(v->histogram, 0, sizeof v->histogram);
    v->finite_count = 0;
    if (v->components == 3) {
        HISTOGRAM_LOOP(float, sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]), 3);
        return;
    }
    switch (v->type) {
    case SL_VOXEL_U8: HISTOGRAM_LOOP(uint8_t, (double)*p, 1); break;
    case SL_VOXEL_U16: HISTOGRAM_LOOP(uint16_t, (double)*p, 1); break;
    case SL_VOXEL_S16: HISTOGRAM_LOOP(int16_t, (double)*p, 1); break;
    case SL_VOXEL_F32: HISTOGRAM_LOOP(float, (double)*p, 1); break;
    }
}
#undef HISTOGRAM_LOOP

sl_status sl_dataset_finish_volume(sl_dataset *ds, sl_err *err)
{
    sl_volume *v = &ds->volume;
    for (int c = 0; c < 3; c++)
        if (!(v->spacing[c] > 0.0) || !isfinite(v->spacing[c]))
            return sl_err_set(err, SL_ERR_FORMAT, "volume spacing %d is %g, must be finite and > 0", c, v->spacing[c]);
    if (!sl_v3_is_finite(ds->origin))
        return sl_err_set(err, SL_ERR_FORMAT, "volume origin is not finite");
    size_t n = (size_t)v->dims[0] * (size_t)v->dims[1] * (size_t)v->dims[2];
    double lo = DBL_MAX, hi = -DBL_MAX;
    if (v->components == 3)
        vector_magnitude_range((const float *)v->data, n, &lo, &hi);
    else
        scalar_range(v->type, v->data, n, &lo, &hi);
    v->value_min = lo <= hi ? lo : 0.0;
    v->value_max = lo <= hi ? hi : 0.0;
    volume_histogram(v, n);
    ds->bounds_min = ds->origin;
    ds->bounds_max = sl_v3(ds->origin.x + (v->dims[0] - 1) * v->spacing[0],
                           ds->origin.y + (v->dims[1] - 1) * v->spacing[1],
                           ds->origin.z + (v->dims[2] - 1) * v->spacing[2]);
    return SL_OK;
}

double sl_dataset_radius(const sl_dataset *ds)
{
    double r = 0.5 * sl_v3_length(sl_v3_sub(ds->bounds_max, ds->bounds_min));
    return r > 0.0 && isfinite(r) ? r : 1.0;
}
