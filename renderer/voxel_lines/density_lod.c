/* density_lod.c — representative average lines per voxel and per coarser
 * level (Kanzler et al., Sec. 3.4, Fig. 7), used for hard shadows from
 * coarse lines (Fig. 12c). The density octree itself is the mip chain of the
 * density texture (voxel_lines.c).
 *
 * Level 0: per voxel the start points and the end points of its lines are
 * averaged separately; a line pointing more than 90 degrees away from the
 * running average direction is flipped first. Each average point is moved to
 * the closest point on the voxel boundary and snapped to the centre of its
 * face bin (the model's quantization N). Level L > 0: the representatives of
 * the 2^3 children, in the parent's local coordinates, are averaged the same
 * way; since children's lines are chained rather than cell-spanning, the
 * line through their average midpoint along their average direction is
 * extended to the parent's boundary and snapped there. Connectivity snapping between
 * neighbours (the paper's last step) is not done. CPU, any thread, no GL.
 */
#include "voxel_lod.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Closest point on the unit cube's boundary to p (inside or on it), snapped
 * to its face bin centre. */
static void snap_to_boundary(const double p[3], int n, float out[3])
{
    int face = 0;
    double best = 2.0;
    for (int ax = 0; ax < 3; ax++)
        for (int side = 0; side < 2; side++) {
            double d = side ? 1.0 - p[ax] : p[ax];
            if (d < best) {
                best = d;
                face = 2 * ax + side;
            }
        }
    double u[3] = {p[0], p[1], p[2]};
    for (int c = 0; c < 3; c++)
        u[c] = u[c] < 0.0 ? 0.0 : (u[c] > 1.0 ? 1.0 : u[c]);
    u[face / 2] = (double)(face & 1);
    double q[3];
    sl_voxel_dequantize(face, sl_voxel_quantize(u, face, n), n, q);
    for (int c = 0; c < 3; c++)
        out[c] = (float)q[c];
}

typedef struct averager {
    double a[3], b[3];
    int count;
} averager;

static void average_add(averager *av, const double a[3], const double b[3])
{
    double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double cur[3] = {av->b[0] - av->a[0], av->b[1] - av->a[1], av->b[2] - av->a[2]};
    int flip = av->count > 0 && d[0] * cur[0] + d[1] * cur[1] + d[2] * cur[2] < 0.0;
    for (int c = 0; c < 3; c++) {
        av->a[c] += flip ? b[c] : a[c];
        av->b[c] += flip ? a[c] : b[c];
    }
    av->count++;
}

/* Writes the snapped average (or NaN for none) into out[6]. extend: the
 * averaged points are the centroid and direction of the children's lines,
 * and the line through them is extended to the cell boundary (for levels
 * above 0, where children's pieces are chained, not cell-spanning). */
static void average_finish(const averager *av, int n, int extend, float out[6])
{
    if (av->count == 0) {
        for (int c = 0; c < 6; c++)
            out[c] = NAN;
        return;
    }
    double a[3], b[3];
    for (int c = 0; c < 3; c++) {
        a[c] = av->a[c] / av->count;
        b[c] = av->b[c] / av->count;
    }
    if (extend) {
        double m[3], d[3], t_lo = -INFINITY, t_hi = INFINITY;
        for (int c = 0; c < 3; c++) {
            m[c] = 0.5 * (a[c] + b[c]);
            d[c] = b[c] - a[c];
            if (d[c] != 0.0) {
                double t0 = (0.0 - m[c]) / d[c], t1 = (1.0 - m[c]) / d[c];
                t_lo = fmax(t_lo, fmin(t0, t1));
                t_hi = fmin(t_hi, fmax(t0, t1));
            }
        }
        if (isfinite(t_lo) && isfinite(t_hi))
            for (int c = 0; c < 3; c++) {
                a[c] = m[c] + t_lo * d[c];
                b[c] = m[c] + t_hi * d[c];
            }
    }
    snap_to_boundary(a, n, out);
    snap_to_boundary(b, n, out + 3);
    if (out[0] == out[3] && out[1] == out[4] && out[2] == out[5])
        for (int c = 0; c < 6; c++)
            out[c] = NAN; /* collapsed: no representative */
}

sl_status sl_voxel_lod_build(const sl_voxel_grid *g, int levels, sl_voxel_lod *lod, sl_err *err)
{
    memset(lod, 0, sizeof *lod);
    if (levels < 1 || levels > SL_VOXEL_LOD_MAX_LEVELS)
        return sl_err_set(err, SL_ERR_INVALID, "representative-line levels %d must be in 1..%d", levels,
                          SL_VOXEL_LOD_MAX_LEVELS);
    int dims[3] = {g->frame.dims[0], g->frame.dims[1], g->frame.dims[2]};
    for (int L = 0; L < levels; L++) {
        sl_voxel_lod_level *lv = &lod->level[L];
        memcpy(lv->dims, dims, sizeof dims);
        size_t cells = (size_t)dims[0] * dims[1] * dims[2];
        lv->lines = malloc(cells * 6 * sizeof *lv->lines);
        if (!lv->lines) {
            sl_voxel_lod_deinit(lod);
            return sl_err_set(err, SL_ERR_NOMEM, "representative lines: out of memory at level %d", L);
        }
        lod->levels = L + 1;
        for (int z = 0; z < dims[2]; z++)
            for (int y = 0; y < dims[1]; y++)
                for (int x = 0; x < dims[0]; x++) {
                    averager av;
                    memset(&av, 0, sizeof av);
                    int c[3] = {x, y, z};
                    size_t id = sl_voxel_index(dims, c);
                    if (L == 0) {
                        for (size_t i = g->offsets[id]; i < (size_t)g->offsets[id] + g->counts[id]; i++) {
                            sl_voxel_line l;
                            sl_voxel_decode_line(g->quant_bits, sl_voxel_grid_line(g, i), &l);
                            double a[3], b[3];
                            sl_voxel_dequantize(l.face_a, l.bin_a, g->quant, a);
                            sl_voxel_dequantize(l.face_b, l.bin_b, g->quant, b);
                            average_add(&av, a, b);
                        }
                    } else {
                        const sl_voxel_lod_level *fine = &lod->level[L - 1];
                        for (int k = 0; k < 8; k++) {
                            int cc[3] = {2 * x + (k & 1), 2 * y + ((k >> 1) & 1), 2 * z + (k >> 2)};
                            if (cc[0] >= fine->dims[0] || cc[1] >= fine->dims[1] || cc[2] >= fine->dims[2])
                                continue;
                            const float *r = fine->lines + 6 * sl_voxel_index(fine->dims, cc);
                            if (isnan(r[0]))
                                continue;
                            double a[3], b[3];
                            for (int q = 0; q < 3; q++) {
                                a[q] = 0.5 * ((cc[q] & 1) + r[q]);
                                b[q] = 0.5 * ((cc[q] & 1) + r[3 + q]);
                            }
                            average_add(&av, a, b);
                        }
                    }
                    average_finish(&av, g->quant, L > 0, lv->lines + 6 * id);
                }
        for (int c = 0; c < 3; c++)
            dims[c] = (dims[c] + 1) / 2;
    }
    return SL_OK;
}

void sl_voxel_lod_deinit(sl_voxel_lod *lod)
{
    if (!lod)
        return;
    for (int L = 0; L < SL_VOXEL_LOD_MAX_LEVELS; L++)
        free(lod->level[L].lines);
    memset(lod, 0, sizeof *lod);
}
