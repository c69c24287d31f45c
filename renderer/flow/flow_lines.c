/* flow_lines.c — a trace result as a line set (positions + tangents =
 * velocities, the Hermite data renderer/tubes draws; attributes "speed"
 * and "t"), so drawing streamlines as tubes is one call away. Any thread;
 * no GL.
 */
#include <math.h>
#include <stdio.h>

#include "sl_flow.h"

sl_status sl_flow_result_to_dataset(const sl_flow_result *r, const char *name, sl_dataset **out,
                                    sl_err *err)
{
    *out = NULL;
    size_t lines = 0, vertices = 0;
    for (size_t i = 0; i < r->line_count; i++)
        if (r->lines[i].count >= 2) {
            lines++;
            vertices += r->lines[i].count;
        }
    if (lines == 0)
        return sl_err_set(err, SL_ERR_INVALID, "no streamline has two samples to draw");
    sl_dataset *ds = sl_dataset_create(SL_DATASET_LINES, name ? name : "streamlines");
    if (!ds)
        return sl_err_set(err, SL_ERR_NOMEM, "out of memory for the streamline dataset");
    sl_lines *L = &ds->lines;
    sl_status st = sl_lines_alloc(L, lines, vertices, 0, 1, err);
    float *speed = st == SL_OK ? sl_lines_add_attribute(L, "speed", 0, err) : NULL;
    float *tt = speed ? sl_lines_add_attribute(L, "t", 0, err) : NULL;
    if (!tt) {
        sl_dataset_destroy(ds);
        return st != SL_OK ? st : err->status;
    }
    /* Store relative to the samples' box centre, computed in double, so far
     * data keeps float precision (finish_lines re-centres the rest). */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < r->line_count; i++)
        if (r->lines[i].count >= 2)
            for (size_t j = 0; j < 3 * r->lines[i].count; j++) {
                double x = r->lines[i].x[j];
                if (x < lo[j % 3])
                    lo[j % 3] = x;
                if (x > hi[j % 3])
                    hi[j % 3] = x;
            }
    double centre[3];
    for (int c = 0; c < 3; c++)
        centre[c] = 0.5 * (lo[c] + hi[c]);
    ds->origin.x = centre[0];
    ds->origin.y = centre[1];
    ds->origin.z = centre[2];
    size_t k = 0, v = 0;
    for (size_t i = 0; i < r->line_count; i++) {
        const sl_flow_line *l = &r->lines[i];
        if (l->count < 2)
            continue;
        L->line_offsets[k++] = (uint32_t)v;
        for (size_t j = 0; j < l->count; j++, v++) {
            const double *x = l->x + 3 * j, *vel = l->v + 3 * j;
            for (int c = 0; c < 3; c++) {
                L->positions[3 * v + c] = (float)(x[c] - centre[c]);
                L->tangents[3 * v + c] = (float)vel[c];
            }
            speed[v] = (float)sqrt(vel[0] * vel[0] + vel[1] * vel[1] + vel[2] * vel[2]);
            tt[v] = (float)l->t[j];
        }
    }
    L->line_offsets[k] = (uint32_t)v;
    st = sl_dataset_finish_lines(ds, err);
    if (st != SL_OK) {
        sl_dataset_destroy(ds);
        return st;
    }
    *out = ds;
    return SL_OK;
}
