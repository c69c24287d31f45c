/* load_obj.c — Wavefront OBJ polylines ("v x y z" and "l i j k ...") into a line set.
 *
 * Every "l" statement is one polyline; indices are 1-based, negative ones
 * count back from the last vertex defined so far, and "i/t" keeps i. Every
 * other statement (faces, normals, groups, materials, comments) is ignored,
 * as are extra values after x y z on a "v" line (w, or vertex colours).
 * A point used by several lines is copied into each. Does not read faces as
 * lines or line continuations ("\" at the end of a line). Two passes (count,
 * then fill exact arrays), so allocation follows the bytes present.
 * Any thread; no GL.
 */
#include "load_common.h"
#include "load_lines.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct obj_build {
    size_t point_count, line_count, index_count;
    float *points;          /* 3 * point_count */
    uint64_t *offsets;      /* line_count + 1 */
    uint32_t *indices;      /* index_count */
    double lo[3], hi[3];    /* bounds of the points (counting pass) */
    double centre[3];       /* points are stored relative to it (dataset origin) */
} obj_build;

/* One pass over the file; with b->points NULL it only counts. */
static sl_status walk(const uint8_t *d, size_t size, obj_build *b, sl_err *err)
{
    sl_text t;
    sl_text_init(&t, d, size);
    size_t points = 0, lines = 0, indices = 0;
    int fill = b->points != NULL;
    while (t.pos < t.size) {
        size_t lineno = t.line;
        const char *tok;
        size_t len;
        if (!sl_text_token_inline(&t, &tok, &len)) {
            sl_text_skip_line(&t);
            continue;
        }
        if (len == 1 && tok[0] == 'v') {
            double xyz[3];
            for (int c = 0; c < 3; c++) {
                if (!sl_text_token_inline(&t, &tok, &len))
                    return sl_err_set(err, SL_ERR_FORMAT, "line %zu: 'v' has %d of 3 coordinates", lineno, c);
                if (!sl_text_double(tok, len, &xyz[c]))
                    return sl_err_set(err, SL_ERR_FORMAT, "line %zu: 'v' coordinate %d \"%.*s\" is not a number",
                                      lineno, c, (int)(len > 32 ? 32 : len), tok);
                if (!isfinite(xyz[c]) || !isfinite(sl_load_narrow(xyz[c])))
                    return sl_err_set(err, SL_ERR_FORMAT, "line %zu: 'v' coordinate %d is %g (not a finite float)",
                                      lineno, c, xyz[c]);
            }
            if (points >= SL_MAX_VERTICES)
                return sl_err_set(err, SL_ERR_LIMIT, "line %zu: more than %u vertices", lineno, SL_MAX_VERTICES);
            /* Narrowed only relative to the bounds centre, so data far from
             * the origin keeps float precision (sl_dataset.h). */
            for (int c = 0; c < 3; c++) {
                if (fill)
                    b->points[3 * points + c] = (float)(xyz[c] - b->centre[c]);
                else if (points == 0 || xyz[c] < b->lo[c])
                    b->lo[c] = xyz[c];
                if (!fill && (points == 0 || xyz[c] > b->hi[c]))
                    b->hi[c] = xyz[c];
            }
            points++;
        } else if (len == 1 && tok[0] == 'l') {
            size_t n = 0;
            while (sl_text_token_inline(&t, &tok, &len)) {
                const char *slash = memchr(tok, '/', len);
                size_t ilen = slash ? (size_t)(slash - tok) : len;
                long long i = 0;
                if (!sl_text_long(tok, ilen, -(long long)SL_MAX_VERTICES, SL_MAX_VERTICES, &i) || i == 0)
                    return sl_err_set(err, SL_ERR_FORMAT, "line %zu: 'l' index \"%.*s\" is not a non-zero integer in range",
                                      lineno, (int)(len > 32 ? 32 : len), tok);
                if (fill) {
                    long long r;
                    if (i < 0) {
                        r = (long long)points + i;
                        if (r < 0)
                            return sl_err_set(err, SL_ERR_FORMAT, "line %zu: 'l' index %lld reaches before the first of %zu vertices defined so far",
                                              lineno, i, points);
                    } else {
                        r = i - 1;
                        if ((size_t)r >= b->point_count)
                            return sl_err_set(err, SL_ERR_FORMAT, "line %zu: 'l' index %lld exceeds the %zu vertices",
                                              lineno, i, b->point_count);
                    }
                    b->indices[indices] = (uint32_t)r;
                }
                indices++;
                n++;
                if (indices > SL_MAX_VERTICES)
                    return sl_err_set(err, SL_ERR_LIMIT, "line %zu: more than %u line vertices", lineno, SL_MAX_VERTICES);
            }
            if (n == 0)
                return sl_err_set(err, SL_ERR_FORMAT, "line %zu: 'l' has no vertex indices", lineno);
            if (lines >= SL_MAX_LINES)
                return sl_err_set(err, SL_ERR_LIMIT, "line %zu: more than %u polylines", lineno, SL_MAX_LINES);
            lines++;
            if (fill)
                b->offsets[lines] = indices;
        }
        sl_text_skip_line(&t);
    }
    if (lines == 0)
        return sl_err_set(err, SL_ERR_FORMAT, "no 'l' polylines (%zu vertices)", points);
    b->point_count = points;
    b->line_count = lines;
    b->index_count = indices;
    return SL_OK;
}

sl_status sl_load_obj(const uint8_t *data, size_t size, const char *path, sl_dataset **out, sl_err *err)
{
    *out = NULL;
    const char *who = sl_load_display_name(path);
    if (!data)
        size = 0;
    obj_build b = {0};
    sl_dataset *ds = NULL;
    sl_status st = walk(data, size, &b, err);
    if (st != SL_OK)
        goto fail;
    for (int c = 0; c < 3; c++)
        b.centre[c] = b.point_count ? 0.5 * (b.lo[c] + b.hi[c]) : 0.0;
    b.points = malloc(3 * (b.point_count ? b.point_count : 1) * sizeof(float));
    b.offsets = calloc(b.line_count + 1, sizeof *b.offsets);
    b.indices = malloc((b.index_count ? b.index_count : 1) * sizeof *b.indices);
    if (!b.points || !b.offsets || !b.indices) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for %zu vertices", b.point_count);
        goto fail;
    }
    st = walk(data, size, &b, err);
    if (st != SL_OK)
        goto fail;
    char name[128];
    sl_load_base_name(path, "obj", name, sizeof name);
    ds = sl_dataset_create(SL_DATASET_LINES, name);
    if (!ds) {
        st = sl_err_set(err, SL_ERR_NOMEM, "out of memory for the dataset");
        goto fail;
    }
    ds->origin = sl_v3(b.centre[0], b.centre[1], b.centre[2]);
    st = sl_lines_from_indexed(ds, b.points, b.point_count, b.offsets, b.line_count, b.indices, err);
    if (st == SL_OK)
        st = sl_dataset_finish_lines(ds, err);
    if (st != SL_OK)
        goto fail;
    free(b.points);
    free(b.offsets);
    free(b.indices);
    *out = ds;
    return SL_OK;
fail:
    sl_err_prefix(err, "%s (OBJ)", who);
    sl_dataset_destroy(ds);
    free(b.points);
    free(b.offsets);
    free(b.indices);
    return st;
}
