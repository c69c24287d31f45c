/* volume_reference.c — the reference ray marcher (see volume_reference.h).
 *
 * The voxels are copied once into a double array; every sample reads its 8
 * voxels from it. Slab intersection of the box in voxel coordinates, in
 * double, with the sample positions and the transfer function evaluated
 * from scratch per sample.
 */
#include "volume_reference.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct grid {
    int d[3];
    double *v;
} grid;

static double voxel_at(const grid *g, int x, int y, int z)
{
    return g->v[((size_t)z * g->d[1] + y) * g->d[0] + x];
}

static int clampi(int v, int lo, int hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

static double value_at(const grid *g, const double p[3], int nearest)
{
    if (nearest) {
        int c[3];
        for (int a = 0; a < 3; a++)
            c[a] = clampi((int)floor(p[a] + 0.5), 0, g->d[a] - 1);
        return voxel_at(g, c[0], c[1], c[2]);
    }
    int i0[3], i1[3];
    double f[3];
    for (int a = 0; a < 3; a++) {
        double q = p[a] < 0.0 ? 0.0 : (p[a] > g->d[a] - 1 ? g->d[a] - 1 : p[a]);
        i0[a] = clampi((int)floor(q), 0, g->d[a] - 1);
        i1[a] = i0[a] + 1 < g->d[a] ? i0[a] + 1 : i0[a];
        f[a] = q - i0[a];
    }
    double c[8];
    for (int k = 0; k < 8; k++) {
        c[k] = voxel_at(g, k & 1 ? i1[0] : i0[0], k & 2 ? i1[1] : i0[1], k & 4 ? i1[2] : i0[2]);
        if (isnan(c[k]))
            return NAN;
    }
    double x00 = c[0] + f[0] * (c[1] - c[0]), x10 = c[2] + f[0] * (c[3] - c[2]);
    double x01 = c[4] + f[0] * (c[5] - c[4]), x11 = c[6] + f[0] * (c[7] - c[6]);
    double y0 = x00 + f[1] * (x10 - x00), y1 = x01 + f[1] * (x11 - x01);
    return y0 + f[2] * (y1 - y0);
}

static void tf_at(const volume_ref_desc *d, double v, double out[4])
{
    int n = d->tf_count;
    if (v <= d->tf[0][0]) {
        memcpy(out, &d->tf[0][1], 4 * sizeof(double));
        return;
    }
    if (v >= d->tf[n - 1][0]) {
        memcpy(out, &d->tf[n - 1][1], 4 * sizeof(double));
        return;
    }
    int k = 1;
    while (v > d->tf[k][0])
        k++;
    double w = (v - d->tf[k - 1][0]) / (d->tf[k][0] - d->tf[k - 1][0]);
    for (int c = 0; c < 4; c++)
        out[c] = (1.0 - w) * d->tf[k - 1][1 + c] + w * d->tf[k][1 + c];
}

static uint8_t to8(double x)
{
    double y = x * 255.0;
    return (uint8_t)(y <= 0.0 ? 0 : (y >= 255.0 ? 255 : lrint(y)));
}

int volume_ref_render(const volume_ref_desc *d, uint8_t *rgba, float *distance)
{
    const sl_view *view = d->view;
    const sl_volume *vol = &d->volume->volume;
    if (vol->components != 1 || d->tf_count < 1 || !(d->step > 0.0))
        return -1;
    grid g = {{vol->dims[0], vol->dims[1], vol->dims[2]}, NULL};
    size_t n_vox = (size_t)g.d[0] * g.d[1] * g.d[2];
    g.v = malloc(n_vox * sizeof *g.v);
    if (!g.v)
        return -1;
    for (int z = 0, i = 0; z < g.d[2]; z++)
        for (int y = 0; y < g.d[1]; y++)
            for (int x = 0; x < g.d[0]; x++, i++)
                g.v[i] = sl_volume_value(vol, (size_t)x, (size_t)y, (size_t)z, 0);
    double hmin = fmin(vol->spacing[0], fmin(vol->spacing[1], vol->spacing[2]));
    double lo[3], hi[3];
    int clip = d->clip_max[0] > 0.0 || d->clip_max[1] > 0.0 || d->clip_max[2] > 0.0;
    const double org[3] = {d->volume->origin.x, d->volume->origin.y, d->volume->origin.z};
    for (int a = 0; a < 3; a++) {
        double b0 = g.d[a] > 1 ? 0.0 : -0.5, b1 = g.d[a] > 1 ? g.d[a] - 1.0 : 0.5;
        lo[a] = clip ? b0 + d->clip_min[a] * (b1 - b0) : b0;
        hi[a] = clip ? b0 + d->clip_max[a] * (b1 - b0) : b1;
    }
    const double bg[3] = {view->background[0], view->background[1], view->background[2]};
    const double eye[3] = {view->camera.eye.x, view->camera.eye.y, view->camera.eye.z};
    double dt = d->step * hmin;
    for (int j = 0; j < view->height; j++)
        for (int i = 0; i < view->width; i++) {
            sl_vec3 dir = sl_view_ray_dir(view, i, j);
            const double dw[3] = {dir.x, dir.y, dir.z};
            double ro[3], rd[3], t_in = -INFINITY, t_out = INFINITY;
            for (int a = 0; a < 3; a++) {
                ro[a] = (eye[a] - org[a]) / vol->spacing[a];
                rd[a] = dw[a] / vol->spacing[a];
                if (rd[a] == 0.0) {
                    if (ro[a] < lo[a] || ro[a] > hi[a])
                        t_in = INFINITY;
                    continue;
                }
                double ta = (lo[a] - ro[a]) / rd[a], tb = (hi[a] - ro[a]) / rd[a];
                t_in = fmax(t_in, fmin(ta, tb));
                t_out = fmin(t_out, fmax(ta, tb));
            }
            double t0 = fmax(t_in, 0.0), t1 = t_out;
            double C[3] = {0, 0, 0}, A = 0.0, dist = 0.0;
            double mip = -INFINITY;
            int mip_any = 0, iso_hit = 0;
            if (t1 > t0) {
                double L = t1 - t0;
                long n = (long)floor(L / dt);
                double rem = L - n * dt;
                double prev = NAN, prev_t = t0;
                if (d->mode == VOLUME_REF_ISO) {
                    double p[3] = {ro[0] + t0 * rd[0], ro[1] + t0 * rd[1], ro[2] + t0 * rd[2]};
                    prev = value_at(&g, p, d->nearest);
                }
                for (long k = 0; k <= n; k++) {
                    double tk, expo;
                    if (k < n) {
                        tk = t0 + (k + 0.5) * dt;
                        expo = d->step;
                    } else {
                        if (!(rem > 0.0))
                            break;
                        tk = t0 + n * dt + 0.5 * rem;
                        expo = rem / hmin;
                    }
                    double p[3] = {ro[0] + tk * rd[0], ro[1] + tk * rd[1], ro[2] + tk * rd[2]};
                    double v = value_at(&g, p, d->nearest);
                    if (d->mode == VOLUME_REF_COMPOSITE) {
                        if (isnan(v))
                            continue;
                        double c[4];
                        tf_at(d, v, c);
                        if (c[3] <= 0.0)
                            continue;
                        double a = c[3] >= 1.0 || d->uncorrected ? c[3] : 1.0 - pow(1.0 - c[3], expo);
                        for (int q = 0; q < 3; q++)
                            C[q] += (1.0 - A) * a * c[q];
                        A += (1.0 - A) * a;
                        if (A > 0.5 && dist == 0.0)
                            dist = tk;
                        if (A >= d->alpha_stop)
                            break;
                    } else if (d->mode == VOLUME_REF_MIP) {
                        if (!isnan(v)) {
                            mip = fmax(mip, v);
                            mip_any = 1;
                        }
                    } else {
                        if (isnan(v)) {
                            prev = NAN;
                            continue;
                        }
                        if (!isnan(prev) && ((prev - d->iso < 0.0) != (v - d->iso < 0.0))) {
                            double ta = prev_t, tc = tk, sa = prev - d->iso;
                            while (tc - ta > 1e-12 * dt) {
                                double tm = 0.5 * (ta + tc);
                                double pm[3] = {ro[0] + tm * rd[0], ro[1] + tm * rd[1], ro[2] + tm * rd[2]};
                                double sm = value_at(&g, pm, d->nearest) - d->iso;
                                if (isnan(sm))
                                    break;
                                if ((sa < 0.0) != (sm < 0.0)) {
                                    tc = tm;
                                } else {
                                    ta = tm;
                                    sa = sm;
                                }
                            }
                            dist = 0.5 * (ta + tc);
                            iso_hit = 1;
                            break;
                        }
                        prev = v;
                        prev_t = tk;
                    }
                }
            }
            double out[3];
            if (d->mode == VOLUME_REF_MIP && mip_any) {
                double c[4];
                tf_at(d, mip, c);
                for (int q = 0; q < 3; q++)
                    out[q] = c[3] * c[q] + (1.0 - c[3]) * bg[q];
            } else if (d->mode == VOLUME_REF_ISO && iso_hit) {
                double c[4];
                tf_at(d, d->iso, c);
                memcpy(out, c, sizeof out);
            } else {
                for (int q = 0; q < 3; q++)
                    out[q] = C[q] + (1.0 - A) * bg[q];
            }
            uint8_t *px = rgba + 4 * ((size_t)j * view->width + i);
            for (int q = 0; q < 3; q++)
                px[q] = to8(out[q]);
            px[3] = 255;
            if (distance)
                distance[(size_t)j * view->width + i] = (float)dist;
        }
    free(g.v);
    return 0;
}
