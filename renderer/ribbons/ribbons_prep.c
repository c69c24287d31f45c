/* ribbons_prep.c — frame resolution and per-point packing for `ribbons` (see ribbons_prep.h).
 *
 * One pass per array on the shared line preparation: BISECTOR tangents,
 * transported (or projected data) normals, trapezoid sums of helicity. The
 * packing keeps dataset order, so the shared colour-scalar SSBO lines up
 * without an index. Any thread; allocates only the three output arrays and
 * temporaries freed before returning.
 */
#include <stdlib.h>
#include <string.h>

#include "ribbons_prep.h"
#include "../lines/sl_lines_prep.h"

sl_status sl_ribbons_frame_resolve(const sl_dataset *ds, sl_ribbons_frame choice, sl_ribbons_frame *out,
                                   sl_err *err)
{
    int has_normals = ds->lines.normals != NULL;
    int has_helicity = sl_lines_find_attribute(&ds->lines, SL_ATTR_HELICITY) >= 0;
    *out = SL_RIBBONS_FRAME_TRANSPORT;
    switch (choice) {
    case SL_RIBBONS_FRAME_AUTO:
        *out = has_normals ? SL_RIBBONS_FRAME_DATA : has_helicity ? SL_RIBBONS_FRAME_HELICITY
                                                                  : SL_RIBBONS_FRAME_TRANSPORT;
        return SL_OK;
    case SL_RIBBONS_FRAME_DATA:
        if (!has_normals)
            return sl_err_set(err, SL_ERR_INVALID,
                              "ribbons: frame 'data' needs per-vertex normals; dataset '%s' has none "
                              "(auto picks what it has)", ds->name);
        *out = choice;
        return SL_OK;
    case SL_RIBBONS_FRAME_HELICITY:
        if (!has_helicity)
            return sl_err_set(err, SL_ERR_INVALID,
                              "ribbons: frame 'helicity' needs a per-vertex attribute '%s'; dataset '%s' has "
                              "none (auto picks what it has)", SL_ATTR_HELICITY, ds->name);
        *out = choice;
        return SL_OK;
    case SL_RIBBONS_FRAME_TRANSPORT:
        return SL_OK;
    }
    return sl_err_set(err, SL_ERR_INVALID, "ribbons: frame %d is not one of auto, transport, helicity, data",
                      (int)choice);
}

void sl_ribbons_points_deinit(sl_ribbons_points *p)
{
    if (!p)
        return;
    free(p->pos_radius);
    free(p->normal_twist);
    free(p->tangent_slope);
    memset(p, 0, sizeof *p);
}

sl_status sl_ribbons_points_init(sl_ribbons_points *out, const sl_lines *l, sl_ribbons_frame frame,
                                 int radius_attribute, sl_err *err)
{
    memset(out, 0, sizeof *out);
    size_t n = l->vertex_count, alloc = n ? n : 1;
    float *t3 = malloc(alloc * 3 * sizeof *t3), *n3 = malloc(alloc * 3 * sizeof *n3);
    float *radii = malloc(alloc * sizeof *radii), *R = malloc(alloc * sizeof *R), *S = malloc(alloc * sizeof *S);
    out->pos_radius = malloc(alloc * 4 * sizeof(float));
    out->normal_twist = malloc(alloc * 4 * sizeof(float));
    out->tangent_slope = malloc(alloc * 4 * sizeof(float));
    if (!t3 || !n3 || !radii || !R || !S || !out->pos_radius || !out->normal_twist || !out->tangent_slope) {
        free(t3); free(n3); free(radii); free(R); free(S);
        sl_ribbons_points_deinit(out);
        return sl_err_set(err, SL_ERR_NOMEM, "ribbons: out of memory for %zu points", n);
    }
    out->count = n;
    out->frame = frame;
    sl_lines_tangents(l, SL_LINES_TANGENT_BISECTOR, t3);
    if (frame == SL_RIBBONS_FRAME_DATA && l->normals)
        out->normal_fallbacks = sl_lines_project_normals(l, t3, l->normals, n3);
    else
        sl_lines_transport_normals(l, t3, NULL, n3);
    if (radius_attribute >= 0 && radius_attribute < l->attribute_count)
        sl_lines_attribute_radii(l, radius_attribute, radii, 1);
    else if (l->radii)
        memcpy(radii, l->radii, n * sizeof *radii);
    else
        for (size_t i = 0; i < n; i++)
            radii[i] = -1.0f;
    int h = sl_lines_find_attribute(l, SL_ATTR_HELICITY);
    if (h >= 0) {
        sl_lines_accumulate(l, l->attributes[h].values, SL_RIBBONS_TWIST_LIMIT, R, S);
    } else {
        memset(R, 0, n * sizeof *R);
        memset(S, 0, n * sizeof *S);
    }
    for (size_t i = 0; i < n; i++) {
        memcpy(out->pos_radius + 4 * i, l->positions + 3 * i, 3 * sizeof(float));
        out->pos_radius[4 * i + 3] = radii[i];
        memcpy(out->normal_twist + 4 * i, n3 + 3 * i, 3 * sizeof(float));
        out->normal_twist[4 * i + 3] = R[i];
        memcpy(out->tangent_slope + 4 * i, t3 + 3 * i, 3 * sizeof(float));
        out->tangent_slope[4 * i + 3] = S[i];
    }
    free(t3); free(n3); free(radii); free(R); free(S);
    return SL_OK;
}
